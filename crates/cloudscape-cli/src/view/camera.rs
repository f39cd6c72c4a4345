//! The viewer's camera: a fly camera and an orbit around a point, in the scene's conventions
//! (metres, `y` up, `x` east, `z` south; yaw clockwise from north, pitch above the horizon; see
//! `cloudscape::scene::direction_from_angles_deg`). Pure maths: no window, no GPU.

use cloudscape::scene::{Camera, direction_from_angles_deg};
use glam::{Vec2, Vec3};

/// Slowest fly speed: walking, m/s.
pub const MIN_SPEED_M_PER_S: f32 = 1.4;
/// Fastest fly speed: enough to cross a cloud layer in seconds, m/s.
pub const MAX_SPEED_M_PER_S: f32 = 1000.0;
/// Speed factor while shift is held.
const FAST_FACTOR: f32 = 10.0;
/// Speed factor per notch of the mouse wheel.
const WHEEL_FACTOR: f32 = 1.25;
/// Degrees the view turns per pixel the mouse moves.
const LOOK_DEG_PER_PX: f32 = 0.15;
/// The pitch stays this far from straight up or down, where yaw loses its meaning, degrees.
const MAX_PITCH_DEG: f32 = 89.0;
/// Nearest and farthest orbit distances, m.
const ORBIT_DISTANCE_M: (f32, f32) = (10.0, 200_000.0);

/// Where the eye is and where it looks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Eye position, m.
    pub position_m: Vec3,
    /// View azimuth, degrees clockwise from north, 0..360.
    pub yaw_deg: f32,
    /// View elevation above the horizon, degrees.
    pub pitch_deg: f32,
}

impl Pose {
    /// The pose of a scene camera: a `look_at_m` becomes the yaw and pitch toward it.
    pub fn of_camera(camera: &Camera) -> Pose {
        let position_m = Vec3::from_array(camera.position_m);
        let Some(target) = camera.look_at_m else {
            return Pose {
                position_m,
                yaw_deg: camera.yaw_deg.rem_euclid(360.0),
                pitch_deg: camera.pitch_deg.clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG),
            };
        };
        let d = (Vec3::from_array(target) - position_m).normalize_or(Vec3::NEG_Z);
        Pose {
            position_m,
            yaw_deg: d.x.atan2(-d.z).to_degrees().rem_euclid(360.0),
            pitch_deg: d.y.asin().to_degrees().clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG),
        }
    }

    /// Writes the pose into a scene camera (by yaw and pitch; its `look_at_m` is cleared).
    pub fn write_to(&self, camera: &mut Camera) {
        camera.position_m = self.position_m.to_array();
        camera.look_at_m = None;
        camera.yaw_deg = self.yaw_deg;
        camera.pitch_deg = self.pitch_deg;
    }

    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        direction_from_angles_deg(self.pitch_deg, self.yaw_deg)
    }

    /// Unit direction to the right of the view, horizontal: `forward x up` with `y` up.
    pub fn right(&self) -> Vec3 {
        let yaw = self.yaw_deg.to_radians();
        Vec3::new(yaw.cos(), 0.0, yaw.sin())
    }

    /// Turns the view by `delta_px` mouse pixels (right and down).
    fn turn(&mut self, delta_px: Vec2) {
        self.yaw_deg = (self.yaw_deg + delta_px.x * LOOK_DEG_PER_PX).rem_euclid(360.0);
        self.pitch_deg =
            (self.pitch_deg - delta_px.y * LOOK_DEG_PER_PX).clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG);
    }
}

/// Movement asked for by the keys held: each axis -1, 0 or 1.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    /// W (+1) and S (-1): along the view.
    pub forward: f32,
    /// D (+1) and A (-1): sideways.
    pub right: f32,
    /// E (+1) and Q (-1): straight up and down.
    pub up: f32,
    /// Shift: ten times faster.
    pub fast: bool,
}

/// How the camera moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mode {
    /// Free flight: the keys move the eye, the mouse turns it.
    Fly,
    /// Around `target_m` at `distance_m`: the mouse swings the eye around it, the wheel moves it
    /// nearer or farther, the keys move the target.
    Orbit {
        /// The point looked at, m.
        target_m: Vec3,
        /// Distance from the target to the eye, m.
        distance_m: f32,
    },
}

/// The viewer's camera: a pose, a mode and a fly speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRig {
    /// Where the eye is and where it looks.
    pub pose: Pose,
    /// Fly or orbit.
    pub mode: Mode,
    /// Speed of the eye (fly) or of the target (orbit), m/s, `MIN_SPEED_M_PER_S..=MAX_SPEED_M_PER_S`.
    pub speed_m_per_s: f32,
}

impl CameraRig {
    /// A fly camera at the scene camera, at a speed of 50 m/s.
    pub fn new(camera: &Camera) -> CameraRig {
        CameraRig {
            pose: Pose::of_camera(camera),
            mode: Mode::Fly,
            speed_m_per_s: 50.0,
        }
    }

    /// The speed the keys move at now, m/s.
    pub fn current_speed_m_per_s(&self, fast: bool) -> f32 {
        let factor = if fast { FAST_FACTOR } else { 1.0 };
        (self.speed_m_per_s * factor).min(MAX_SPEED_M_PER_S)
    }

    /// Moves by `motion` for `dt_s` seconds: the eye in flight, the target in orbit.
    pub fn advance(&mut self, motion: &Motion, dt_s: f32) {
        let step = motion.forward * self.pose.forward()
            + motion.right * self.pose.right()
            + motion.up * Vec3::Y;
        let offset = step.normalize_or_zero() * self.current_speed_m_per_s(motion.fast) * dt_s;
        match &mut self.mode {
            Mode::Fly => self.pose.position_m += offset,
            Mode::Orbit { target_m, .. } => *target_m += offset,
        }
        self.place_orbit_eye();
    }

    /// Turns the view (fly) or swings the eye around the target (orbit) by `delta_px` mouse
    /// pixels.
    pub fn look(&mut self, delta_px: Vec2) {
        self.pose.turn(delta_px);
        self.place_orbit_eye();
    }

    /// Takes `notches` of the mouse wheel (positive away from the user): faster in flight, nearer
    /// in orbit.
    pub fn scroll(&mut self, notches: f32) {
        match &mut self.mode {
            Mode::Fly => {
                self.speed_m_per_s = (self.speed_m_per_s * WHEEL_FACTOR.powf(notches))
                    .clamp(MIN_SPEED_M_PER_S, MAX_SPEED_M_PER_S);
            }
            Mode::Orbit { distance_m, .. } => {
                let (near, far) = ORBIT_DISTANCE_M;
                *distance_m = (*distance_m / WHEEL_FACTOR.powf(notches)).clamp(near, far);
            }
        }
        self.place_orbit_eye();
    }

    /// Starts orbiting the point `distance_m` ahead of the eye (the eye stays where it is), or goes
    /// back to free flight from where the orbit left the eye.
    pub fn set_orbit(&mut self, orbit: bool, distance_m: f32) {
        self.mode = if orbit {
            let distance_m = distance_m.clamp(ORBIT_DISTANCE_M.0, ORBIT_DISTANCE_M.1);
            Mode::Orbit {
                target_m: self.pose.position_m + self.pose.forward() * distance_m,
                distance_m,
            }
        } else {
            Mode::Fly
        };
        self.place_orbit_eye();
    }

    /// In orbit, puts the eye `distance_m` back from the target along the view.
    fn place_orbit_eye(&mut self) {
        if let Mode::Orbit {
            target_m,
            distance_m,
        } = self.mode
        {
            self.pose.position_m = target_m - self.pose.forward() * distance_m;
        }
    }
}

/// Distance along the view from `pose` to the altitude `altitude_m` (a cloud layer's middle),
/// when the view is headed there and it is nearer than `far_m`; else `far_m`.
pub fn distance_to_altitude_m(pose: &Pose, altitude_m: f32, far_m: f32) -> f32 {
    let dy = altitude_m - pose.position_m.y;
    let rise = pose.forward().y;
    let t = dy / rise;
    if t.is_finite() && t > 0.0 {
        t.min(far_m)
    } else {
        far_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_near(a: Vec3, b: Vec3) {
        assert!((a - b).length() < 1e-3, "{a} != {b}");
    }

    fn pose(yaw_deg: f32, pitch_deg: f32) -> Pose {
        Pose {
            position_m: Vec3::new(0.0, 100.0, 0.0),
            yaw_deg,
            pitch_deg,
        }
    }

    #[test]
    fn yaw_is_clockwise_from_north_and_right_is_to_the_right() {
        assert_near(pose(0.0, 0.0).forward(), Vec3::NEG_Z);
        assert_near(pose(90.0, 0.0).forward(), Vec3::X);
        assert_near(pose(0.0, 0.0).right(), Vec3::X);
        assert_near(pose(90.0, 0.0).right(), Vec3::Z);
        let p = pose(37.0, 20.0);
        let expected = p.forward().cross(Vec3::Y).normalize();
        assert_near(p.right(), expected);
    }

    #[test]
    fn a_look_at_camera_becomes_the_same_view_by_yaw_and_pitch() {
        let camera = Camera {
            position_m: [100.0, 30.0, -50.0],
            look_at_m: Some([-400.0, 1500.0, -3000.0]),
            ..Camera::default()
        };
        let p = Pose::of_camera(&camera);
        let expected =
            (Vec3::new(-400.0, 1500.0, -3000.0) - Vec3::new(100.0, 30.0, -50.0)).normalize();
        assert_near(p.forward(), expected);
        let mut written = Camera::default();
        p.write_to(&mut written);
        assert_eq!(written.look_at_m, None);
        assert_eq!(Pose::of_camera(&written), p);
    }

    #[test]
    fn flying_moves_along_the_view_at_the_speed_and_shift_is_faster_up_to_1_km_s() {
        let mut rig = CameraRig::new(&Camera::default());
        rig.pose = pose(90.0, 0.0);
        rig.speed_m_per_s = 10.0;
        let w = Motion {
            forward: 1.0,
            ..Motion::default()
        };
        rig.advance(&w, 2.0);
        assert_near(rig.pose.position_m, Vec3::new(20.0, 100.0, 0.0));
        rig.advance(&Motion { fast: true, ..w }, 1.0);
        assert_near(rig.pose.position_m, Vec3::new(120.0, 100.0, 0.0));
        rig.speed_m_per_s = MAX_SPEED_M_PER_S;
        assert_eq!(rig.current_speed_m_per_s(true), MAX_SPEED_M_PER_S);
        let up_and_right = Motion {
            up: 1.0,
            right: 1.0,
            ..Motion::default()
        };
        rig.speed_m_per_s = 1.0;
        let before = rig.pose.position_m;
        rig.advance(&up_and_right, 1.0);
        assert!(((rig.pose.position_m - before).length() - 1.0).abs() < 1e-4);
    }

    #[test]
    fn the_wheel_spans_walking_to_1_km_s() {
        let mut rig = CameraRig::new(&Camera::default());
        rig.scroll(-100.0);
        assert_eq!(rig.speed_m_per_s, MIN_SPEED_M_PER_S);
        rig.scroll(100.0);
        assert_eq!(rig.speed_m_per_s, MAX_SPEED_M_PER_S);
        rig.speed_m_per_s = 100.0;
        rig.scroll(1.0);
        assert!((rig.speed_m_per_s - 125.0).abs() < 1e-3);
    }

    #[test]
    fn the_mouse_turns_the_view_and_the_pitch_stops_short_of_the_pole() {
        let mut rig = CameraRig::new(&Camera::default());
        rig.pose = pose(350.0, 0.0);
        rig.look(Vec2::new(100.0, -1000.0));
        assert!(
            (rig.pose.yaw_deg - 5.0).abs() < 1e-3,
            "{}",
            rig.pose.yaw_deg
        );
        assert_eq!(rig.pose.pitch_deg, MAX_PITCH_DEG);
    }

    #[test]
    fn an_orbit_keeps_its_target_in_view_at_its_distance() {
        let mut rig = CameraRig::new(&Camera::default());
        rig.pose = pose(0.0, 10.0);
        let eye = rig.pose.position_m;
        rig.set_orbit(true, 2000.0);
        assert_near(rig.pose.position_m, eye);
        let Mode::Orbit { target_m, .. } = rig.mode else {
            panic!("orbiting")
        };
        for delta in [Vec2::new(300.0, 0.0), Vec2::new(-50.0, 80.0)] {
            rig.look(delta);
            let to_target = target_m - rig.pose.position_m;
            assert!((to_target.length() - 2000.0).abs() < 0.1);
            assert_near(to_target.normalize(), rig.pose.forward());
        }
        rig.scroll(1.0);
        let distance = (target_m - rig.pose.position_m).length();
        assert!((distance - 1600.0).abs() < 0.1, "{distance}");
        let seen_from = rig.pose.position_m;
        rig.set_orbit(false, 0.0);
        assert_eq!((rig.mode, rig.pose.position_m), (Mode::Fly, seen_from));
    }

    #[test]
    fn the_distance_to_a_layer_is_along_the_view() {
        let p = pose(0.0, 30.0);
        let d = distance_to_altitude_m(&p, 2100.0, 50_000.0);
        assert!((d - 4000.0).abs() < 0.5, "{d}");
        assert_eq!(
            distance_to_altitude_m(&pose(0.0, -10.0), 2100.0, 5000.0),
            5000.0
        );
    }
}
