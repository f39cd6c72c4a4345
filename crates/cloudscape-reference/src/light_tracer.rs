//! Light tracing: photons from the sun followed through a medium by the same delta and ratio
//! tracking as the path tracer, each collision sending its share of light to orthographic
//! cameras (next-event estimation toward the eye).
//!
//! It is the path tracer's dual and unbiased like it; it is used where camera paths struggle:
//! under a sun, the forward peak of cloud droplets (0.3 degrees wide, half their scattering)
//! keeps a collimated beam inside a cloud, which camera paths meet only when one happens to point
//! at the sun, and then as a firefly. Photons start in that beam.

use crate::integrator::PathTracer;
use crate::medium::Medium;
use crate::rng::Rng;
use cloudscape::particles::density::uniform_disc_point;
use cloudscape::particles::preview::DiscView;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// An orthographic camera: the view of the particle's disc `disc` (its direction, pixels and
/// image axes), scaled to a square of side `2 half_extent_m` centred on `centre_m`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrthographicView {
    /// Direction, pixels and axes.
    pub disc: DiscView,
    /// Centre of the image square, m.
    pub centre_m: Vec3,
    /// Half the side of the image square, m.
    pub half_extent_m: f32,
}

impl OrthographicView {
    /// The pixel `p` projects into, if any.
    fn pixel(&self, p: Vec3) -> Option<usize> {
        let (right, up) = self.disc.axes();
        let local = Vec2::new((p - self.centre_m).dot(right), (p - self.centre_m).dot(up));
        let uv = Vec2::new(local.x + self.half_extent_m, self.half_extent_m - local.y)
            / (2.0 * self.half_extent_m)
            * self.disc.pixels as f32;
        let inside =
            uv.cmpge(Vec2::ZERO).all() && uv.cmplt(Vec2::splat(self.disc.pixels as f32)).all();
        inside.then(|| uv.y as usize * self.disc.pixels as usize + uv.x as usize)
    }

    /// Area of one pixel, m^2.
    fn pixel_area_m2(&self) -> f32 {
        (2.0 * self.half_extent_m / self.disc.pixels as f32).powi(2)
    }
}

/// Radiance per pixel of one view (row-major, `pixels^2`): light scattered once, and all light.
#[derive(Clone, Debug, PartialEq)]
pub struct LightTracedImage {
    /// Single scattering.
    pub single: Vec<f64>,
    /// Every order.
    pub total: Vec<f64>,
}

/// Traces `photons` photons from `tracer`'s sun into the ball of radius `radius_m` about
/// `centre_m` (which must hold all of the medium), and images the light leaving it in `views`.
/// The sky, the ground and the haze are ignored: these are images of sunlight alone.
///
/// # Panics
/// When `tracer` has no sun.
pub fn light_trace<M: Medium>(
    tracer: &PathTracer<M>,
    centre_m: Vec3,
    radius_m: f32,
    views: &[OrthographicView],
    photons: u64,
    seed: u64,
) -> Vec<LightTracedImage> {
    let sun = tracer.environment.sun.expect("light tracing needs a sun");
    let light = -sun.direction;
    let right = light.any_orthonormal_vector();
    let up = light.cross(right);
    // Power of each photon: the irradiance over the disc it is drawn on.
    let power = f64::from(sun.irradiance.y) * std::f64::consts::PI * f64::from(radius_m).powi(2)
        / photons as f64;
    let empty = || {
        views
            .iter()
            .map(|v| {
                let n = (v.disc.pixels * v.disc.pixels) as usize;
                LightTracedImage {
                    single: vec![0.0; n],
                    total: vec![0.0; n],
                }
            })
            .collect::<Vec<_>>()
    };
    const CHUNK: u64 = 4096;
    let mut images = (0..photons.div_ceil(CHUNK))
        .into_par_iter()
        .fold(empty, |mut images, chunk| {
            for k in chunk * CHUNK..((chunk + 1) * CHUNK).min(photons) {
                let mut rng = Rng::for_sample(seed, 0, k);
                let d = uniform_disc_point(rng.next_vec2()) * radius_m;
                let start = centre_m - light * (2.0 * radius_m) + right * d.x + up * d.y;
                trace_photon(tracer, start, light, views, &mut images, &mut rng);
            }
            images
        })
        .reduce(empty, |mut a, b| {
            for (x, y) in a.iter_mut().zip(b) {
                x.single.iter_mut().zip(y.single).for_each(|(p, q)| *p += q);
                x.total.iter_mut().zip(y.total).for_each(|(p, q)| *p += q);
            }
            a
        });
    for (image, view) in images.iter_mut().zip(views) {
        let scale = power / f64::from(view.pixel_area_m2());
        image.single.iter_mut().for_each(|v| *v *= scale);
        image.total.iter_mut().for_each(|v| *v *= scale);
    }
    images
}

/// One photon's walk; every collision splats `phase * albedo * transmittance` toward each view.
fn trace_photon<M: Medium>(
    tracer: &PathTracer<M>,
    mut position: Vec3,
    mut dir: Vec3,
    views: &[OrthographicView],
    images: &mut [LightTracedImage],
    rng: &mut Rng,
) {
    let mut weight = Vec3::ONE;
    for order in 1..=crate::integrator::MAX_SCATTERING_EVENTS {
        let Some(t) = tracer.volume.free_flight(position, dir, f32::INFINITY, rng) else {
            return;
        };
        position += dir * t;
        weight *= tracer.albedo;
        for (view, image) in views.iter().zip(images.iter_mut()) {
            let Some(pixel) = view.pixel(position) else {
                continue;
            };
            let out = -view.disc.dir;
            let phase = tracer.phase.eval(dir.dot(out));
            let transmittance = tracer
                .volume
                .transmittance(position, out, f32::INFINITY, rng);
            let value = f64::from(weight.y * phase * transmittance);
            image.total[pixel] += value;
            if order == 1 {
                image.single[pixel] += value;
            }
        }
        dir = tracer.phase.sample(dir, rng.next_vec3());
        if !crate::integrator::roulette(&mut weight, rng) {
            return;
        }
    }
}
