//! Clouds built from boxes (Wang 2003, "Cloud creation"): an artist builds a cloud's shape from
//! boxes, a script fills the boxes with randomly placed sprite centres and culls every sprite
//! whose centre lies within a cull radius of another, and the result is exported to a file.
//! [`CloudModel::generate`] is that script: deterministic from the model's seed.

use glam::{Vec2, Vec3};

use super::textures::texture_in;
use super::types::Recipe;
use crate::field::noise::{hash_to_unit, pcg_hash};
use crate::scene::CloudType;

/// An axis-aligned box of a cloud model, relative to the cloud's centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpriteBox {
    /// Centre of the box relative to the cloud's centre, m.
    pub center_m: Vec3,
    /// Size of the box, m.
    pub size_m: Vec3,
}

impl From<&crate::scene::SpriteBoxSpec> for SpriteBox {
    /// The box a scene or model file describes.
    fn from(spec: &crate::scene::SpriteBoxSpec) -> SpriteBox {
        SpriteBox {
            center_m: Vec3::from_array(spec.center_m),
            size_m: Vec3::from_array(spec.size_m),
        }
    }
}

impl SpriteBox {
    /// Volume, m^3.
    pub fn volume_m3(&self) -> f32 {
        self.size_m.x * self.size_m.y * self.size_m.z
    }

    /// The point at fractions `u` (each 0..1) of the box.
    pub fn point(&self, u: Vec3) -> Vec3 {
        self.center_m + (u - 0.5) * self.size_m
    }
}

/// What an artist builds: a cloud type, its boxes and the seed that fills them.
#[derive(Clone, Debug, PartialEq)]
pub struct CloudModel {
    /// The type: its recipe fills the boxes and its textures dress the sprites.
    pub cloud_type: CloudType,
    /// Centre of the cloud in the world, m.
    pub center_m: Vec3,
    /// The boxes, relative to the centre; at least one.
    pub boxes: Vec<SpriteBox>,
    /// Seed of the random sprite placement.
    pub seed: u32,
    /// The artist's parameters (the type's recipe, or the scene's overrides of it).
    pub recipe: Recipe,
}

/// One textured sprite of a cloud.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sprite {
    /// Centre relative to the cloud's centre, m.
    pub offset_m: Vec3,
    /// Width and height, m.
    pub size_m: Vec2,
    /// Rotation about the view axis, radians.
    pub rotation_rad: f32,
    /// Which of the 16 puff textures (0..16).
    pub texture: u32,
    /// The shading group it belongs to (an index into its cloud's groups).
    pub group: u32,
    /// Opacity: a hand-made sprite's share (0..1) of its chord's optical depth (the type's
    /// opacity); a field sprite's optical depth over the most a puff's opacity shows (the matter
    /// of its cell, `from_field.rs`; above 1 for a cell denser than that).
    pub opacity: f32,
}

/// A cloud ready to draw: its sprites, in generation order, and its shading groups.
#[derive(Clone, Debug, PartialEq)]
pub struct SpriteCloud {
    /// The cloud type.
    pub cloud_type: CloudType,
    /// Centre in the world, m.
    pub center_m: Vec3,
    /// The boxes it was filled from (relative to the centre).
    pub boxes: Vec<SpriteBox>,
    /// The cloud layer whose wind carries it (None: it stays put).
    pub layer: Option<u32>,
    /// The sprites.
    pub sprites: Vec<Sprite>,
}

impl CloudModel {
    /// The model of a hand-made cloud: its type's recipe with the scene's overrides.
    pub fn from_spec(spec: &crate::scene::SpriteCloudSpec) -> CloudModel {
        let mut recipe = spec.cloud_type.recipe();
        if let Some(n) = spec.sprites {
            recipe.sprites = n;
        }
        if let Some([lo, hi]) = spec.width {
            recipe.width = (lo, hi);
        }
        if let Some([lo, hi]) = spec.rotation_deg {
            recipe.rotation_deg = (lo, hi);
        }
        CloudModel {
            cloud_type: spec.cloud_type,
            center_m: Vec3::from_array(spec.center_m),
            boxes: spec.boxes.iter().map(SpriteBox::from).collect(),
            seed: spec.seed,
            recipe,
        }
    }

    /// Height of the cloud: from the lowest box bottom to the highest box top, m.
    pub fn height_m(&self) -> f32 {
        let (lo, hi) = vertical_extent(&self.boxes);
        hi - lo
    }

    /// The cull radius: the recipe's fraction of the cloud's height (Wang 2003).
    pub fn cull_radius_m(&self) -> f32 {
        self.recipe.cull_fraction * self.height_m()
    }

    /// Fills the boxes with `recipe.sprites` candidate centres (each box receives candidates in
    /// proportion to its volume), culls every candidate within the cull radius of an earlier kept
    /// one, and dresses the survivors from the recipe's ranges; `layer` is the wind that carries
    /// the cloud.
    pub fn generate(&self, layer: Option<u32>) -> SpriteCloud {
        let candidates = (0..self.recipe.sprites)
            .map(|k| self.candidate(k))
            .collect::<Vec<_>>();
        let kept = cull(&candidates, self.cull_radius_m());
        let height = self.height_m();
        let sprites = kept
            .iter()
            .enumerate()
            .map(|(k, &offset_m)| dress(&self.recipe, self.seed, k as u32, offset_m, height))
            .collect();
        let mut cloud = SpriteCloud {
            cloud_type: self.cloud_type,
            center_m: self.center_m,
            boxes: self.boxes.clone(),
            layer,
            sprites,
        };
        assign_groups(&mut cloud.sprites, self.recipe.group_size);
        cloud
    }

    /// The `k`th candidate centre: a box chosen by volume, a uniform point within it.
    fn candidate(&self, k: u32) -> Vec3 {
        let u = |lane: u32| unit_random(self.seed, k, lane);
        let total: f32 = self.boxes.iter().map(SpriteBox::volume_m3).sum();
        let mut pick = u(0) * total;
        let chosen = self
            .boxes
            .iter()
            .find(|b| {
                pick -= b.volume_m3();
                pick <= 0.0
            })
            .unwrap_or(&self.boxes[self.boxes.len() - 1]);
        chosen.point(Vec3::new(u(1), u(2), u(3)))
    }
}

/// A uniform number in [0, 1) for candidate `k`, lane `lane` of a cloud seeded `seed`.
pub fn unit_random(seed: u32, k: u32, lane: u32) -> f32 {
    hash_to_unit(pcg_hash(
        seed ^ pcg_hash(k.wrapping_mul(8).wrapping_add(lane)),
    ))
}

/// The candidates that survive Wang 2003's cull: in order, each kept unless its centre lies within
/// `radius_m` of a centre kept before it. So no two kept centres are closer than the radius, and
/// every culled candidate has a kept one within it. The kept centres are listed in a grid of cells
/// at least one radius wide, so each candidate looks only at the 27 cells around it.
pub fn cull(candidates: &[Vec3], radius_m: f32) -> Vec<Vec3> {
    let r2 = radius_m * radius_m;
    let grid = CullGrid::new(candidates, radius_m);
    let mut heads = vec![u32::MAX; grid.cells()];
    let mut next: Vec<u32> = Vec::with_capacity(candidates.len());
    let mut kept: Vec<Vec3> = Vec::with_capacity(candidates.len());
    for &c in candidates {
        let home = grid.cell(c);
        let clear = grid.around(home).all(|cell| {
            let mut k = heads[cell];
            while k != u32::MAX {
                if kept[k as usize].distance_squared(c) < r2 {
                    return false;
                }
                k = next[k as usize];
            }
            true
        });
        if clear {
            let slot = grid.index(home);
            next.push(heads[slot]);
            heads[slot] = kept.len() as u32;
            kept.push(c);
        }
    }
    kept
}

/// The cells of [`cull`]: a box over the candidates cut into cells at least the radius wide, and
/// wide enough that there are at most about four cells per candidate.
struct CullGrid {
    lo: Vec3,
    cell_m: f32,
    dims: glam::IVec3,
}

impl CullGrid {
    fn new(candidates: &[Vec3], radius_m: f32) -> CullGrid {
        let (lo, hi) = candidates
            .iter()
            .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &c| {
                (lo.min(c), hi.max(c))
            });
        let (lo, extent) = match candidates.is_empty() {
            true => (Vec3::ZERO, Vec3::ZERO),
            false => (lo, hi - lo),
        };
        let volume = extent
            .max(Vec3::splat(radius_m.max(1e-3)))
            .element_product();
        let sparse = (volume / (4.0 * candidates.len().max(1) as f32)).cbrt();
        let cell_m = radius_m.max(sparse).max(1e-3);
        let dims = (extent / cell_m).floor().as_ivec3() + 1;
        CullGrid { lo, cell_m, dims }
    }

    fn cells(&self) -> usize {
        self.dims.element_product() as usize
    }

    fn cell(&self, p: Vec3) -> glam::IVec3 {
        ((p - self.lo) / self.cell_m)
            .floor()
            .as_ivec3()
            .clamp(glam::IVec3::ZERO, self.dims - 1)
    }

    fn index(&self, c: glam::IVec3) -> usize {
        (c.x + self.dims.x * (c.y + self.dims.y * c.z)) as usize
    }

    /// The indices of the cells around `home` (itself included) inside the grid.
    fn around(&self, home: glam::IVec3) -> impl Iterator<Item = usize> + '_ {
        let lo = (home - 1).max(glam::IVec3::ZERO);
        let hi = (home + 1).min(self.dims - 1);
        (lo.z..=hi.z).flat_map(move |z| {
            (lo.y..=hi.y).flat_map(move |y| {
                (lo.x..=hi.x).map(move |x| self.index(glam::IVec3::new(x, y, z)))
            })
        })
    }
}

/// The sprite at `offset_m`, sized, turned and textured from the recipe's ranges (`height_m`: the
/// cloud's height, which the widths are fractions of).
pub fn dress(recipe: &Recipe, seed: u32, k: u32, offset_m: Vec3, height_m: f32) -> Sprite {
    let u = |lane: u32| unit_random(seed ^ 0x5bd1_e995, k, lane);
    let lerp = |(lo, hi): (f32, f32), t: f32| lo + (hi - lo) * t;
    let width = lerp(recipe.width, u(0)) * height_m;
    Sprite {
        offset_m,
        size_m: Vec2::new(width, width * lerp(recipe.aspect, u(1))),
        rotation_rad: lerp(recipe.rotation_deg, u(2)).to_radians(),
        texture: texture_in(recipe.textures, u(3)),
        group: 0,
        opacity: recipe.opacity,
    }
}

/// Lowest bottom and highest top of `boxes`, m.
pub fn vertical_extent(boxes: &[SpriteBox]) -> (f32, f32) {
    boxes.iter().fold((f32::MAX, f32::MIN), |(lo, hi), b| {
        (
            lo.min(b.center_m.y - 0.5 * b.size_m.y),
            hi.max(b.center_m.y + 0.5 * b.size_m.y),
        )
    })
}

/// Shading groups (Wang 2003, "sections of 1-30 sprites that are shaded as a unit"): the cloud
/// split at the median of its longest axis, again and again, until each part holds at most
/// `group_size` sprites, so each group is a compact section of the cloud.
pub fn assign_groups(sprites: &mut [Sprite], group_size: u32) {
    let size = group_size.clamp(1, 30) as usize;
    let mut indices: Vec<usize> = (0..sprites.len()).collect();
    let mut next = 0;
    split_groups(sprites, &mut indices, size, &mut next);
}

/// Splits `indices` (sprites of one section) until each part fits `size`, numbering the parts.
fn split_groups(sprites: &mut [Sprite], indices: &mut [usize], size: usize, next: &mut u32) {
    if indices.len() <= size {
        for &i in indices.iter() {
            sprites[i].group = *next;
        }
        *next += 1;
        return;
    }
    let (lo, hi) = indices.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &i| {
        (lo.min(sprites[i].offset_m), hi.max(sprites[i].offset_m))
    });
    let extent = hi - lo;
    let axis = if extent.x >= extent.y.max(extent.z) {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    indices.sort_by(|&a, &b| sprites[a].offset_m[axis].total_cmp(&sprites[b].offset_m[axis]));
    let (left, right) = indices.split_at_mut(indices.len() / 2);
    split_groups(sprites, left, size, next);
    split_groups(sprites, right, size, next);
}

impl SpriteCloud {
    /// Number of shading groups.
    pub fn group_count(&self) -> u32 {
        self.sprites.iter().map(|s| s.group + 1).max().unwrap_or(0)
    }

    /// Centre of each shading group relative to the cloud's centre, m (the mean of its sprites).
    pub fn group_centres_m(&self) -> Vec<Vec3> {
        let n = self.group_count() as usize;
        let mut sums = vec![(Vec3::ZERO, 0u32); n];
        for s in &self.sprites {
            let entry = &mut sums[s.group as usize];
            entry.0 += s.offset_m;
            entry.1 += 1;
        }
        sums.iter()
            .map(|(sum, count)| *sum / *count as f32)
            .collect()
    }

    /// Lowest sprite bottom and highest sprite top relative to the centre, m.
    pub fn vertical_extent_m(&self) -> (f32, f32) {
        self.sprites
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), s| {
                let half = 0.5 * s.size_m.y;
                (lo.min(s.offset_m.y - half), hi.max(s.offset_m.y + half))
            })
    }

    /// The single-billboard level of detail (Wang 2003, "Fallback on older systems": "a degenerate
    /// case of our cluster of sprites model"): one sprite as wide and tall as the cloud, at the
    /// mean of its sprites, textured like its first sprite.
    pub fn billboard(&self) -> SpriteCloud {
        let Some(first) = self.sprites.first() else {
            return self.clone();
        };
        let n = self.sprites.len() as f32;
        let centre = self.sprites.iter().map(|s| s.offset_m).sum::<Vec3>() / n;
        let (lo, hi) = self.vertical_extent_m();
        let width = self
            .sprites
            .iter()
            .map(|s| 2.0 * Vec2::new(s.offset_m.x - centre.x, s.offset_m.z - centre.z).length())
            .fold(0.0f32, f32::max)
            + first.size_m.x;
        let opacity = self.sprites.iter().map(|s| s.opacity).sum::<f32>() / n;
        SpriteCloud {
            sprites: vec![Sprite {
                offset_m: Vec3::new(centre.x, 0.5 * (lo + hi), centre.z),
                size_m: Vec2::new(width, hi - lo),
                rotation_rad: 0.0,
                group: 0,
                opacity,
                ..*first
            }],
            ..self.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model(cloud_type: CloudType, seed: u32) -> CloudModel {
        CloudModel {
            cloud_type,
            center_m: Vec3::new(100.0, 1500.0, -200.0),
            boxes: vec![
                SpriteBox {
                    center_m: Vec3::ZERO,
                    size_m: Vec3::new(1200.0, 400.0, 900.0),
                },
                SpriteBox {
                    center_m: Vec3::new(0.0, 400.0, 0.0),
                    size_m: Vec3::new(700.0, 400.0, 600.0),
                },
            ],
            seed,
            recipe: cloud_type.recipe(),
        }
    }

    #[test]
    fn cull_keeps_no_two_centres_within_the_radius_and_covers_every_culled_one() {
        for (cloud_type, seed) in [
            (CloudType::CumulusMediocris, 1),
            (CloudType::Cumulonimbus, 2),
            (CloudType::Stratus, 3),
        ] {
            let m = model(cloud_type, seed);
            let r = m.cull_radius_m();
            assert!((r - m.recipe.cull_fraction * 800.0).abs() < 1e-3, "{r}");
            let candidates: Vec<Vec3> = (0..m.recipe.sprites).map(|k| m.candidate(k)).collect();
            let kept = cull(&candidates, r);
            assert!(
                kept.len() > 3 && kept.len() < candidates.len(),
                "{}",
                kept.len()
            );
            for (i, a) in kept.iter().enumerate() {
                for b in &kept[i + 1..] {
                    assert!(a.distance(*b) >= r, "{a} {b} closer than {r}");
                }
            }
            for c in &candidates {
                assert!(kept.iter().any(|k| k.distance(*c) < r || k == c));
            }
        }
    }

    #[test]
    fn dense_clouds_keep_more_sprites_than_typical_ones_from_the_same_candidates() {
        let m = model(CloudType::CumulusMediocris, 4);
        let candidates: Vec<Vec3> = (0..200).map(|k| m.candidate(k)).collect();
        let typical = cull(&candidates, m.height_m() / 3.0).len();
        let dense = cull(&candidates, m.height_m() / 5.0).len();
        assert!(dense > typical, "{dense} <= {typical}");
    }

    #[test]
    fn generation_is_deterministic_inside_the_boxes_and_within_the_ranges() {
        let m = model(CloudType::CumulusMediocris, 9);
        let cloud = m.generate(Some(0));
        assert_eq!(cloud, m.generate(Some(0)));
        assert_ne!(
            cloud.sprites,
            model(m.cloud_type, 10).generate(Some(0)).sprites
        );
        let height = m.height_m();
        for s in &cloud.sprites {
            let inside = m.boxes.iter().any(|b| {
                let d = (s.offset_m - b.center_m).abs();
                d.cmple(b.size_m * 0.5 + 1e-3).all()
            });
            assert!(inside, "{s:?}");
            let w = s.size_m.x / height;
            assert!((m.recipe.width.0..=m.recipe.width.1).contains(&w), "{w}");
            let rot = s.rotation_rad.to_degrees();
            assert!(
                (m.recipe.rotation_deg.0 - 1e-3..=m.recipe.rotation_deg.1 + 1e-3).contains(&rot)
            );
            assert!(m.recipe.textures & (1 << s.texture) != 0);
        }
    }

    #[test]
    fn shading_groups_hold_one_to_the_recipes_size() {
        let cloud = model(CloudType::Cumulonimbus, 5).generate(None);
        let size = CloudType::Cumulonimbus.recipe().group_size;
        let mut counts = vec![0u32; cloud.group_count() as usize];
        cloud
            .sprites
            .iter()
            .for_each(|s| counts[s.group as usize] += 1);
        assert!(
            counts.iter().all(|&c| (1..=size).contains(&c)),
            "{counts:?}"
        );
        assert!(counts.len() > 1);
    }

    #[test]
    fn the_billboard_is_one_sprite_spanning_the_cloud() {
        let cloud = model(CloudType::CumulusMediocris, 6).generate(None);
        let lod = cloud.billboard();
        assert_eq!(lod.sprites.len(), 1);
        let (lo, hi) = cloud.vertical_extent_m();
        assert!((lod.sprites[0].size_m.y - (hi - lo)).abs() < 1e-3);
        assert!(lod.sprites[0].size_m.x >= cloud.sprites[0].size_m.x);
    }
}
