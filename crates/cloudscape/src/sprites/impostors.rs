//! The ring of impostors (Wang 2003, "Ring of impostors"): an octagon of 8 impostors around the
//! eye, 45 degrees each. Clouds beyond the ring are rendered into the impostors' textures and
//! drawn as 8 quads; clouds within it are drawn in 3D. An impostor is rendered again after the eye
//! moves 15 % of the ring radius sideways or 2 % vertically, or after 10 minutes of scene time
//! (Wang's empirical thresholds), one sector per frame so the work spreads over frames.
//!
//! Wang's "gray edges" come from blending non-premultiplied colour into a cleared texture and
//! blending the result again; here an impostor holds premultiplied radiance and opacity, exactly
//! what the sprites would have written, so compositing it adds no fringe.

use glam::{Mat4, Vec3, Vec4};

/// Sectors of the ring.
pub const SECTORS: usize = 8;
/// Horizontal half-angle of a sector: 22.5 degrees.
pub const HALF_ANGLE_RAD: f32 = std::f32::consts::PI / SECTORS as f32;
/// Re-render after the eye moves this fraction of the ring radius sideways (Wang 2003).
pub const HORIZONTAL_TOLERANCE: f32 = 0.15;
/// Re-render after the eye moves this fraction of the ring radius vertically (Wang 2003).
pub const VERTICAL_TOLERANCE: f32 = 0.02;
/// Re-render after this much scene time, s (Wang 2003: 10 minutes).
pub const MAX_AGE_S: f32 = 600.0;
/// Height over width of an impostor's texture.
pub const ASPECT: f32 = 0.5;

/// One sector's view: where it was rendered from and what it covers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SectorView {
    /// The eye it was rendered from, m.
    pub eye_m: Vec3,
    /// Scene time it was rendered at, s.
    pub time_s: f32,
    /// World to clip of its camera.
    pub clip_from_world: Mat4,
    /// Its quad's corners at the ring radius: bottom-left, bottom-right, top-left, top-right.
    pub corners_m: [Vec3; 4],
    /// Unit horizontal direction of its centre.
    pub forward: Vec3,
}

/// Unit horizontal direction of sector `k`'s centre (k x 45 degrees clockwise from north).
pub fn sector_direction(k: usize) -> Vec3 {
    let az = 2.0 * HALF_ANGLE_RAD * k as f32;
    Vec3::new(az.sin(), 0.0, -az.cos())
}

/// The sector of horizontal direction `d` from the eye.
pub fn sector_of(d: Vec3) -> usize {
    let az = d.x.atan2(-d.z).rem_euclid(std::f32::consts::TAU);
    ((az / (2.0 * HALF_ANGLE_RAD) + 0.5) as usize) % SECTORS
}

impl SectorView {
    /// Sector `k` seen from `eye_m` at `time_s`, at ring radius `radius_m`, covering elevations
    /// whose tangents run from `tan_low` to `tan_high`: an off-axis perspective whose image plane
    /// is the quad.
    pub fn new(
        k: usize,
        eye_m: Vec3,
        time_s: f32,
        radius_m: f32,
        (tan_low, tan_high): (f32, f32),
    ) -> SectorView {
        let forward = sector_direction(k);
        let right = forward.cross(Vec3::Y);
        let view_from_world = glam::camera::rh::view::look_to_mat4(eye_m, forward, Vec3::Y);
        let tan_side = HALF_ANGLE_RAD.tan();
        let (centre, half) = (0.5 * (tan_high + tan_low), 0.5 * (tan_high - tan_low));
        // x_ndc = (x / -z) / tan_side, y_ndc = (y / -z - centre) / half; z_ndc a constant 1/2, so
        // nothing is clipped by depth but what lies behind the eye.
        let clip_from_view = Mat4::from_cols(
            Vec4::new(1.0 / tan_side, 0.0, 0.0, 0.0),
            Vec4::new(0.0, 1.0 / half, 0.0, 0.0),
            Vec4::new(0.0, centre / half, -0.5, -1.0),
            Vec4::ZERO,
        );
        let at = |side: f32, tan: f32| {
            eye_m + (forward + right * side * tan_side + Vec3::Y * tan) * radius_m
        };
        SectorView {
            eye_m,
            time_s,
            clip_from_world: clip_from_view * view_from_world,
            corners_m: [
                at(-1.0, tan_low),
                at(1.0, tan_low),
                at(-1.0, tan_high),
                at(1.0, tan_high),
            ],
            forward,
        }
    }

    /// Whether the eye at `eye_m`, at `time_s`, has moved or aged past Wang's thresholds.
    pub fn stale(&self, eye_m: Vec3, time_s: f32, radius_m: f32) -> bool {
        let moved = eye_m - self.eye_m;
        let sideways = Vec3::new(moved.x, 0.0, moved.z).length();
        sideways > HORIZONTAL_TOLERANCE * radius_m
            || moved.y.abs() > VERTICAL_TOLERANCE * radius_m
            || (time_s - self.time_s).abs() > MAX_AGE_S
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eight_sectors_tile_the_horizon() {
        for k in 0..SECTORS {
            assert_eq!(sector_of(sector_direction(k)), k);
            let edge = Mat4::from_rotation_y(-(HALF_ANGLE_RAD - 0.01))
                .transform_vector3(sector_direction(k));
            assert_eq!(sector_of(edge), k);
        }
    }

    #[test]
    fn the_quad_is_the_image_plane_of_its_camera() {
        let eye = Vec3::new(100.0, 1200.0, -50.0);
        let s = SectorView::new(3, eye, 0.0, 10_000.0, (-0.1, 0.3));
        let ndc = |p: Vec3| {
            let c = s.clip_from_world * p.extend(1.0);
            c.truncate() / c.w
        };
        let expected = [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)];
        for (corner, (x, y)) in s.corners_m.iter().zip(expected) {
            let n = ndc(*corner);
            assert!((n.x - x).abs() < 1e-4 && (n.y - y).abs() < 1e-4, "{n}");
            assert!((corner.distance(eye) > 10_000.0));
        }
        // Points farther along the same rays land on the same texels.
        let far = eye + (s.corners_m[3] - eye) * 4.0;
        assert!((ndc(far) - ndc(s.corners_m[3])).truncate().length() < 1e-4);
    }

    #[test]
    fn impostors_go_stale_after_wangs_thresholds() {
        let s = SectorView::new(0, Vec3::new(0.0, 1000.0, 0.0), 0.0, 10_000.0, (-0.1, 0.3));
        let r = 10_000.0;
        assert!(!s.stale(Vec3::new(1400.0, 1000.0, 0.0), 10.0, r));
        assert!(s.stale(Vec3::new(1600.0, 1000.0, 0.0), 10.0, r));
        assert!(!s.stale(Vec3::new(0.0, 1190.0, 0.0), 10.0, r));
        assert!(s.stale(Vec3::new(0.0, 1210.0, 0.0), 10.0, r));
        assert!(s.stale(Vec3::new(0.0, 1000.0, 0.0), 601.0, r));
    }
}
