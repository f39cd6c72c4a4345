//! Sprite clouds from the cloud field, so the sprites show the clouds the ray marcher shows, in the
//! same places.
//!
//! Each layer is cut into square tiles of `sprites.cloud_size_m` that move with the layer's wind
//! (the field moves rigidly with it, so a tile's cloud keeps its shape). The cloudy part of a tile
//! becomes one cloud:
//!
//! 1. Candidate centres fill the tile over the band where the tile's cloud type can have cloud
//!    (its height profile), and Wang 2003's cull thins them to one per cull radius: the tile's
//!    [`TileDraft`]. None of this depends on coverage, so a sequence whose coverage changes keeps
//!    every sprite in place, and an edit of coverage keeps the drafts.
//! 2. The coarse field (weather, height profile, base noise: the density the ray marcher's light
//!    paths read) is read at every candidate of every new tile at once, by a
//!    [`CoarseFieldReader`] (the GPU in a frame). Where it is clear, the sprite is dropped;
//!    elsewhere it is as opaque as the matter of its cell. As coverage grows, the densest cores
//!    appear first and the edges last, so clouds form from the core and dissipate from the edges
//!    (Wang 2003, "Animation"), as the field's clouds do.
//! 3. The cloud's boxes are the columns of a 3 x 3 split of the tile, each from its lowest sprite
//!    bottom to its highest top: a footprint, base and top that follow the field.

use glam::{IVec2, Vec2, Vec3};
use rayon::prelude::*;

use super::model::{SpriteBox, SpriteCloud, assign_groups, cull, dress, unit_random};
use super::shading::MAX_SPRITE_OPTICAL_DEPTH;
use crate::field::noise::pcg_hash;
use crate::field::{CloudField, CoarseFieldReader, LayerField, profile};
use crate::particles::generate::world_point;
use crate::scene::CloudType;

/// Candidates where the coarse density (of the layer's densest) is below this are dropped.
pub const MIN_DENSITY: f32 = 0.0025;
/// A field sprite of a sheet is at least this many times as wide as the sheet's sprites are
/// apart, so that they overlap into one veil (the recipes size sprites by the cloud's height,
/// which leaves a thin deck small puffs with gaps between them; 4 measured by eye on the thin
/// stratus deck, 2 and 3 still leave a mackerel sky).
const MIN_WIDTH_PER_SPACING: f32 = 4.0;
/// A field cloud's nominal height, which its cull radius and sprite sizes are fractions of, as a
/// fraction of the band its type can fill: cumulus rarely fill the whole band (tuned by eye
/// against the ray marcher on the default scene).
const NOMINAL_HEIGHT: f32 = 0.6;
/// Candidates drawn per cull-radius cell of the band: enough that the cull, not the draw, sets the
/// spacing.
const CANDIDATES_PER_CELL: f32 = 2.0;
/// Most candidates a tile draws.
const MAX_CANDIDATES: u32 = 600;
/// Columns along each side of a tile that the cloud's boxes follow.
const BOX_COLUMNS: i32 = 3;
/// Height fractions at which the band of a type's profile is searched.
const BAND_STEPS: u32 = 32;
/// Heights at which a sheet's column is read under each of its sprites: a sheet's sprite stands for
/// the whole column of the deck at its place, so its opacity follows the column's mean extinction,
/// not the extinction at the candidate's own height (in a thin deck that jumps from the profile's
/// peak to nothing across the band, and broke the thin stratus into streaks of blue sky). Four
/// midpoints hold a sprite's matter within 8 % of the column integrated finely (tested; two
/// Gauss-Legendre nodes missed by 18 %).
const SHEET_COLUMN_READS: usize = 4;
/// Most candidates a sheet's tile draws: its sprites are sized by their spacing, not by the cull,
/// so fewer, wider ones make the same deck, and the column's reads cost no more than one read at
/// each of [`MAX_CANDIDATES`] (the overcast sky's build stays within 0.3 s).
const MAX_SHEET_CANDIDATES: u32 = MAX_CANDIDATES / SHEET_COLUMN_READS as u32;

/// Where and how far field clouds are made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldTiling {
    /// Side of a tile, m: the largest a field cloud gets.
    pub tile_m: f32,
    /// Tiles whose centre lies within this horizontal distance of the camera are made, m.
    pub distance_m: f32,
    /// Scene time, s (tiles move with the wind).
    pub time_s: f32,
}

/// One tile of one layer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TileKey {
    /// Layer index.
    pub layer: u32,
    /// Tile lattice position in the layer's wind frame, (x, z).
    pub tile: [i32; 2],
}

impl FieldTiling {
    /// The tiles around `camera_m` in every layer, nearest layer first then row by row.
    pub fn tiles_around(&self, field: &CloudField, camera_m: Vec3) -> Vec<TileKey> {
        let mut keys = Vec::new();
        for (index, layer) in field.layers.iter().enumerate() {
            let eye = self.wind_frame(layer, Vec2::new(camera_m.x, camera_m.z));
            let reach = (self.distance_m / self.tile_m).ceil() as i32 + 1;
            let centre = (eye / self.tile_m).floor().as_ivec2();
            for dz in -reach..=reach {
                for dx in -reach..=reach {
                    let tile = centre + IVec2::new(dx, dz);
                    let mid = (tile.as_vec2() + 0.5) * self.tile_m;
                    if mid.distance(eye) <= self.distance_m {
                        keys.push(TileKey {
                            layer: index as u32,
                            tile: tile.to_array(),
                        });
                    }
                }
            }
        }
        keys
    }

    /// A world position `xz` at this time in the wind frame of `layer` (where it was at time 0).
    pub fn wind_frame(&self, layer: &LayerField, xz: Vec2) -> Vec2 {
        xz - layer.wind_m_per_s * self.time_s
    }

    /// The clouds of `keys` (None where a tile is clear), their densities read by `reader` at
    /// this tiling's time.
    pub fn clouds(
        &self,
        field: &CloudField,
        keys: &[TileKey],
        reader: &dyn CoarseFieldReader,
    ) -> Vec<Option<SpriteCloud>> {
        let drafts: Vec<Option<TileDraft>> =
            keys.par_iter().map(|&key| self.draft(field, key)).collect();
        let drafts: Vec<Option<&TileDraft>> = drafts.iter().map(Option::as_ref).collect();
        self.finish(field, &drafts, reader)
    }

    /// The clouds of `drafts`, each from its candidates' densities: every candidate of every
    /// draft read in one call to `reader`, at this tiling's time.
    pub fn finish(
        &self,
        field: &CloudField,
        drafts: &[Option<&TileDraft>],
        reader: &dyn CoarseFieldReader,
    ) -> Vec<Option<SpriteCloud>> {
        let points: Vec<Vec3> = drafts
            .iter()
            .flatten()
            .flat_map(|d| {
                let wind = layer_drift_m(&field.layers[d.layer as usize], self.time_s);
                d.read_points_m().iter().map(move |&p| p + wind)
            })
            .collect();
        let extinctions = reader.coarse_extinctions_per_m(&points);
        // Baked here, outside the parallel loop: a lazy bake inside it would wait on itself.
        let cover = super::textures::mean_cover();
        let mut at = 0;
        let mut read = Vec::with_capacity(drafts.len());
        for draft in drafts {
            read.push(draft.map(|d| {
                let span = at..at + d.read_points_m().len();
                at = span.end;
                (d, span)
            }));
        }
        read.into_par_iter()
            .map(|r| {
                let (draft, span) = r?;
                let layer = &field.layers[draft.layer as usize];
                draft.finish(&extinctions[span], layer.extinction_per_m, cover)
            })
            .collect()
    }

    /// The draft of one tile's cloud, in the layer's wind frame at time 0: its type and its
    /// candidate sprites after the cull, nothing that coverage changes (no density is read);
    /// None where the tile's type has no band to fill.
    pub fn draft(&self, field: &CloudField, key: TileKey) -> Option<TileDraft> {
        let layer = &field.layers[key.layer as usize];
        let tile = IVec2::from_array(key.tile);
        let origin = tile.as_vec2() * self.tile_m;
        let middle = origin + 0.5 * self.tile_m;
        let weather = field
            .weather
            .texture
            .sample((middle / field.weather.extent_m + layer.weather_offset).extend(0.0));
        let type_coord = layer.types.type_coord(weather.y);
        let (bottom, top) = profile_band(layer, type_coord)?;
        let height_m = NOMINAL_HEIGHT * (top - bottom).min(self.tile_m);
        let cloud_type = CloudType::from_field(type_coord, bottom, height_m);
        let recipe = cloud_type.recipe();
        let seed = pcg_hash(
            pcg_hash(layer.noise_offset_m.x.to_bits())
                ^ pcg_hash(tile.x as u32 ^ pcg_hash(tile.y as u32)),
        );
        let radius = recipe.cull_fraction * height_m;
        let cells = self.tile_m * self.tile_m * (top - bottom) / radius.powi(3);
        let most = match recipe.sheet {
            true => MAX_SHEET_CANDIDATES,
            false => MAX_CANDIDATES,
        };
        let n = ((cells * CANDIDATES_PER_CELL) as u32).clamp(recipe.sprites, most);
        let candidates: Vec<Vec3> = (0..n)
            .map(|k| {
                let u = |lane| unit_random(seed, k, lane);
                let xz = origin + Vec2::new(u(0), u(1)) * self.tile_m;
                Vec3::new(xz.x, bottom + u(2) * (top - bottom), xz.y)
            })
            .collect();
        let kept = cull(&candidates, radius);
        let points_m: Vec<Vec3> = kept
            .iter()
            .map(|c| world_point(field, Vec2::new(c.x, c.z), c.y))
            .collect();
        let column_reads_m = match recipe.sheet {
            true => kept
                .iter()
                .flat_map(|c| {
                    (0..SHEET_COLUMN_READS).map(move |i| {
                        let share = (i as f32 + 0.5) / SHEET_COLUMN_READS as f32;
                        world_point(field, Vec2::new(c.x, c.z), bottom + share * (top - bottom))
                    })
                })
                .collect(),
            false => Vec::new(),
        };
        let cell_m3 = self.tile_m * self.tile_m * (top - bottom) / points_m.len().max(1) as f32;
        Some(TileDraft {
            cloud_type,
            seed,
            centre_m: world_point(field, middle, 0.5 * (bottom + top)),
            height_m,
            layer: key.layer,
            tile_m: self.tile_m,
            points_m,
            column_reads_m,
            cell_m3,
        })
    }
}

/// A field sprite's opacity: the optical depth its puff needs to hold the matter of its cell,
/// `cell_m3` of cloud of extinction `extinction_per_m` (puffs of mean cover `cover`,
/// [`super::textures::mean_cover`]), over [`MAX_SPRITE_OPTICAL_DEPTH`] (a field
/// sprite's optical depth is its opacity times that). The puff's optical depth integrated over its
/// quad, `tau m w h` (`m` the puffs' mean normalised column density), equals the cell's `sigma V`:
/// summed over overlapping sprites, a view through the cloud meets the field's optical depth,
/// however many sprites stand for it. Above 1 where the cell holds more than a puff at the bound
/// shows: the blend stops the puff's opacity at the bound (its soft rim), its light keeps the whole
/// matter (`sprite_render.wgsl`).
fn mass_opacity(extinction_per_m: f32, (cell_m3, cover): (f32, f32), size_m: Vec2) -> f32 {
    let tau = extinction_per_m * cell_m3 / (cover * size_m.x * size_m.y);
    (tau / MAX_SPRITE_OPTICAL_DEPTH).max(0.0)
}

impl TileDraft {
    /// The least width of the sprites at `present` (the candidates where the tile is cloudy),
    /// m: for a sheet ([`super::types::Recipe::sheet`]), [`MIN_WIDTH_PER_SPACING`] times how far
    /// apart they lie across the tile (a deck covers its tiles); none for other clouds, whose
    /// recipe sizes overlap.
    fn least_width_m(&self, recipe: &super::types::Recipe, present: usize) -> f32 {
        match recipe.sheet {
            true => MIN_WIDTH_PER_SPACING * self.tile_m / (present.max(1) as f32).sqrt(),
            false => 0.0,
        }
    }
}

/// How far `layer`'s wind has carried its clouds by `time_s`, m.
fn layer_drift_m(layer: &LayerField, time_s: f32) -> Vec3 {
    let drift = layer.wind_m_per_s * time_s;
    Vec3::new(drift.x, 0.0, drift.y)
}

/// A tile's cloud before the field's density is read (made once per tile, kept through coverage
/// edits): its type and its candidate sprites after Wang 2003's cull.
#[derive(Clone, Debug)]
pub struct TileDraft {
    cloud_type: CloudType,
    seed: u32,
    /// The cloud's centre, in the layer's wind frame at time 0, m.
    centre_m: Vec3,
    /// The cloud's nominal height, which its sprite sizes are fractions of, m.
    height_m: f32,
    layer: u32,
    tile_m: f32,
    /// The candidates' centres after the cull, in the layer's wind frame at time 0, m.
    points_m: Vec<Vec3>,
    /// A sheet's: [`SHEET_COLUMN_READS`] points across the band under each candidate, where its
    /// extinction is read (empty for other clouds, read at the candidates), m.
    column_reads_m: Vec<Vec3>,
    /// The volume of cloud each candidate stands for: the band over the tile, shared out, m^3.
    cell_m3: f32,
}

impl TileDraft {
    /// Its candidate sprites: what finishing it reads of the field.
    pub fn candidates(&self) -> usize {
        self.points_m.len()
    }

    /// Where the field is read for the candidates: each candidate's column for a sheet, else the
    /// candidates themselves.
    fn read_points_m(&self) -> &[Vec3] {
        match self.column_reads_m.is_empty() {
            true => &self.points_m,
            false => &self.column_reads_m,
        }
    }

    /// The cloud of the candidates where the field is cloudy (`extinctions_per_m`, read at
    /// [`Self::read_points_m`], of a layer whose densest extinction is
    /// `layer_extinction_per_m`), each sprite wide enough to overlap its neighbours and as opaque
    /// as the matter of its cell (puffs of mean cover `cover`); None where the tile is clear.
    fn finish(
        &self,
        extinctions_per_m: &[f32],
        layer_extinction_per_m: f32,
        cover: f32,
    ) -> Option<SpriteCloud> {
        let recipe = self.cloud_type.recipe();
        let reads = extinctions_per_m.len() / self.points_m.len().max(1);
        let means = extinctions_per_m
            .chunks(reads.max(1))
            .map(|column| column.iter().sum::<f32>() / column.len() as f32);
        let present: Vec<(usize, Vec3, f32)> = self
            .points_m
            .iter()
            .zip(means)
            .enumerate()
            .filter(|(_, (_, e))| *e >= MIN_DENSITY * layer_extinction_per_m)
            .map(|(k, (&p, e))| (k, p, e))
            .collect();
        let least_width_m = self.least_width_m(&recipe, present.len());
        let sprites: Vec<_> = present
            .into_iter()
            .map(|(k, p, extinction)| {
                let offset = p - self.centre_m;
                let mut s = dress(&recipe, self.seed, k as u32, offset, self.height_m);
                s.size_m *= (least_width_m / s.size_m.x).max(1.0);
                s.opacity = mass_opacity(extinction, (self.cell_m3, cover), s.size_m);
                s
            })
            .collect();
        if sprites.is_empty() {
            return None;
        }
        let mut cloud = SpriteCloud {
            cloud_type: self.cloud_type,
            center_m: self.centre_m,
            boxes: Vec::new(),
            layer: Some(self.layer),
            sprites,
        };
        cloud.boxes = column_boxes(&cloud, self.tile_m);
        assign_groups(&mut cloud.sprites, recipe.group_size);
        Some(cloud)
    }
}

/// The altitudes where a layer's cloud of type coordinate `type_coord` can have density (its
/// height gradient is positive), m; None if nowhere.
pub fn profile_band(layer: &LayerField, type_coord: f32) -> Option<(f32, f32)> {
    let inside: Vec<f32> = (0..=BAND_STEPS)
        .map(|i| i as f32 / BAND_STEPS as f32)
        .filter(|&f| profile::height_gradient(type_coord, f) > 0.0)
        .collect();
    let (lo, hi) = (*inside.first()?, *inside.last()?);
    let step = 1.0 / BAND_STEPS as f32;
    let at = |f: f32| layer.bottom_m + f.clamp(0.0, 1.0) * layer.thickness_m;
    Some((at(lo - step), at(hi + step)))
}

/// The boxes of a field cloud: each of the tile's columns that holds sprites, from its lowest
/// sprite bottom to its highest top (relative to the cloud's centre).
fn column_boxes(cloud: &SpriteCloud, tile_m: f32) -> Vec<SpriteBox> {
    let column_m = tile_m / BOX_COLUMNS as f32;
    let mut boxes = Vec::new();
    for cz in 0..BOX_COLUMNS {
        for cx in 0..BOX_COLUMNS {
            let lo = Vec2::new(cx as f32, cz as f32) * column_m - 0.5 * tile_m;
            let inside = |s: &&super::model::Sprite| {
                let d = Vec2::new(s.offset_m.x, s.offset_m.z) - lo;
                d.cmpge(Vec2::ZERO).all() && d.cmplt(Vec2::splat(column_m)).all()
            };
            let (bottom, top) =
                cloud
                    .sprites
                    .iter()
                    .filter(inside)
                    .fold((f32::MAX, f32::MIN), |(b, t), s| {
                        let half = 0.5 * s.size_m.y;
                        (b.min(s.offset_m.y - half), t.max(s.offset_m.y + half))
                    });
            if bottom < top {
                boxes.push(SpriteBox {
                    center_m: Vec3::new(
                        lo.x + 0.5 * column_m,
                        0.5 * (bottom + top),
                        lo.y + 0.5 * column_m,
                    ),
                    size_m: Vec3::new(column_m, top - bottom, column_m),
                });
            }
        }
    }
    boxes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::CpuCoarseReader;
    use crate::scene::{Scene, SceneDocument};
    use std::path::Path;

    fn field(coverage: f32) -> CloudField {
        let mut scene = Scene::default();
        scene.layers[0].coverage = coverage;
        CloudField::new(&scene, Path::new(".")).unwrap()
    }

    const TILING: FieldTiling = FieldTiling {
        tile_m: 1500.0,
        distance_m: 5000.0,
        time_s: 0.0,
    };

    #[test]
    fn field_clouds_sit_where_the_field_is_cloudy_and_form_from_their_cores() {
        let (thin, thick) = (field(0.35), field(0.6));
        let keys = TILING.tiles_around(&thin, glam::Vec3::ZERO);
        let read = |f| CpuCoarseReader {
            field: f,
            time_s: 0.0,
        };
        let made = TILING.clouds(&thin, &keys, &read(&thin));
        let clouds: Vec<_> = keys
            .iter()
            .zip(made)
            .filter_map(|(k, c)| Some((k, c?)))
            .collect();
        assert!(
            !clouds.is_empty() && clouds.len() < keys.len(),
            "{} of {}",
            clouds.len(),
            keys.len()
        );
        let mut grown = 0;
        for (key, cloud) in &clouds {
            for s in &cloud.sprites {
                let p = cloud.center_m + s.offset_m;
                assert!(
                    thin.coarse_extinction_per_m(p, 0.0) > 0.0,
                    "a sprite in clear air at {p}"
                );
                assert!(cloud.boxes.iter().any(|b| {
                    ((s.offset_m - b.center_m).abs())
                        .cmple(b.size_m * 0.5 + 1.0)
                        .all()
                }));
            }
            // More coverage keeps every sprite where it was, at least as opaque, and adds more:
            // clouds grow from their cores outward and dissipate back from their edges.
            let more = TILING.clouds(&thick, &[**key], &read(&thick))[0]
                .clone()
                .expect("a cloud stays when coverage grows");
            for s in &cloud.sprites {
                let same = more
                    .sprites
                    .iter()
                    .find(|m| m.offset_m.distance(s.offset_m) < 1e-2);
                let same = same.expect("a sprite vanished as coverage grew");
                assert!(same.opacity >= s.opacity - 1e-6);
            }
            grown += more.sprites.len() - cloud.sprites.len();
        }
        assert!(grown > 0);
    }

    #[test]
    fn a_clear_sky_makes_no_field_clouds() {
        let clear = field(0.0);
        let keys = TILING.tiles_around(&clear, glam::Vec3::ZERO);
        let read = CpuCoarseReader {
            field: &clear,
            time_s: 0.0,
        };
        assert!(
            TILING
                .clouds(&clear, &keys, &read)
                .iter()
                .all(Option::is_none)
        );
    }

    #[test]
    fn tiles_ride_the_wind() {
        let f = field(0.45);
        let later = FieldTiling {
            time_s: 600.0,
            ..TILING
        };
        let wind = f.layers[0].wind_m_per_s * 600.0;
        let eye = glam::Vec3::new(wind.x, 0.0, wind.y);
        assert_eq!(
            TILING.tiles_around(&f, glam::Vec3::ZERO),
            later.tiles_around(&f, eye)
        );
    }

    /// Each field sprite's puff holds the matter of its cell (`sigma V`, the extinction at its
    /// centre times the volume each candidate stands for), and a sheet's sprites are wide enough
    /// to overlap into a veil.
    #[test]
    fn field_sprites_hold_the_matter_of_their_cells_and_sheets_overlap_over_their_columns() {
        let mut scene = Scene::default();
        scene.layers[0].coverage = 0.6;
        let f = CloudField::new(&scene, Path::new(".")).unwrap();
        let read = CpuCoarseReader {
            field: &f,
            time_s: 0.0,
        };
        let keys = TILING.tiles_around(&f, glam::Vec3::ZERO);
        let mut checked = 0;
        for key in keys.iter().take(12) {
            let Some(draft) = TILING.draft(&f, *key) else {
                continue;
            };
            let Some(cloud) = TILING.clouds(&f, &[*key], &read)[0].clone() else {
                continue;
            };
            for s in &cloud.sprites {
                let p = cloud.center_m + s.offset_m;
                let held = s.opacity
                    * MAX_SPRITE_OPTICAL_DEPTH
                    * super::super::textures::mean_cover()
                    * s.size_m.x
                    * s.size_m.y;
                let matter = f.coarse_extinction_per_m(p, 0.0) * draft.cell_m3;
                assert!((held - matter).abs() <= 1e-3 * matter, "{held} vs {matter}");
                checked += 1;
            }
        }
        assert!(checked > 25, "{checked}");

        // A thin stratus deck: its sprites lie at least a quarter of their width apart.
        let deck = SceneDocument::parse(
            "[[layers]]\nbottom_m = 700.0\nthickness_m = 400.0\ncoverage = 0.97\n\
             types = { stratus = 1.0 }\n",
            "deck",
            Path::new("."),
            &[],
        )
        .unwrap()
        .scene;
        let f = CloudField::new(&deck, Path::new(".")).unwrap();
        let read = CpuCoarseReader {
            field: &f,
            time_s: 0.0,
        };
        let key = TILING.tiles_around(&f, glam::Vec3::ZERO)[0];
        let cloud = TILING.clouds(&f, &[key], &read)[0].clone().expect("a deck");
        assert!(cloud.cloud_type.recipe().sheet);
        let spacing = TILING.tile_m / (cloud.sprites.len() as f32).sqrt();
        assert!(
            cloud.sprites.iter().all(|s| s.size_m.x >= 3.99 * spacing),
            "{spacing}"
        );

        // A sheet's sprite holds the matter of the deck's whole column at its place (integrated
        // finely here), whatever height its candidate was drawn at.
        let draft = TILING.draft(&f, key).unwrap();
        let mut columns = 0;
        for s in &cloud.sprites {
            let p = cloud.center_m + s.offset_m;
            let steps = 256;
            let column: f32 = (0..steps)
                .map(|i| {
                    let y = 700.0 + (i as f32 + 0.5) / steps as f32 * 400.0;
                    let at = world_point(&f, Vec2::new(p.x, p.z), y);
                    f.coarse_extinction_per_m(at, 0.0)
                })
                .sum::<f32>()
                * 400.0
                / steps as f32;
            let matter = column * TILING.tile_m * TILING.tile_m / draft.candidates() as f32;
            let held = s.opacity
                * MAX_SPRITE_OPTICAL_DEPTH
                * super::super::textures::mean_cover()
                * s.size_m.x
                * s.size_m.y;
            assert!((held - matter).abs() <= 0.08 * matter, "{held} vs {matter}");
            columns += 1;
        }
        assert!(columns > 10, "{columns}");
    }
}
