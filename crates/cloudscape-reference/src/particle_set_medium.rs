//! The particle technique's own particles as a medium: a cloud made of a set of
//! [`Particle`]s, each an ellipsoid of the reference particle, whose extinction is the sum of the
//! particles' (Yusov 2014, "High-Performance Rendering of Realistic Cumulus Clouds Using
//! Pre-computed Lighting": the cloud is a set of particles, each a scaled and rotated instance of
//! one reference particle). Path traced, it is the ground truth of what the particle technique
//! approximates with its precomputed tables and its blending of particles one by one.
//!
//! Particle `k` maps a world point `p` into the unit ball as `particle_segment` in
//! `particle_render.wgsl` does: `local = (p - centre) / (radius, height, radius)`, and reads the
//! reference particle turned by its random orientation `q = particle_rotation(id)`, as the GPU's
//! `particle_rotate(q, local)` (glam's `q * local`). Its extinction there is
//! `sigma_max * density * volume.density(q * local)`, where `volume` is the reference particle's
//! noise baked into a [`NoiseVolume`] of [`NOISE_VOLUME_SIZE`]^3 voxels: the very noise the GPU
//! integrates its particle tables through (`particle_bake.wgsl`), with the falloff and the edges
//! evaluated exactly. It is within the volume's trilinear error of `reference.density` (about
//! 0.01 in the mean) and costs one trilinear read per particle instead of four Perlin octaves.
//!
//! Point queries and box bounds walk a bounding volume hierarchy over the particles' boxes
//! (median splits along the widest axis of the centres), so that hundreds of thousands of
//! particles cost a few dozen box tests per query.

use crate::geometry::Aabb;
use crate::medium::Nesting;
use crate::medium::{Medium, Support};
use cloudscape::particles::density::{NoiseVolume, ReferenceParticle, metaball_falloff};
use cloudscape::particles::generate::Particle;
use cloudscape::particles::gpu::NOISE_VOLUME_SIZE;
use cloudscape::particles::optical_depth::particle_rotation;
use cloudscape::scene::ParticleStyle;
use glam::{IVec3, Quat, Vec3};

/// The reference particle's largest density: every style ends in a clamp to [0, 1] or a
/// smoothstep (`ReferenceParticle::density_with_noise`), so its density is at most 1.
pub const MAX_REFERENCE_DENSITY: f32 = 1.0;
/// Relative margin on every bound: the sum of the particles' extinctions rounds in `f32`, in
/// another order than the bound's sum.
const BOUND_RELATIVE_MARGIN: f32 = 1e-3;
/// Margin on the nearest particle-space radius of a box, before the smooth style's falloff is
/// bounded there: the rotation rounds a point's radius by an `f32` step or two.
const RADIUS_MARGIN: f32 = 1e-5;
/// Absolute margin on the smooth style's falloff bound: near the surface the falloff's
/// polynomial cancels to a few `f32` steps of its unit-sized terms.
const FALLOFF_MARGIN: f32 = 1e-6;
/// Particles in a leaf of the hierarchy, at most.
const LEAF_PARTICLES: usize = 4;
/// Depth of the traversal stack: a median-split hierarchy over `n` particles is about
/// `log2(n / LEAF_PARTICLES)` deep, far less than this for any `u32` count.
const STACK_DEPTH: usize = 64;

/// One particle, as the queries read it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Placed {
    /// Centre, m.
    centre_m: Vec3,
    /// Radii (horizontal, vertical, horizontal), m.
    radii_m: Vec3,
    /// Their reciprocals.
    inv_radii: Vec3,
    /// Its random orientation, `particle_rotation(id)`.
    rotation: Quat,
    /// Peak extinction `sigma_max * density`, m^-1.
    extinction_per_m: f32,
}

impl Placed {
    fn new(p: &Particle, sigma_max_per_m: f32) -> Placed {
        let radii_m = Vec3::new(p.radius_m, p.height_m, p.radius_m);
        Placed {
            centre_m: p.centre_m,
            radii_m,
            inv_radii: radii_m.recip(),
            rotation: particle_rotation(p.id),
            extinction_per_m: sigma_max_per_m * p.density,
        }
    }

    fn aabb(&self) -> Aabb {
        Aabb {
            min: self.centre_m - self.radii_m,
            max: self.centre_m + self.radii_m,
        }
    }

    /// Particle-space radius of the point of `b` nearest the centre (exact: the axis-aligned
    /// scaling to the unit ball maps the box to a box).
    fn nearest_radius(&self, b: &Aabb) -> f32 {
        ((self.centre_m.clamp(b.min, b.max) - self.centre_m) * self.inv_radii).length()
    }
}

/// A node of the hierarchy: its box, and either its particles `first..first + count` (a leaf) or,
/// with `count == 0`, its children at `first` and `first + 1`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Node {
    bounds: Aabb,
    first: u32,
    count: u32,
}

/// A set of particles as a [`Medium`]: the sum of their extinctions (Yusov 2014's cloud of
/// reference-particle instances), with a bounding volume hierarchy for point queries and box
/// bounds.
#[derive(Clone, Debug)]
pub struct ParticleSetMedium {
    reference: ReferenceParticle,
    /// The reference particle's noise, baked.
    noise: NoiseVolume,
    nesting: Option<Nesting>,
    /// In leaf order.
    particles: Vec<Placed>,
    nodes: Vec<Node>,
    support: Support,
}

impl ParticleSetMedium {
    /// The medium of `particles`, each an ellipsoid of `reference` of peak extinction
    /// `sigma_max_per_m * density` (the extinction of density 1, the particle tables' and the
    /// generation's `sigma_max_per_m`). Particles with no volume, no positive density or a
    /// non-finite placement are left out: they hold no medium.
    pub fn new(
        particles: &[Particle],
        reference: ReferenceParticle,
        sigma_max_per_m: f32,
    ) -> ParticleSetMedium {
        let mut placed: Vec<Placed> = particles
            .iter()
            .filter(|p| p.radius_m > 0.0 && p.height_m > 0.0 && p.density > 0.0)
            .map(|p| Placed::new(p, sigma_max_per_m))
            .filter(|p| {
                let finite = p.centre_m.is_finite() && p.inv_radii.is_finite();
                finite && p.extinction_per_m > 0.0 && p.extinction_per_m.is_finite()
            })
            .collect();
        let mut nodes = Vec::with_capacity(2 * placed.len().div_ceil(LEAF_PARTICLES));
        if !placed.is_empty() {
            nodes.push(Node {
                bounds: placed[0].aabb(),
                first: 0,
                count: 0,
            });
            let len = placed.len();
            build(&mut placed, &mut nodes, 0, 0..len);
        }
        let grid_box = nodes.first().map_or(
            Aabb {
                min: Vec3::splat(-0.5),
                max: Vec3::splat(0.5),
            },
            |root| root.bounds,
        );
        ParticleSetMedium {
            reference,
            noise: NoiseVolume::bake(&reference, NOISE_VOLUME_SIZE),
            nesting: None,
            particles: placed,
            nodes,
            support: Support {
                grid_box,
                shell: None,
            },
        }
    }

    /// The medium with its majorant grid nested about `focus_m` (the camera), the innermost level
    /// reaching `inner_reach_m` horizontally (see [`crate::majorant::MajorantGrid`]): the particle
    /// technique's particles grow with the distance from the camera, and so should the cells
    /// that bound them.
    pub fn nested_about(self, focus_m: Vec3, inner_reach_m: f32) -> ParticleSetMedium {
        ParticleSetMedium {
            nesting: Some(Nesting {
                focus_m,
                inner_reach_m,
            }),
            ..self
        }
    }

    /// The baked noise the extinction reads (see the module's documentation).
    pub fn noise(&self) -> &NoiseVolume {
        &self.noise
    }

    /// [`NoiseVolume::sample`] at `p` (particle space, inside the unit ball), the same sum in the
    /// same order without its generic fetches and `floor` calls.
    fn noise_at(&self, p: Vec3) -> f32 {
        let n = self.noise.size as i32;
        let x = (p + 1.0) * 0.5 * n as f32 - 0.5;
        // Truncation is the floor here: x > -1 inside the unit cube.
        let t = x.as_ivec3();
        let base = t - IVec3::from(x.cmplt(t.as_vec3()));
        let f = x - base.as_vec3();
        let clamp = |i: i32| i.clamp(0, n - 1) as usize;
        let (xs, ys, zs) = (
            [clamp(base.x), clamp(base.x + 1)],
            [clamp(base.y), clamp(base.y + 1)],
            [clamp(base.z), clamp(base.z + 1)],
        );
        let (wxs, wys, wzs) = ([1.0 - f.x, f.x], [1.0 - f.y, f.y], [1.0 - f.z, f.z]);
        let n = n as usize;
        let mut out = 0.0;
        for (z, wz) in zs.into_iter().zip(wzs) {
            for (y, wy) in ys.into_iter().zip(wys) {
                let row = n * (y + n * z);
                for (x, wx) in xs.into_iter().zip(wxs) {
                    out += self.noise.values[row + x] * (wx * wy * wz);
                }
            }
        }
        out
    }

    /// Particles in the medium (those with volume and positive density).
    pub fn len(&self) -> usize {
        self.particles.len()
    }

    /// Whether no particle holds medium (the extinction is 0 everywhere).
    pub fn is_empty(&self) -> bool {
        self.particles.is_empty()
    }

    /// The reference particle every particle is an instance of.
    pub fn reference(&self) -> ReferenceParticle {
        self.reference
    }

    /// Upper bound of the reference particle's density at particle-space radii of at least `r`:
    /// the smooth style's density is its metaball falloff (decreasing in `r`) times a factor in
    /// [0, 1]; the noisy styles are bounded by [`MAX_REFERENCE_DENSITY`] alone.
    fn density_bound(&self, r: f32) -> f32 {
        match self.reference.style {
            ParticleStyle::Smooth => (metaball_falloff((r - RADIUS_MARGIN).max(0.0))
                + FALLOFF_MARGIN)
                .min(MAX_REFERENCE_DENSITY),
            ParticleStyle::Thresholded | ParticleStyle::Pyroclastic => MAX_REFERENCE_DENSITY,
        }
    }

    /// Calls `leaf` on every particle whose box may overlap the region `overlaps` accepts (a
    /// predicate on boxes that must accept every box holding a point of the region).
    fn visit(&self, overlaps: impl Fn(&Aabb) -> bool, mut leaf: impl FnMut(&Placed)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = [0u32; STACK_DEPTH];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let node = &self.nodes[stack[depth] as usize];
            if !overlaps(&node.bounds) {
                continue;
            }
            if node.count > 0 {
                let first = node.first as usize;
                for p in &self.particles[first..first + node.count as usize] {
                    leaf(p);
                }
            } else {
                stack[depth] = node.first;
                stack[depth + 1] = node.first + 1;
                depth += 2;
            }
        }
    }
}

/// Builds the subtree of `node` over `particles[range]`: a leaf of at most [`LEAF_PARTICLES`], or
/// two children split at the median centre along the widest axis of the centres.
fn build(
    particles: &mut [Placed],
    nodes: &mut Vec<Node>,
    node: usize,
    range: std::ops::Range<usize>,
) {
    let slice = &mut particles[range.clone()];
    let bounds = slice
        .iter()
        .map(Placed::aabb)
        .reduce(|a, b| a.union(&b))
        .expect("a non-empty range");
    if slice.len() <= LEAF_PARTICLES {
        nodes[node] = Node {
            bounds,
            first: range.start as u32,
            count: slice.len() as u32,
        };
        return;
    }
    let (lo, hi) = slice.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p.centre_m), hi.max(p.centre_m)),
    );
    let axis = (hi - lo).max_position();
    let mid = slice.len() / 2;
    slice.select_nth_unstable_by(mid, |a, b| a.centre_m[axis].total_cmp(&b.centre_m[axis]));
    let first = nodes.len();
    let child = Node {
        bounds,
        first: 0,
        count: 0,
    };
    nodes.extend([child, child]);
    nodes[node] = Node {
        bounds,
        first: first as u32,
        count: 0,
    };
    build(particles, nodes, first, range.start..range.start + mid);
    build(particles, nodes, first + 1, range.start + mid..range.end);
}

impl Medium for ParticleSetMedium {
    fn extinction_per_m(&self, p: Vec3) -> f32 {
        let mut sum = 0.0;
        self.visit(
            |b| p.cmpge(b.min).all() && p.cmple(b.max).all(),
            |q| {
                let local = (p - q.centre_m) * q.inv_radii;
                if local.length_squared() < 1.0 {
                    let local = q.rotation * local;
                    let noise = self.noise_at(local);
                    sum += q.extinction_per_m * self.reference.density_with_noise(local, noise);
                }
            },
        );
        sum
    }

    fn max_extinction_in_box(&self, b: &Aabb) -> f32 {
        let mut sum = 0.0;
        self.visit(
            |node| node.overlaps(b),
            |q| {
                let r = q.nearest_radius(b);
                if r < 1.0 {
                    sum += q.extinction_per_m * self.density_bound(r);
                }
            },
        );
        sum * (1.0 + BOUND_RELATIVE_MARGIN)
    }

    fn support(&self) -> Support {
        self.support
    }

    fn nesting(&self) -> Option<Nesting> {
        self.nesting
    }

    fn bounds_within(&self, region: &Aabb) -> Option<Aabb> {
        let mut bounds: Option<Aabb> = None;
        self.visit(
            |node| node.overlaps(region),
            |q| {
                let b = q.aabb();
                if b.overlaps(region) {
                    bounds = Some(bounds.map_or(b, |a| a.union(&b)));
                }
            },
        );
        bounds
    }
}
