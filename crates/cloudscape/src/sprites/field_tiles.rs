//! The field's sprite clouds tile by tile around the camera: each tile's draft (its candidates,
//! made once and kept through edits of coverage) and its cloud at the field's density. After an
//! edit of coverage the clouds are *stale*: a still remakes them all before it draws, a real-time
//! host remakes them over frames, nearest the eye first, drawing each old cloud until its new one
//! is made, so that no frame stalls on the whole sky.

use std::collections::{BTreeMap, BTreeSet};

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::from_field::{FieldTiling, TileDraft, TileKey};
use super::model::SpriteCloud;
use crate::field::{CloudField, CoarseFieldReader};

/// Candidates whose density a real-time frame reads to remake stale clouds: about 25 ms of this
/// machine's two cores (read, finish and lay-out ~0.26 us a candidate: the overcast scene's 795,000
/// in ~210 ms), so that the frame an edit lands in stays under 50 ms with the sort and the upload.
pub const REFRESH_CANDIDATES_PER_FRAME: usize = 100_000;

/// The field's tiles around the camera, their drafts and their clouds.
pub struct FieldTiles {
    /// Where and how far clouds are made.
    pub tiling: FieldTiling,
    drafts: BTreeMap<TileKey, Option<TileDraft>>,
    /// Each tile's cloud (None where the tile is clear).
    pub tiles: BTreeMap<TileKey, Option<SpriteCloud>>,
    /// Tiles whose cloud was made before the last edit of the field's density.
    stale: BTreeSet<TileKey>,
}

/// What [`FieldTiles::update`] changed.
#[derive(Debug, Default, PartialEq)]
pub struct TilesChanged {
    /// Tiles the camera left.
    pub removed: Vec<TileKey>,
    /// Tiles whose cloud was (re)made.
    pub made: Vec<TileKey>,
}

impl TilesChanged {
    /// Whether any cloud came or went.
    pub fn any(&self) -> bool {
        !self.removed.is_empty() || !self.made.is_empty()
    }
}

impl FieldTiles {
    /// No tiles yet.
    pub fn new(tiling: FieldTiling) -> FieldTiles {
        FieldTiles {
            tiling,
            drafts: BTreeMap::new(),
            tiles: BTreeMap::new(),
            stale: BTreeSet::new(),
        }
    }

    /// After an edit that keeps the drafts (the field's density: coverage): every cloud is stale.
    pub fn mark_stale(&mut self) {
        self.stale.extend(self.tiles.keys().copied());
    }

    /// Tiles whose cloud is still the one made before the last edit.
    pub fn stale_count(&self) -> usize {
        self.stale.len()
    }

    /// Brings the tiles to this frame: drafts and makes the tiles the camera reached, forgets
    /// those it left, and remakes stale clouds: all of them with `refresh_budget` None (a still),
    /// else the nearest the eye, at least one, until their candidates reach the budget.
    pub fn update(
        &mut self,
        field: &CloudField,
        reader: &dyn CoarseFieldReader,
        camera_m: Vec3,
        refresh_budget: Option<usize>,
    ) -> TilesChanged {
        let wanted = self.tiling.tiles_around(field, camera_m);
        let keep: BTreeSet<TileKey> = wanted.iter().copied().collect();
        let removed: Vec<TileKey> = self
            .tiles
            .keys()
            .filter(|k| !keep.contains(k))
            .copied()
            .collect();
        self.tiles.retain(|k, _| keep.contains(k));
        self.drafts.retain(|k, _| keep.contains(k));
        self.stale.retain(|k| keep.contains(k));
        self.draft(field, &wanted);
        let mut made: Vec<TileKey> = wanted
            .into_iter()
            .filter(|k| !self.tiles.contains_key(k))
            .collect();
        made.extend(self.refresh_order(field, camera_m, refresh_budget));
        let drafts: Vec<Option<&TileDraft>> =
            made.iter().map(|k| self.drafts[k].as_ref()).collect();
        let clouds = self.tiling.finish(field, &drafts, reader);
        for (key, cloud) in made.iter().zip(clouds) {
            self.stale.remove(key);
            self.tiles.insert(*key, cloud);
        }
        TilesChanged { removed, made }
    }

    /// Drafts the tiles of `wanted` that have none, in parallel.
    fn draft(&mut self, field: &CloudField, wanted: &[TileKey]) {
        let undrafted: Vec<TileKey> = wanted
            .iter()
            .filter(|k| !self.drafts.contains_key(k))
            .copied()
            .collect();
        let tiling = self.tiling;
        let drafted: Vec<Option<TileDraft>> = undrafted
            .par_iter()
            .map(|&k| tiling.draft(field, k))
            .collect();
        self.drafts.extend(undrafted.into_iter().zip(drafted));
    }

    /// The stale tiles to remake this frame: nearest the eye first, within `budget` candidates
    /// (at least one tile), or all of them without a budget.
    fn refresh_order(
        &self,
        field: &CloudField,
        camera_m: Vec3,
        budget: Option<usize>,
    ) -> Vec<TileKey> {
        let mut order: Vec<(f32, TileKey)> = self
            .stale
            .iter()
            .map(|&k| (self.distance_m(field, k, camera_m), k))
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let Some(budget) = budget else {
            return order.into_iter().map(|(_, k)| k).collect();
        };
        let mut spent = 0;
        let mut chosen = Vec::new();
        for (_, key) in order {
            let candidates = self.drafts[&key].as_ref().map_or(0, TileDraft::candidates);
            if !chosen.is_empty() && spent + candidates > budget {
                break;
            }
            spent += candidates;
            chosen.push(key);
        }
        chosen
    }

    /// Horizontal distance from the eye to the centre of tile `key` at this tiling's time, m.
    fn distance_m(&self, field: &CloudField, key: TileKey, camera_m: Vec3) -> f32 {
        let layer = &field.layers[key.layer as usize];
        let eye = self
            .tiling
            .wind_frame(layer, Vec2::new(camera_m.x, camera_m.z));
        let centre = (glam::IVec2::from_array(key.tile).as_vec2() + 0.5) * self.tiling.tile_m;
        centre.distance(eye)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::CpuCoarseReader;
    use crate::scene::Scene;
    use std::path::Path;

    fn field(coverage: f32) -> CloudField {
        let mut scene = Scene::default();
        scene.layers[0].coverage = coverage;
        CloudField::new(&scene, Path::new(".")).expect("the default scene's field")
    }

    fn reader(field: &CloudField) -> CpuCoarseReader<'_> {
        CpuCoarseReader { field, time_s: 0.0 }
    }

    const TILING: FieldTiling = FieldTiling {
        tile_m: 1500.0,
        distance_m: 5000.0,
        time_s: 0.0,
    };

    #[test]
    fn stale_clouds_are_remade_nearest_first_within_the_budget() {
        let (thin, thick) = (field(0.35), field(0.6));
        let eye = Vec3::new(700.0, 1200.0, -300.0);
        let mut tiles = FieldTiles::new(TILING);
        let first = tiles.update(&thin, &reader(&thin), eye, Some(1));
        assert_eq!(
            first.made.len(),
            tiles.tiles.len(),
            "new tiles are made at once"
        );
        tiles.mark_stale();
        let total: usize = tiles
            .drafts
            .values()
            .flatten()
            .map(TileDraft::candidates)
            .sum();
        let budget = total / 4;
        let mut frames = 0;
        while tiles.stale_count() > 0 {
            let stale_before: Vec<TileKey> = tiles.stale.iter().copied().collect();
            let made = tiles
                .update(&thick, &reader(&thick), eye, Some(budget))
                .made;
            let spent: usize = made
                .iter()
                .map(|k| tiles.drafts[k].as_ref().map_or(0, TileDraft::candidates))
                .sum();
            assert!(
                made.len() == 1 || spent <= budget,
                "{spent} candidates over {budget}"
            );
            let reach = made
                .iter()
                .map(|&k| tiles.distance_m(&thick, k, eye))
                .fold(0.0, f32::max);
            for k in stale_before.iter().filter(|k| tiles.stale.contains(k)) {
                assert!(
                    tiles.distance_m(&thick, *k, eye) >= reach,
                    "a nearer tile was left stale"
                );
            }
            frames += 1;
            assert!(frames < 100);
        }
        assert!(
            frames >= 4,
            "{frames} frames for a quarter of the candidates each"
        );
        let mut still = FieldTiles::new(TILING);
        still.update(&thick, &reader(&thick), eye, None);
        assert_eq!(
            format!("{:?}", tiles.tiles),
            format!("{:?}", still.tiles),
            "remade over frames, the clouds are those a still makes"
        );
    }
}
