//! Pictures of the reference particle as its tables shade it: orthographic views of its disc,
//! for `cloudscape bake --preview` and for checking the tables against a full transport solution
//! pixel by pixel.

use glam::Vec3;

use super::optical_depth::OpticalDepthTable;
use super::scattering::ScatteringTables;
use crate::optics::PhaseLobes;

/// An orthographic view of the unit particle: the direction the eye looks along and the image
/// axes, `n x n` pixels over the square `[-1, 1]^2` of the particle's disc, top row first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscView {
    /// Unit direction the eye looks along.
    pub dir: Vec3,
    /// Pixels per side.
    pub pixels: u32,
}

impl DiscView {
    /// The image axes (right, up): the ones `cloudscape_reference::light_tracer` images with.
    pub fn axes(&self) -> (Vec3, Vec3) {
        let right = self.dir.any_orthonormal_vector();
        (right, self.dir.cross(right))
    }

    /// The mean over `subsamples^2` points of each pixel of `f(entry, dir)`, where `entry` is the
    /// point of the unit sphere the eye's ray through the point enters at (0 where it misses).
    pub fn average(&self, subsamples: u32, f: impl Fn(Vec3) -> f32) -> Vec<f32> {
        let (right, up) = self.axes();
        let n = self.pixels * subsamples;
        let mut image = vec![0.0; (self.pixels * self.pixels) as usize];
        let weight = 1.0 / (subsamples * subsamples) as f32;
        for j in 0..n {
            for i in 0..n {
                let a = (i as f32 + 0.5) / n as f32 * 2.0 - 1.0;
                let b = 1.0 - (j as f32 + 0.5) / n as f32 * 2.0;
                let r2 = a * a + b * b;
                if r2 >= 1.0 {
                    continue;
                }
                let entry = right * a + up * b - self.dir * (1.0 - r2).sqrt();
                let pixel = (j / subsamples) * self.pixels + i / subsamples;
                image[pixel as usize] += f(entry) * weight;
            }
        }
        image
    }

    /// Radiance leaving the symmetric particle toward the eye per unit irradiance of a sun whose
    /// light travels along `light_dir`: single scattering and everything (`E (p S + M)`).
    pub fn scattering(
        &self,
        tables: &ScatteringTables,
        phase: &PhaseLobes,
        light_dir: Vec3,
        subsamples: u32,
    ) -> (Vec<f32>, Vec<f32>) {
        let out = -self.dir;
        let p = phase.eval(light_dir.dot(out));
        let single = self.average(subsamples, |e| p * tables.lookup(e, out, -light_dir).0);
        let multiple = self.average(subsamples, |e| tables.lookup(e, out, -light_dir).1);
        let total = single.iter().zip(&multiple).map(|(s, m)| s + m).collect();
        (single, total)
    }

    /// Optical mass (particle radii) through the noisy particle along the eye's rays, rotated by
    /// `rotation` as a particle of the technique is.
    pub fn optical_mass(&self, table: &OpticalDepthTable, rotation: glam::Quat) -> Vec<f32> {
        self.average(2, |e| table.lookup(rotation * e, rotation * self.dir))
    }
}
