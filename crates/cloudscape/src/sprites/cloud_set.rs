//! Every sprite cloud of a scene, kept up to date on the CPU and laid out for the GPU: field clouds
//! in the tiles around the camera (made as the camera reaches them, kept while it stays near), the
//! hand-made clouds and those of a model file; each cloud's colour levels and each shading
//! group's light for the current sun.

use std::collections::BTreeMap;
use std::path::Path;

use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3, Vec4};

use super::field_tiles::{FieldTiles, TilesChanged};
use super::from_field::{FieldTiling, TileKey};
use super::model::SpriteCloud;
use super::shading::{self, ColorLevel, LEVELS, SunLight, physical_levels};
use super::{CloudModel, ModelFile};
use crate::field::{CloudField, CoarseFieldReader, CpuCoarseReader, FieldError};
use crate::optics::PhaseLobes;
use crate::particles::DEFAULT_EXTINCTION_PER_M;
use crate::scene::{Scene, SpriteCloudSpec, SpriteLod};

/// `layer` of a sprite no wind carries.
pub const NO_LAYER: u32 = 4;
/// The sun must turn this far before the groups' light is recomputed, radians (0.2 degrees).
const SUN_TOLERANCE_RAD: f32 = 0.0035;

/// One sprite as `sprite_render.wgsl` reads it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuSprite {
    /// Centre at time 0 in its layer's wind frame, m.
    pub position_m: Vec3,
    /// The layer whose wind carries it; [`NO_LAYER`]: none.
    pub layer: u32,
    /// Width and height, m.
    pub size_m: Vec2,
    /// Rotation about the view axis, radians.
    pub rotation_rad: f32,
    /// Tile of the puff sheet.
    pub texture: u32,
    /// Index of its cloud.
    pub cloud: u32,
    /// Optical depth through its densest column.
    pub optical_depth: f32,
    /// Its group's directional factor, 0..1.
    pub directional: f32,
    /// Direct sun reaching its group, 0..1.
    pub sun_transmittance: f32,
}

/// One cloud's colour levels and vertical extent as `sprite_render.wgsl` reads them.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GpuCloud {
    /// Ambient fraction and opacity of each level.
    pub colors: [Vec4; LEVELS],
    /// Height fractions of levels 0..3.
    pub level_heights: Vec4,
    /// Height fraction of level 4.
    pub top_level_height: f32,
    /// World y of the cloud's bottom, m.
    pub bottom_y_m: f32,
    /// Bottom to top, m.
    pub height_m: f32,
    pad: f32,
}

impl GpuCloud {
    fn new(levels: &[ColorLevel; LEVELS], bottom_y_m: f32, height_m: f32) -> GpuCloud {
        GpuCloud {
            colors: levels.map(|l| l.rgba),
            level_heights: Vec4::from_array(std::array::from_fn(|i| levels[i].height)),
            top_level_height: levels[LEVELS - 1].height,
            bottom_y_m,
            height_m,
            pad: 0.0,
        }
    }
}

/// A cloud to lay out: the cloud, its colour levels (None: derived) and whether the field made it.
type Laid<'a> = (&'a SpriteCloud, Option<[ColorLevel; LEVELS]>, bool);

/// One cloud laid out for the GPU.
struct LaidCloud {
    cloud: GpuCloud,
    sprites: Vec<GpuSprite>,
    /// Its centre at time 0 (wind frame) and its layer ([`CloudSet::cloud_centres`]).
    centre: (Vec3, u32),
}

/// The scene's sprite clouds and their GPU records.
pub struct CloudSet {
    authored: Vec<Authored>,
    /// The field's clouds, tile by tile (None when the scene makes none).
    field_tiles: Option<FieldTiles>,
    /// Each field tile's cloud laid out for the GPU, kept until the tile is remade or the light
    /// changes, so that a frame that remakes a few tiles lays out only those.
    laid: BTreeMap<TileKey, Option<LaidCloud>>,
    scene_key: String,
    draft_key: String,
    layout_key: String,
    /// The light of the configured scene, toward the sun the groups were last lit by.
    light: SunLight,
    /// Extinction of clouds of no layer (hand-made), m^-1: the densest layer's.
    default_extinction_per_m: f32,
    lod: SpriteLod,
    /// Whether field clouds are lit on the GPU from the light volume (no group light here).
    lit_by_volume: bool,
    /// The sprites, cloud by cloud.
    pub sprites: Vec<GpuSprite>,
    /// The clouds.
    pub clouds: Vec<GpuCloud>,
    /// Per cloud: its centre at time 0 (wind frame) and its layer.
    pub cloud_centres: Vec<(Vec3, u32)>,
    /// Bumped whenever `sprites` or `clouds` change.
    pub generation: u64,
}

impl Default for CloudSet {
    /// An empty set, to be configured by [`CloudSet::configure`].
    fn default() -> CloudSet {
        CloudSet {
            authored: Vec::new(),
            field_tiles: None,
            laid: BTreeMap::new(),
            scene_key: String::new(),
            draft_key: String::new(),
            layout_key: String::new(),
            light: SunLight::default(),
            default_extinction_per_m: DEFAULT_EXTINCTION_PER_M,
            lod: SpriteLod::Clusters,
            lit_by_volume: false,
            sprites: Vec::new(),
            clouds: Vec::new(),
            cloud_centres: Vec::new(),
            generation: 0,
        }
    }
}

impl CloudSet {
    /// Takes `scene`'s settings and its hand-made and model-file clouds `authored` (with their
    /// levels, None to derive them, as [`authored_clouds`] reads them); the next
    /// [`CloudSet::update`] makes again what depends on anything that changed. After an edit that
    /// keeps the drafts (coverage, lighting, the phase function) the field's clouds are stale and
    /// remade as [`FieldTiles::update`] says.
    pub fn configure(&mut self, scene: &Scene, authored: &[Authored]) {
        let key = scene_key(scene, authored);
        if key == self.scene_key {
            return;
        }
        self.scene_key = key;
        let (draft_key, layout_key) = (draft_key(scene), layout_key(scene));
        let tiling = scene.sprites.field_clouds.then_some(FieldTiling {
            tile_m: scene.sprites.cloud_size_m,
            distance_m: scene.sprites.distance_m,
            time_s: 0.0,
        });
        match (self.field_tiles.as_mut(), tiling) {
            (Some(tiles), Some(_)) if draft_key == self.draft_key => tiles.mark_stale(),
            (_, tiling) => self.field_tiles = tiling.map(FieldTiles::new),
        }
        if (&draft_key, &layout_key) != (&self.draft_key, &self.layout_key) {
            self.laid.clear();
        }
        (self.draft_key, self.layout_key) = (draft_key, layout_key);
        self.authored = authored.to_vec();
        self.sprites.clear();
        self.clouds.clear();
        self.lod = scene.sprites.lod;
        self.lit_by_volume = scene.lighting.model == crate::scene::LightingModel::Volume;
        let g = PhaseLobes::from_scene(&scene.phase).mean_cosine();
        self.light = SunLight::from_scene(scene, Vec3::ZERO, g);
        self.default_extinction_per_m = scene
            .layers
            .iter()
            .map(|l| l.extinction_per_m)
            .reduce(f32::max)
            .unwrap_or(DEFAULT_EXTINCTION_PER_M);
    }

    /// Brings the set to this frame: makes the field clouds of tiles the camera reached (their
    /// candidates' densities read by `reader`, at `time_s`), forgets those it left, remakes stale
    /// ones (all, or within `refresh_budget` candidates: [`FieldTiles::update`]) and relights the
    /// groups when the sun turned. Returns whether the records changed.
    pub fn update(
        &mut self,
        field: &CloudField,
        reader: &dyn CoarseFieldReader,
        (camera_m, sun): (Vec3, Vec3),
        time_s: f32,
        refresh_budget: Option<usize>,
    ) -> bool {
        let mut changed = TilesChanged::default();
        if let Some(tiles) = self.field_tiles.as_mut() {
            tiles.tiling.time_s = time_s;
            changed = tiles.update(field, reader, camera_m, refresh_budget);
        }
        let lit = self.light.sun;
        let relight = lit.angle_between(sun) > SUN_TOLERANCE_RAD || lit == Vec3::ZERO;
        let empty = self.sprites.is_empty() && self.clouds.is_empty();
        if !(empty || changed.any() || relight) {
            return false;
        }
        self.light.sun = sun;
        if relight && !self.lit_by_volume {
            self.laid.clear();
        }
        // Tiles the camera left go in `rebuild`, with every tile no longer made.
        for key in &changed.made {
            self.laid.remove(key);
        }
        self.rebuild(field);
        self.generation += 1;
        true
    }

    /// Field tiles whose cloud is still the one made before the last edit of coverage.
    pub fn stale_tiles(&self) -> usize {
        self.field_tiles.as_ref().map_or(0, FieldTiles::stale_count)
    }

    /// Lays out the field tiles not laid out yet and the hand-made clouds, and gathers every
    /// cloud's records.
    fn rebuild(&mut self, field: &CloudField) {
        let empty = BTreeMap::new();
        let tiles = self.field_tiles.as_ref().map_or(&empty, |t| &t.tiles);
        self.laid.retain(|k, _| tiles.contains_key(k));
        let unlaid: Vec<(&TileKey, &Option<SpriteCloud>)> = tiles
            .iter()
            .filter(|(k, _)| !self.laid.contains_key(k))
            .collect();
        let newly: Vec<Option<LaidCloud>> = {
            use rayon::prelude::*;
            unlaid
                .par_iter()
                .map(|(_, cloud)| cloud.as_ref().map(|c| self.lay_out((c, None, true), field)))
                .collect()
        };
        let keys: Vec<TileKey> = unlaid.iter().map(|(k, _)| **k).collect();
        self.laid.extend(keys.into_iter().zip(newly));
        let authored: Vec<LaidCloud> = self
            .authored
            .iter()
            .map(|(cloud, levels)| self.lay_out((cloud, *levels, false), field))
            .collect();
        self.sprites.clear();
        self.clouds.clear();
        self.cloud_centres.clear();
        let all = authored.iter().chain(self.laid.values().flatten());
        for (index, laid) in all.enumerate() {
            self.cloud_centres.push(laid.centre);
            self.clouds.push(laid.cloud);
            self.sprites.extend(laid.sprites.iter().map(|s| GpuSprite {
                cloud: index as u32,
                ..*s
            }));
        }
    }

    /// One cloud laid out for the GPU (its sprites' `cloud` index set by the caller), lit at
    /// its layer's extinction.
    fn lay_out(&self, (placed, levels, from_field): Laid, field: &CloudField) -> LaidCloud {
        let extinction = placed
            .layer
            .and_then(|l| field.layers.get(l as usize))
            .map_or(self.default_extinction_per_m, |l| l.extinction_per_m);
        let light = &self.light.with_extinction(extinction);
        let billboard;
        let cloud = match self.lod {
            SpriteLod::Clusters => placed,
            SpriteLod::Billboards => {
                billboard = placed.billboard();
                &billboard
            }
        };
        let (lo, hi) = placed.vertical_extent_m();
        let height = (hi - lo).max(1.0);
        let levels =
            levels.unwrap_or_else(|| physical_levels(height, light.extinction_per_m, light.g));
        let lights = match (from_field, self.lit_by_volume) {
            (true, true) => vec![shading::GroupLight::default(); cloud.group_count() as usize],
            (from_field, _) => shading::group_lights(cloud, from_field.then_some(field), light),
        };
        let layer = cloud.layer.unwrap_or(NO_LAYER);
        let sprites = cloud
            .sprites
            .iter()
            .map(|s| {
                let group = lights[s.group as usize];
                GpuSprite {
                    position_m: cloud.center_m + s.offset_m,
                    layer,
                    size_m: s.size_m,
                    rotation_rad: s.rotation_rad,
                    texture: s.texture,
                    cloud: 0,
                    optical_depth: match from_field {
                        true => s.opacity * shading::MAX_SPRITE_OPTICAL_DEPTH,
                        false => {
                            s.opacity
                                * shading::sprite_optical_depth(light.extinction_per_m, s.size_m.x)
                        }
                    },
                    directional: group.directional,
                    sun_transmittance: group.sun_transmittance,
                }
            })
            .collect();
        LaidCloud {
            cloud: GpuCloud::new(&levels, cloud.center_m.y + lo, height),
            sprites,
            centre: (placed.center_m, layer),
        }
    }

    /// The sun's light as last lit, at the extinction of clouds of no layer.
    pub(super) fn light(&self) -> SunLight {
        self.light.with_extinction(self.default_extinction_per_m)
    }

    /// Whether the field's clouds are drawn.
    pub(super) fn has_field_clouds(&self) -> bool {
        self.field_tiles.is_some()
    }

    /// The hand-made and model-file clouds, with their colour levels (None: derived).
    pub(super) fn authored_clouds(
        &self,
    ) -> impl Iterator<Item = (&SpriteCloud, Option<[ColorLevel; LEVELS]>)> {
        self.authored.iter().map(|(cloud, levels)| (cloud, *levels))
    }

    /// Every cloud drawn, as the model file would hold it (field clouds as made this frame).
    pub fn sprite_clouds(&self) -> Vec<SpriteCloud> {
        self.authored
            .iter()
            .map(|(cloud, _)| cloud.clone())
            .chain(
                self.field_tiles
                    .iter()
                    .flat_map(|t| t.tiles.values().flatten().cloned()),
            )
            .collect()
    }
}

/// Every sprite cloud of `scene` at its time: the hand-made ones, those of its model file (files
/// resolve against `base_dir`) and the field's around the camera (what `cloudscape export
/// --sprites` writes).
pub fn scene_clouds(
    scene: &Scene,
    field: &CloudField,
    base_dir: &Path,
) -> Result<Vec<SpriteCloud>, FieldError> {
    let mut clouds: Vec<SpriteCloud> = authored_clouds(scene, base_dir)?
        .into_iter()
        .map(|(cloud, _)| cloud)
        .collect();
    if scene.sprites.field_clouds {
        let tiling = FieldTiling {
            tile_m: scene.sprites.cloud_size_m,
            distance_m: scene.sprites.distance_m,
            time_s: scene.render.time_s,
        };
        let camera = glam::Vec3::from_array(scene.camera.position_m);
        let keys = tiling.tiles_around(field, camera);
        let reader = CpuCoarseReader {
            field,
            time_s: tiling.time_s,
        };
        clouds.extend(tiling.clouds(field, &keys, &reader).into_iter().flatten());
    }
    Ok(clouds)
}

/// A hand-made or model-file cloud with its colour levels (None: derived).
pub type Authored = (SpriteCloud, Option<[ColorLevel; LEVELS]>);

/// The hand-made clouds of `scene` and those of its model file.
pub fn authored_clouds(scene: &Scene, base_dir: &Path) -> Result<Vec<Authored>, FieldError> {
    let mut clouds: Vec<_> = scene
        .sprite_clouds
        .iter()
        .map(|spec| (CloudModel::from_spec(spec).generate(None), levels_of(spec)))
        .collect();
    if let Some(path) = &scene.sprites.model {
        let file = ModelFile::read(&base_dir.join(path)).map_err(|e| FieldError {
            key_path: "sprites.model".into(),
            message: e.to_string(),
        })?;
        clouds.extend(file.clouds().into_iter().map(|c| (c, None)));
    }
    Ok(clouds)
}

/// A hand-made cloud's colour levels, when the scene gives them.
fn levels_of(spec: &SpriteCloudSpec) -> Option<[ColorLevel; LEVELS]> {
    let given = spec.color_levels.as_ref()?;
    Some(std::array::from_fn(|i| {
        let [height, r, g, b, a] = given[i];
        ColorLevel {
            height,
            rgba: Vec4::new(r, g, b, a),
        }
    }))
}

/// What the tiles' drafts depend on: the scene's layers but for their coverage, the weather, the
/// planet and the sprites' settings. An edit of coverage alone keeps every draft.
fn draft_key(scene: &Scene) -> String {
    let layers: Vec<_> = scene
        .layers
        .iter()
        .map(|l| crate::scene::CloudLayer {
            coverage: 0.0,
            ..l.clone()
        })
        .collect();
    format!(
        "{:?}",
        (
            &layers,
            &scene.weather,
            &scene.noise,
            &scene.planet,
            &scene.sprites
        )
    )
}

/// What laying the clouds out depends on besides the drafts and the sun: a change lays every
/// cloud out again.
fn layout_key(scene: &Scene) -> String {
    format!("{:?}", (&scene.lighting, &scene.phase))
}

/// What the clouds depend on besides the camera, time and sun: a change makes again what depends
/// on it ([`CloudSet::configure`]).
fn scene_key(scene: &Scene, authored: &[Authored]) -> String {
    format!(
        "{:?}",
        (
            (&scene.layers, &scene.weather, &scene.noise, &scene.planet),
            (&scene.sprites, &scene.lighting, &scene.phase),
            authored,
        )
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn after_an_edit_of_coverage_the_records_are_a_stills_once_every_tile_is_remade() {
        let scene = |coverage: f32| {
            let mut scene = Scene::default();
            scene.layers[0].coverage = coverage;
            scene.sprites.distance_m = 4000.0;
            scene
        };
        let (before, after) = (scene(0.35), scene(0.6));
        let fields = [&before, &after].map(|s| CloudField::new(s, Path::new(".")).unwrap());
        let read = |field| CpuCoarseReader { field, time_s: 0.0 };
        let view = (
            Vec3::new(0.0, 1200.0, 0.0),
            Vec3::new(0.3, 0.5, 0.2).normalize(),
        );
        let mut live = CloudSet::default();
        live.configure(&before, &[]);
        assert!(live.update(&fields[0], &read(&fields[0]), view, 0.0, Some(1)));
        let old_sprites = live.sprites.len();
        live.configure(&after, &[]);
        let stale = live.stale_tiles();
        assert!(stale > 1);
        assert!(live.update(&fields[1], &read(&fields[1]), view, 0.0, Some(1)));
        assert_eq!(
            live.stale_tiles(),
            stale - 1,
            "one tile a frame at the least budget"
        );
        assert!(
            live.sprites.len() >= old_sprites,
            "the old clouds are drawn until remade"
        );
        while live.stale_tiles() > 0 {
            assert!(live.update(&fields[1], &read(&fields[1]), view, 0.0, Some(1)));
        }
        let mut still = CloudSet::default();
        still.configure(&after, &[]);
        still.update(&fields[1], &read(&fields[1]), view, 0.0, None);
        assert_eq!(live.sprites, still.sprites);
        assert_eq!(live.clouds, still.clouds);
        assert_eq!(live.cloud_centres, still.cloud_centres);
        assert!(!live.update(&fields[1], &read(&fields[1]), view, 0.0, Some(1)));
    }

    #[test]
    fn sprite_records_match_their_wgsl_layout() {
        assert_wgsl_layout!(
            &crate::sprites::render::SPRITE_RENDER_WGSL,
            "Sprite",
            GpuSprite {
                position_m,
                layer,
                size_m,
                rotation_rad,
                texture,
                cloud,
                optical_depth,
                directional,
                sun_transmittance,
            }
        );
        assert_wgsl_layout!(
            &crate::sprites::render::SPRITE_RENDER_WGSL,
            "Cloud",
            GpuCloud {
                colors,
                level_heights,
                top_level_height,
                bottom_y_m,
                height_m,
                pad,
            }
        );
    }
}
