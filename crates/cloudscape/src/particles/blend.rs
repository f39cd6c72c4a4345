//! Volume-aware blending (Yusov 2014, "Volume-aware blending"), per pixel: the CPU specification
//! of `particle_render.wgsl`'s blending.
//!
//! Each pixel keeps one record, the segment of the nearest particles not yet blended: near and far
//! distance, optical depth and colour ([`Segment`], the seed's 24-byte record). A particle segment
//! that overlaps the record merges into it as one volume of uniform density per particle, by the
//! seed's front / intersection / back formulas ([`merge`]); one that begins behind it pushes the
//! record into the blended result and takes its place. Particles arrive nearest first (the seed
//! draws back to front and blends the record into a back buffer; front to back is the same
//! algebra and lets a pixel stop once it is opaque). [`Blending::Alpha`] blends every segment as
//! it comes, as conventional alpha blending does.

use glam::Vec3;

/// The stretch of a view ray through one particle, or through merged particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Where it begins, m along the ray.
    pub near_m: f32,
    /// Where it ends, m.
    pub far_m: f32,
    /// Optical depth along it.
    pub optical_depth: f32,
    /// Radiance it scatters toward the eye per unit opacity: its premultiplied radiance is
    /// `colour (1 - exp(-optical_depth))`.
    pub colour: Vec3,
}

impl Segment {
    /// Transmittance through it.
    pub fn transmittance(&self) -> f32 {
        (-self.optical_depth).exp()
    }

    /// Extinction per metre, uniform along it.
    fn density(&self) -> f32 {
        self.optical_depth / (self.far_m - self.near_m).max(1e-6)
    }
}

/// Merges two overlapping segments (in either order) into one, as the seed does: the part of the
/// nearer alone (front), both together (intersection, densities added and colours weighted by
/// density), and the part of the one reaching farther alone (back):
/// `T = T_front T_isec T_back`, `C = (C_front + C_isec T_front + C_back T_front T_isec) / (1 - T)`
/// with each `C_x` premultiplied.
pub fn merge(a: Segment, b: Segment) -> Segment {
    let (first, second) = if a.near_m <= b.near_m { (a, b) } else { (b, a) };
    let (rho_first, rho_second) = (first.density(), second.density());
    let front_m = second.near_m.min(first.far_m) - first.near_m;
    let isec_m = (first.far_m.min(second.far_m) - second.near_m).max(0.0);
    let (back, back_m) = if first.far_m > second.far_m {
        (first, first.far_m - second.far_m)
    } else {
        (second, second.far_m - first.far_m.max(second.near_m))
    };
    let t_front = (-rho_first * front_m).exp();
    let rho_isec = rho_first + rho_second;
    let t_isec = (-rho_isec * isec_m).exp();
    let t_back = (-back.density() * back_m).exp();
    let isec_colour = if rho_isec > 0.0 {
        (first.colour * rho_first + second.colour * rho_second) / rho_isec
    } else {
        first.colour
    };
    let premultiplied = first.colour * (1.0 - t_front)
        + isec_colour * (1.0 - t_isec) * t_front
        + back.colour * (1.0 - t_back) * t_front * t_isec;
    let t = t_front * t_isec * t_back;
    Segment {
        near_m: first.near_m,
        far_m: first.far_m.max(second.far_m),
        optical_depth: a.optical_depth + b.optical_depth,
        colour: if t < 1.0 {
            premultiplied / (1.0 - t)
        } else {
            isec_colour
        },
    }
}

/// How a pixel blends the particle segments along its ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blending {
    /// Overlapping segments merge as one volume ([`merge`]).
    VolumeAware,
    /// Each segment is blended over what lies behind it, in arrival order.
    Alpha,
}

impl Blending {
    /// The scene's choice.
    pub fn from_scene(blending: crate::scene::ParticleBlending) -> Blending {
        match blending {
            crate::scene::ParticleBlending::VolumeAware => Blending::VolumeAware,
            crate::scene::ParticleBlending::Alpha => Blending::Alpha,
        }
    }

    /// Its index in `particle_render.wgsl`.
    pub fn gpu_index(self) -> u32 {
        self as u32
    }
}

/// Transmittance below which a pixel stops taking particles: the seed's 0.01.
pub const OPAQUE_TRANSMITTANCE: f32 = 0.01;

/// One pixel's blend, front to back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelBlend {
    mode: Blending,
    record: Option<Segment>,
    /// Premultiplied radiance blended so far (in front of the record).
    pub radiance: Vec3,
    /// Transmittance blended so far.
    pub transmittance: f32,
    distance_weighted_m: f32,
}

impl PixelBlend {
    /// An empty pixel.
    pub fn new(mode: Blending) -> PixelBlend {
        PixelBlend {
            mode,
            record: None,
            radiance: Vec3::ZERO,
            transmittance: 1.0,
            distance_weighted_m: 0.0,
        }
    }

    /// Whether the pixel is opaque: later segments cannot change it noticeably.
    pub fn is_opaque(&self) -> bool {
        self.transmittance * self.record.map_or(1.0, |r| r.transmittance()) < OPAQUE_TRANSMITTANCE
    }

    /// Takes the next segment.
    pub fn add(&mut self, segment: Segment) {
        self.record = Some(match (self.mode, self.record) {
            (_, None) => segment,
            (Blending::VolumeAware, Some(r)) if segment.near_m < r.far_m => merge(r, segment),
            (_, Some(r)) => {
                self.blend(r);
                segment
            }
        });
    }

    fn blend(&mut self, s: Segment) {
        let opacity = 1.0 - s.transmittance();
        self.radiance += self.transmittance * opacity * s.colour;
        self.distance_weighted_m += self.transmittance * opacity * 0.5 * (s.near_m + s.far_m);
        self.transmittance *= 1.0 - opacity;
    }

    /// Premultiplied radiance, transmittance and the transmittance-weighted cloud distance (0
    /// without cloud): the cloud-output contract.
    pub fn finish(mut self) -> (Vec3, f32, f32) {
        if let Some(r) = self.record.take() {
            self.blend(r);
        }
        let coverage = 1.0 - self.transmittance;
        let distance = if coverage > 0.0 {
            self.distance_weighted_m / coverage
        } else {
            0.0
        };
        (self.radiance, self.transmittance, distance)
    }
}

/// Particle blending on the GPU (`particle_blend.wgsl`), the twin of this module.
pub static PARTICLE_BLEND_WGSL: crate::shader::WgslModule =
    crate::shader::wgsl_module!("particle_blend", "particle_blend.wgsl", []);

#[cfg(test)]
mod tests {
    use super::*;

    fn segment(near_m: f32, far_m: f32, optical_depth: f32, colour: f32) -> Segment {
        Segment {
            near_m,
            far_m,
            optical_depth,
            colour: Vec3::splat(colour),
        }
    }

    #[test]
    fn disjoint_segments_blend_as_alpha_does() {
        let (a, b) = (segment(0.0, 1.0, 1.0, 2.0), segment(2.0, 3.0, 0.5, 1.0));
        let mut volume = PixelBlend::new(Blending::VolumeAware);
        let mut alpha = PixelBlend::new(Blending::Alpha);
        for s in [a, b] {
            volume.add(s);
            alpha.add(s);
        }
        let (lv, tv, dv) = volume.finish();
        let (la, ta, da) = alpha.finish();
        assert!((lv - la).abs().max_element() < 1e-6 && (tv - ta).abs() < 1e-6);
        assert!((dv - da).abs() < 1e-5);
        let expect = 2.0 * (1.0 - (-1.0f32).exp()) + (-1.0f32).exp() * (1.0 - (-0.5f32).exp());
        assert!((lv.x - expect).abs() < 1e-5, "{} vs {expect}", lv.x);
    }

    /// A segment merged with a copy of itself is one segment of twice the density: the same
    /// colour, the transmittance squared. Alpha blending also squares the transmittance, but
    /// darkens the colour by the front copy hiding the back one.
    #[test]
    fn merging_a_segment_with_itself_doubles_its_density() {
        let a = segment(10.0, 20.0, 0.7, 3.0);
        let m = merge(a, a);
        assert!((m.optical_depth - 1.4).abs() < 1e-6);
        assert!((m.colour.x - 3.0).abs() < 1e-5, "{}", m.colour.x);
        assert_eq!((m.near_m, m.far_m), (10.0, 20.0));
    }

    /// Splitting one uniform segment into two overlapping halves and merging them back gives it.
    #[test]
    fn overlapping_parts_merge_back_into_the_whole() {
        let whole = segment(0.0, 10.0, 2.0, 1.5);
        let merged = merge(segment(0.0, 6.0, 1.2, 1.5), segment(6.0, 10.0, 0.8, 1.5));
        assert!((merged.optical_depth - whole.optical_depth).abs() < 1e-6);
        assert!((merged.colour - whole.colour).abs().max_element() < 1e-5);
        // Order does not matter.
        let (x, y) = (segment(0.0, 8.0, 1.0, 1.0), segment(3.0, 12.0, 2.0, 4.0));
        let (xy, yx) = (merge(x, y), merge(y, x));
        assert!((xy.colour - yx.colour).abs().max_element() < 1e-6);
    }

    /// The seed's point: a bright particle inside a dark one. Alpha blending in centre order
    /// lets whichever centre is nearer cover the other; volume-aware blending mixes them by
    /// density whatever the order, so sorting flips cannot pop.
    #[test]
    fn volume_aware_blending_does_not_depend_on_the_order_of_overlapping_particles() {
        let (big, small) = (segment(0.0, 10.0, 3.0, 0.2), segment(4.0, 6.0, 3.0, 5.0));
        let result = |mode, order: [Segment; 2]| {
            let mut p = PixelBlend::new(mode);
            order.into_iter().for_each(|s| p.add(s));
            p.finish()
        };
        let (v1, _, _) = result(Blending::VolumeAware, [big, small]);
        let (v2, _, _) = result(Blending::VolumeAware, [small, big]);
        assert!((v1 - v2).abs().max_element() < 1e-4, "{v1} vs {v2}");
        let (a1, _, _) = result(Blending::Alpha, [big, small]);
        let (a2, _, _) = result(Blending::Alpha, [small, big]);
        assert!((a1 - a2).abs().max_element() > 0.5, "{a1} vs {a2}");
    }
}
