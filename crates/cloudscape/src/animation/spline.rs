//! Interpolating splines over keyframe times: the Catmull-Rom family with the keyframe times as
//! knots, evaluated as cubic Hermite segments.
//!
//! Catmull and Rom ("A class of local interpolating splines", 1974) build each segment from the
//! four nearest keys; Barry and Goldman ("A recursive evaluation algorithm for a class of
//! Catmull-Rom splines", SIGGRAPH 1988) evaluate them for any knot sequence, and Yuksel, Schaefer
//! and Keyser ("Parameterization and applications of Catmull-Rom curves", CAD 2011) compare the
//! uniform, centripetal and chordal knot choices. Here the knots are the keyframe times: the curve
//! is then C1 in *time* (velocity is continuous across keyframes, which a camera path needs), and
//! with evenly spaced times it is the uniform Catmull-Rom spline. Centripetal knots would need a
//! time reparameterisation that breaks velocity continuity at the keys.

use std::ops::{Add, Mul, Sub};

/// A value a spline interpolates: anything with vector-space arithmetic over `f32` (`f32`, `Vec3`).
pub trait SplineValue:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<f32, Output = Self>
{
}

impl<T> SplineValue for T where T: Copy + Add<Output = T> + Sub<Output = T> + Mul<f32, Output = T> {}

/// The value at `time_s` of the Catmull-Rom spline through `keys` (`(time_s, value)`, times
/// strictly increasing), with the key times as knots: it passes through every key, its velocity is
/// continuous, and it holds the first value before the first key and the last after the last.
/// `None` when `keys` is empty.
///
/// On the segment from key `i` (time `t_i`, value `p_i`) to key `i + 1` it is the cubic Hermite
/// curve with end velocities [`velocity_at_key`], at `u = (t - t_i) / h`, `h = t_{i+1} - t_i`:
/// `(2u^3 - 3u^2 + 1) p_i + (u^3 - 2u^2 + u) h m_i + (-2u^3 + 3u^2) p_{i+1} + (u^3 - u^2) h m_{i+1}`.
pub fn catmull_rom<T: SplineValue>(keys: &[(f32, T)], time_s: f32) -> Option<T> {
    let (first, last) = (keys.first()?, keys.last()?);
    let next = keys.partition_point(|&(t, _)| t <= time_s);
    if next == 0 {
        return Some(first.1);
    }
    if next == keys.len() {
        return Some(last.1);
    }
    let ((t0, p0), (t1, p1)) = (keys[next - 1], keys[next]);
    let h = t1 - t0;
    let u = (time_s - t0) / h;
    let (u2, u3) = (u * u, u * u * u);
    let m0 = velocity_at_key(keys, next - 1) * h;
    let m1 = velocity_at_key(keys, next) * h;
    Some(
        p0 * (2.0 * u3 - 3.0 * u2 + 1.0)
            + m0 * (u3 - 2.0 * u2 + u)
            + p1 * (-2.0 * u3 + 3.0 * u2)
            + m1 * (u3 - u2),
    )
}

/// The spline's velocity (per second) at key `index` of at least 2 keys: the derivative of the
/// Barry-Goldman pyramid at its middle knot (Barry & Goldman 1988),
/// `m_i = (b d_{i-1} + a d_i) / (a + b)` with `a = t_i - t_{i-1}`, `b = t_{i+1} - t_i` and chord
/// slopes `d_i = (p_{i+1} - p_i) / (t_{i+1} - t_i)`; at the first and last key, the slope of the
/// one chord there (the tangent of a mirrored phantom key).
pub fn velocity_at_key<T: SplineValue>(keys: &[(f32, T)], index: usize) -> T {
    let slope = |i: usize| {
        let ((ta, pa), (tb, pb)) = (keys[i], keys[i + 1]);
        (pb - pa) * (1.0 / (tb - ta))
    };
    match (index.checked_sub(1), index + 1 < keys.len()) {
        (None, _) => slope(0),
        (Some(previous), false) => slope(previous),
        (Some(previous), true) => {
            let a = keys[index].0 - keys[previous].0;
            let b = keys[index + 1].0 - keys[index].0;
            (slope(previous) * b + slope(index) * a) * (1.0 / (a + b))
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use glam::Vec3;

    /// Keys at uneven times, turning sharply, so that the chords on either side of each interior
    /// key have very different slopes.
    pub(in crate::animation) fn zigzag() -> Vec<(f32, Vec3)> {
        vec![
            (0.0, Vec3::new(0.0, 0.0, 0.0)),
            (1.0, Vec3::new(4.0, 1.0, 0.0)),
            (3.5, Vec3::new(5.0, -2.0, 3.0)),
            (4.0, Vec3::new(1.0, 0.0, 2.0)),
            (7.0, Vec3::new(2.0, 6.0, -1.0)),
        ]
    }

    /// One-sided velocities of `f` at `t` from the left and from the right, by second-order
    /// finite differences `(3 f(t) - 4 f(t -+ e) + f(t -+ 2e)) / (+-2e)`.
    pub(in crate::animation) fn one_sided_velocities(
        f: impl Fn(f32) -> Vec3,
        t: f32,
    ) -> (Vec3, Vec3) {
        let e = 1e-2;
        let left = (f(t) * 3.0 - f(t - e) * 4.0 + f(t - 2.0 * e)) / (2.0 * e);
        let right = (f(t + e) * 4.0 - f(t) * 3.0 - f(t + 2.0 * e)) / (2.0 * e);
        (left, right)
    }

    fn at(keys: &[(f32, Vec3)], t: f32) -> Vec3 {
        catmull_rom(keys, t).unwrap()
    }

    #[test]
    fn passes_through_every_key() {
        let keys = zigzag();
        for &(t, p) in &keys {
            assert!(at(&keys, t).abs_diff_eq(p, 1e-5), "{t}: {}", at(&keys, t));
        }
    }

    #[test]
    fn velocity_is_continuous_across_interior_keys() {
        let keys = zigzag();
        for (index, &(t, _)) in keys.iter().enumerate().take(keys.len() - 1).skip(1) {
            let (left, right) = one_sided_velocities(|t| at(&keys, t), t);
            let expected = velocity_at_key(&keys, index);
            assert!(
                left.abs_diff_eq(expected, 2e-2),
                "{t}: {left} vs {expected}"
            );
            assert!(
                right.abs_diff_eq(expected, 2e-2),
                "{t}: {right} vs {expected}"
            );
            // The chords meet at an angle, so a spline that is only C0 would fail the checks above.
            let (before, after) = (
                velocity_at_key(&keys[index - 1..=index], 1),
                velocity_at_key(&keys[index..], 0),
            );
            assert!(before.distance(after) > 1.0, "{t}: {before} {after}");
        }
    }

    #[test]
    fn holds_the_end_values_outside_the_keys() {
        let keys = zigzag();
        assert_eq!(at(&keys, -5.0), keys[0].1);
        assert_eq!(at(&keys, 100.0), keys[4].1);
        assert_eq!(catmull_rom::<f32>(&[], 1.0), None);
        assert_eq!(catmull_rom(&[(2.0, 3.0f32)], 0.0), Some(3.0));
    }

    #[test]
    fn uniform_motion_stays_uniform_at_uneven_key_times() {
        let (start, speed) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(-2.0, 0.5, 4.0));
        let keys: Vec<(f32, Vec3)> = [0.0, 0.3, 2.0, 2.5, 6.0]
            .iter()
            .map(|&t| (t, start + speed * t))
            .collect();
        for step in 0..=60 {
            let t = step as f32 * 0.1;
            assert!(at(&keys, t).abs_diff_eq(start + speed * t, 1e-4), "{t}");
        }
    }

    #[test]
    fn evenly_spaced_keys_give_the_uniform_catmull_rom_spline() {
        // Uniform Catmull-Rom (Catmull & Rom 1974) at the middle of the segment p1..p2:
        // (-p0 + 9 p1 + 9 p2 - p3) / 16.
        let values = [0.0f32, 1.0, 5.0, 2.0];
        let keys: Vec<(f32, f32)> = values
            .iter()
            .enumerate()
            .map(|(i, &v)| (i as f32 * 2.0, v))
            .collect();
        let expected = (-values[0] + 9.0 * values[1] + 9.0 * values[2] - values[3]) / 16.0;
        assert!((catmull_rom(&keys, 3.0).unwrap() - expected).abs() < 1e-5);
    }
}
