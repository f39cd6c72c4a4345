//! Direction sampling on the sphere (Pharr, Jakob & Humphreys, "Physically Based Rendering", 4th
//! ed., sections A.5.2-A.5.4): each sampler maps two uniform numbers to a unit vector; its density
//! per steradian is given beside it.

use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// The unit vector at polar cosine `cos_theta` from `axis` and azimuth `2 pi u` about it.
fn around(axis: Vec3, cos_theta: f32, u: f32) -> Vec3 {
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (tangent, bitangent) = axis.any_orthonormal_pair();
    let (sin_phi, cos_phi) = (TAU * u).sin_cos();
    (tangent * cos_phi + bitangent * sin_phi) * sin_theta + axis * cos_theta
}

/// Uniform over the cone of half-angle `acos(cos_max)` about `axis`: density
/// `1 / (2 pi (1 - cos_max))`. Writing `cos_theta` as `1 - u (1 - cos_max)` keeps the tiny cone
/// of the sun (1 - cos_max = 1.1e-5) exact in `f32`.
pub fn uniform_cone(axis: Vec3, cos_max: f32, u: Vec2) -> Vec3 {
    around(axis, 1.0 - u.x * (1.0 - cos_max), u.y)
}

/// Uniform over the hemisphere about `axis`: density `1 / (2 pi)`.
pub fn uniform_hemisphere(axis: Vec3, u: Vec2) -> Vec3 {
    around(axis, u.x, u.y)
}

/// Uniform over the sphere: density `1 / (4 pi)`.
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    around(Vec3::Y, 1.0 - 2.0 * u.x, u.y)
}

/// Cosine-weighted over the hemisphere about `normal` (Malley's method): density `cos / pi`.
pub fn cosine_hemisphere(normal: Vec3, u: Vec2) -> Vec3 {
    around(normal, u.x.sqrt(), u.y)
}

/// Density of [`uniform_hemisphere`], per steradian.
pub const UNIFORM_HEMISPHERE_PDF: f32 = 1.0 / (2.0 * PI);
/// Density of [`uniform_sphere`], per steradian.
pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// Monte Carlo mean of `f` over `n` directions from `sample`.
    fn mean(n: u64, sample: impl Fn(Vec2) -> Vec3, f: impl Fn(Vec3) -> f32) -> f32 {
        let mut rng = Rng::for_sample(9, 0, 0);
        (0..n).map(|_| f(sample(rng.next_vec2()))).sum::<f32>() / n as f32
    }

    #[test]
    fn samplers_have_their_moments() {
        let axis = Vec3::new(0.3, -0.5, 0.8).normalize();
        let n = 50_000;
        // E[cos] is 1/2 on the hemisphere, 2/3 cosine-weighted, 0 on the sphere.
        let cos = |d: Vec3| d.dot(axis);
        assert!((mean(n, |u| uniform_hemisphere(axis, u), cos) - 0.5).abs() < 0.01);
        assert!((mean(n, |u| cosine_hemisphere(axis, u), cos) - 2.0 / 3.0).abs() < 0.01);
        assert!(mean(n, uniform_sphere, cos).abs() < 0.01);
        let cone = |u| uniform_cone(axis, 0.99, u);
        assert!((mean(n, cone, cos) - 0.995).abs() < 1e-4);
        let all_unit = |d: Vec3| ((d.length() - 1.0).abs() < 1e-5) as u32 as f32;
        assert_eq!(mean(1000, uniform_sphere, all_unit), 1.0);
    }
}
