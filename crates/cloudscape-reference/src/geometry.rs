//! Rays against boxes, the planet and altitude bands. Sphere tests run in `f64`: at an Earth radius
//! of 6 360 km, `f32` keeps only about half a metre.

use cloudscape::field::PlanetGeometry;
use cloudscape::scene::PlanetShape;
use glam::{DVec3, Vec3};

/// A ray parameter interval `[start, end]`, metres along a unit direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Where the interval begins.
    pub start: f32,
    /// Where it ends (>= start for a non-empty interval).
    pub end: f32,
}

impl Interval {
    /// The overlap with `[start, end]`, if any has positive length.
    pub fn clip(self, start: f32, end: f32) -> Option<Interval> {
        let clipped = Interval {
            start: self.start.max(start),
            end: self.end.min(end),
        };
        (clipped.end > clipped.start).then_some(clipped)
    }
}

/// An axis-aligned box, metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Minimum corner.
    pub min: Vec3,
    /// Maximum corner.
    pub max: Vec3,
}

impl Aabb {
    /// Where the ray `origin + t dir` is inside the box (slab method, Kay & Kajiya 1986), or None.
    pub fn ray_interval(&self, origin: Vec3, dir: Vec3) -> Option<Interval> {
        let inv = dir.recip();
        let a = (self.min - origin) * inv;
        let b = (self.max - origin) * inv;
        // NaN (0 * inf, a ray in a face's plane) is dropped by min/max.
        let start = a.min(b).max_element();
        let end = a.max(b).min_element();
        (end >= start && end > 0.0).then_some(Interval { start, end })
    }

    /// The smallest box holding both.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Whether the closed boxes share a point.
    pub fn overlaps(&self, other: &Aabb) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }
}

/// Centre of the spherical planet, `(0, -R, 0)` (see `cloudscape::scene`).
fn planet_centre(planet: &PlanetGeometry) -> DVec3 {
    DVec3::new(0.0, -f64::from(planet.radius_m), 0.0)
}

/// Unit vector straight up at `p`: +y on a flat planet, away from the centre on a sphere.
pub fn up(planet: &PlanetGeometry, p: Vec3) -> Vec3 {
    match planet.shape {
        PlanetShape::Flat => Vec3::Y,
        PlanetShape::Spherical => (p.as_dvec3() - planet_centre(planet)).normalize().as_vec3(),
    }
}

/// Distance along the ray to the ground (altitude 0), or infinity when it never gets there. A ray
/// that starts below the ground is taken to hit it at once.
pub fn ground_distance(planet: &PlanetGeometry, origin: Vec3, dir: Vec3) -> f32 {
    match planet.below(origin, dir, 0.0) {
        Some((t0, t1)) if t1 > 0.0 => t0.max(0.0) as f32,
        _ => f32::INFINITY,
    }
}

/// The stretches of the ray within `[t_min, t_max]` whose altitude lies in
/// `[bottom_m, top_m]`, in order: at most two (down through a spherical shell and up out of it).
pub fn band_intervals(
    planet: &PlanetGeometry,
    origin: Vec3,
    dir: Vec3,
    (bottom_m, top_m): (f32, f32),
    (t_min, t_max): (f32, f32),
) -> [Option<Interval>; 2] {
    let Some((outer0, outer1)) = planet.below(origin, dir, top_m) else {
        return [None, None];
    };
    let span = |a: f64, b: f64| {
        Interval {
            start: a as f32,
            end: b as f32,
        }
        .clip(t_min, t_max)
    };
    match planet.below(origin, dir, bottom_m) {
        Some((inner0, inner1)) if inner1 > outer0 && inner0 < outer1 => {
            match (
                span(outer0, inner0.max(outer0)),
                span(inner1.min(outer1), outer1),
            ) {
                (None, second) => [second, None],
                (first, second) => [first, second],
            }
        }
        _ => [span(outer0, outer1), None],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const EARTH: PlanetGeometry = PlanetGeometry {
        shape: PlanetShape::Spherical,
        radius_m: 6_360_000.0,
    };
    const FLAT: PlanetGeometry = PlanetGeometry {
        shape: PlanetShape::Flat,
        radius_m: 6_360_000.0,
    };

    #[test]
    fn box_interval_is_where_the_ray_is_inside() {
        let b = Aabb {
            min: Vec3::splat(-1.0),
            max: Vec3::splat(1.0),
        };
        let i = b.ray_interval(Vec3::new(-3.0, 0.0, 0.0), Vec3::X).unwrap();
        assert_eq!((i.start, i.end), (2.0, 4.0));
        assert!(b.ray_interval(Vec3::new(-3.0, 2.0, 0.0), Vec3::X).is_none());
        assert!(b.ray_interval(Vec3::new(3.0, 0.0, 0.0), Vec3::X).is_none());
        let inside = b.ray_interval(Vec3::ZERO, Vec3::Y).unwrap();
        assert_eq!((inside.start, inside.end), (-1.0, 1.0));
    }

    #[test]
    fn ground_is_hit_straight_down_and_missed_looking_up() {
        for planet in [EARTH, FLAT] {
            let o = Vec3::new(10.0, 100.0, -5.0);
            let t = ground_distance(&planet, o, Vec3::NEG_Y);
            assert!((t - 100.0).abs() < 1e-3, "{t}");
            assert_eq!(ground_distance(&planet, o, Vec3::Y), f32::INFINITY);
        }
        // A horizontal ray misses the sphere (it curves away) but not a tilted one.
        assert_eq!(
            ground_distance(&EARTH, Vec3::Y * 100.0, Vec3::X),
            f32::INFINITY
        );
        let dir = Vec3::new(1.0, -0.01, 0.0).normalize();
        let t = ground_distance(&EARTH, Vec3::Y * 100.0, dir);
        let hit = Vec3::Y * 100.0 + dir * t;
        assert!(
            EARTH.altitude_m(hit).abs() < 0.5,
            "{}",
            EARTH.altitude_m(hit)
        );
    }

    #[test]
    fn band_from_below_is_one_stretch_and_grazing_from_above_two() {
        let up_ray = band_intervals(&EARTH, Vec3::ZERO, Vec3::Y, (1000.0, 2000.0), (0.0, 1e9));
        let i = up_ray[0].unwrap();
        assert!((i.start - 1000.0).abs() < 0.01 && (i.end - 2000.0).abs() < 0.01);
        assert!(up_ray[1].is_none());
        // From 3 km, slightly downward: down through the band, below it (lowest at 138 m, 190 km
        // away), and up through it again as the ground curves away.
        let dir = Vec3::new(1.0, -0.03, 0.0).normalize();
        let [a, b] = band_intervals(&EARTH, Vec3::Y * 3000.0, dir, (500.0, 2000.0), (0.0, 1e9));
        let (a, b) = (a.unwrap(), b.unwrap());
        assert!(a.end <= b.start);
        for t in [a.start, a.end, b.start, b.end] {
            let h = EARTH.altitude_m(Vec3::Y * 3000.0 + dir * t);
            assert!((h - 500.0).abs() < 2.0 || (h - 2000.0).abs() < 2.0, "{h}");
        }
        let [flat, none] = band_intervals(&FLAT, Vec3::ZERO, Vec3::Y, (5.0, 7.0), (0.0, 6.0));
        assert_eq!(
            flat,
            Some(Interval {
                start: 5.0,
                end: 6.0
            })
        );
        assert!(none.is_none());
    }
}
