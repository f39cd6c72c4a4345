//! The sheet of 16 puff textures (Wang 2003, "Mix and match 16 textures": solid puffs for cumulus,
//! blurry puffs for stratus, in less video memory than a texture per cloud), in a 4 x 4 grid.
//!
//! The puffs are baked at start from the project's own volumetric model rather than painted: each
//! is the column density of a reference particle of the particle technique
//! ([`crate::particles::density`]) seen along its axis, normalised to 1 at its densest, so a
//! sprite is a picture of the same noisy cloud matter the other techniques render. The sprite
//! shader turns it into opacity `1 - exp(-tau c)` with the sprite's own optical depth `tau`. Solid puffs are the pyroclastic and thresholded
//! particles, blurry ones the smooth particle, wispy ones the smooth particle stretched wide.

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::particles::density::ReferenceParticle;
use crate::scene::ParticleStyle;

/// Tiles along each side of the sheet.
pub const SHEET_TILES: u32 = 4;
/// Texels along each side of one tile.
pub const TILE_TEXELS: u32 = 64;
/// Texels along each side of the sheet.
pub const SHEET_TEXELS: u32 = SHEET_TILES * TILE_TEXELS;

/// Tiles 0-7: solid puffs (cumulus).
pub const SOLID: u16 = 0x00ff;
/// Tiles 8-11: blurry puffs (stratus).
pub const BLURRY: u16 = 0x0f00;
/// Tiles 12-15: wispy, stretched puffs (altostratus).
pub const WISPY: u16 = 0xf000;

/// Integration steps through a particle per texel.
const STEPS: u32 = 32;
/// The tile spans particle-space `[-TILE_SPAN, TILE_SPAN]`: the unit ball with a margin, so every
/// tile is transparent at its border and bilinear filtering never bleeds into a neighbour.
const TILE_SPAN: f32 = 1.08;

/// How one tile is baked: the particle and how much it is stretched across (x).
#[derive(Clone, Copy, Debug)]
struct Puff {
    style: ParticleStyle,
    seed: u32,
    stretch: f32,
}

/// The recipe of tile `index` (0..16).
fn puff(index: u32) -> Puff {
    let (style, stretch) = match index {
        0..4 => (ParticleStyle::Pyroclastic, 1.0),
        4..8 => (ParticleStyle::Thresholded, 1.0),
        8..12 => (ParticleStyle::Smooth, 1.0),
        _ => (ParticleStyle::Smooth, 1.8),
    };
    Puff {
        style,
        seed: 101 + index * 7919,
        stretch,
    }
}

/// The tile of `mask` (a set of tiles) that `u` in [0, 1) picks, each set tile equally likely.
pub fn texture_in(mask: u16, u: f32) -> u32 {
    let set: Vec<u32> = (0..16).filter(|i| mask & (1 << i) != 0).collect();
    let pick = ((u * set.len() as f32) as usize).min(set.len() - 1);
    set[pick]
}

/// The whole sheet, row-major, one byte of normalised column density per texel.
pub fn bake_sheet() -> Vec<u8> {
    let tiles: Vec<Vec<u8>> = (0..SHEET_TILES * SHEET_TILES)
        .into_par_iter()
        .map(|i| bake_tile(puff(i)))
        .collect();
    let mut sheet = vec![0u8; (SHEET_TEXELS * SHEET_TEXELS) as usize];
    for (i, tile) in tiles.iter().enumerate() {
        let (tx, ty) = (i as u32 % SHEET_TILES, i as u32 / SHEET_TILES);
        for y in 0..TILE_TEXELS {
            let row = ((ty * TILE_TEXELS + y) * SHEET_TEXELS + tx * TILE_TEXELS) as usize;
            let src = (y * TILE_TEXELS) as usize;
            sheet[row..row + TILE_TEXELS as usize]
                .copy_from_slice(&tile[src..src + TILE_TEXELS as usize]);
        }
    }
    sheet
}

/// One tile: the particle's column density, normalised to 1 at its densest.
fn bake_tile(p: Puff) -> Vec<u8> {
    let particle = ReferenceParticle {
        style: p.style,
        seed: p.seed,
    };
    let n = TILE_TEXELS;
    let columns: Vec<f32> = (0..n * n)
        .map(|i| {
            let t = (Vec2::new((i % n) as f32, (i / n) as f32) + 0.5) / n as f32;
            let xy = (t * 2.0 - 1.0) * TILE_SPAN * Vec2::new(p.stretch, 1.0);
            column_density(&particle, xy)
        })
        .collect();
    let peak = columns.iter().cloned().fold(1e-6f32, f32::max);
    columns
        .iter()
        .map(|c| (c / peak * 255.0).round() as u8)
        .collect()
}

/// The particle's density integrated along z through `xy` (particle space), midpoint rule.
fn column_density(particle: &ReferenceParticle, xy: Vec2) -> f32 {
    let half = (1.0 - xy.length_squared()).max(0.0).sqrt();
    if half <= 0.0 {
        return 0.0;
    }
    let dz = 2.0 * half / STEPS as f32;
    (0..STEPS)
        .map(|k| {
            let z = -half + (k as f32 + 0.5) * dz;
            particle.density(Vec3::new(xy.x, xy.y, z)) * dz
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tile_of(sheet: &[u8], index: u32) -> Vec<f32> {
        let (tx, ty) = (index % SHEET_TILES, index / SHEET_TILES);
        (0..TILE_TEXELS * TILE_TEXELS)
            .map(|i| {
                let (x, y) = (
                    tx * TILE_TEXELS + i % TILE_TEXELS,
                    ty * TILE_TEXELS + i / TILE_TEXELS,
                );
                sheet[(y * SHEET_TEXELS + x) as usize] as f32 / 255.0
            })
            .collect()
    }

    #[test]
    fn sixteen_distinct_puffs_transparent_at_their_borders_solid_ones_denser_than_blurry() {
        let sheet = bake_sheet();
        let tiles: Vec<Vec<f32>> = (0..16).map(|i| tile_of(&sheet, i)).collect();
        let n = TILE_TEXELS as usize;
        for (i, t) in tiles.iter().enumerate() {
            let border =
                (0..n).flat_map(|k| [t[k], t[(n - 1) * n + k], t[k * n], t[k * n + n - 1]]);
            assert!(border.fold(0.0f32, f32::max) == 0.0, "tile {i} bleeds");
            assert!(
                t[n / 2 * n + n / 2] > 0.5,
                "tile {i} is empty at its centre"
            );
            for (j, u) in tiles.iter().enumerate().skip(i + 1) {
                assert_ne!(t, u, "tiles {i} and {j}");
            }
        }
        let mean = |t: &Vec<f32>| t.iter().sum::<f32>() / t.len() as f32;
        let solid = (0..8).map(|i| mean(&tiles[i])).sum::<f32>() / 8.0;
        let blurry = (8..12).map(|i| mean(&tiles[i])).sum::<f32>() / 4.0;
        // Solid puffs hold their opacity to a crisper edge.
        let hard = |t: &Vec<f32>| t.iter().filter(|&&a| a > 0.7).count();
        assert!(solid > blurry * 0.5, "{solid} {blurry}");
        assert!(hard(&tiles[0]) > hard(&tiles[8]));
    }

    #[test]
    fn texture_picks_stay_in_their_set() {
        for u in [0.0, 0.3, 0.999] {
            assert!(BLURRY & (1 << texture_in(BLURRY, u)) != 0);
        }
        assert_eq!(texture_in(SOLID, 0.0), 0);
        assert_eq!(texture_in(SOLID, 0.999), 7);
    }
}
