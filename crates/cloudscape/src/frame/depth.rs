//! What a host's depth buffer stores: the three conventions engines use.

use glam::{Mat4, Vec4};

/// How depth-buffer values map to distance. The host chooses; the clouds stop at its geometry in
/// every convention.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DepthConvention {
    /// 0 at the near plane, 1 at the far plane; cleared to 1.
    #[default]
    Standard,
    /// 1 at the near plane, 0 at the far plane; cleared to 0 (better precision far away).
    Reversed,
    /// Reversed-Z with the far plane at infinity (Bevy's): 1 at the near plane, 0 at infinity.
    ReversedInfinite,
}

impl DepthConvention {
    /// Every convention.
    pub const ALL: [DepthConvention; 3] = [
        DepthConvention::Standard,
        DepthConvention::Reversed,
        DepthConvention::ReversedInfinite,
    ];

    /// A right-handed perspective projection (wgpu clip space) of vertical field of view
    /// `fov_y_rad`, for this convention.
    pub fn perspective(self, fov_y_rad: f32, aspect: f32, near_m: f32, far_m: f32) -> Mat4 {
        use glam::camera::rh::proj::directx;
        match self {
            DepthConvention::Standard => directx::perspective(fov_y_rad, aspect, near_m, far_m),
            DepthConvention::Reversed => directx::perspective(fov_y_rad, aspect, far_m, near_m),
            DepthConvention::ReversedInfinite => {
                directx::perspective_infinite_reverse(fov_y_rad, aspect, near_m)
            }
        }
    }

    /// The value a cleared buffer holds: no geometry.
    pub fn far_value(self) -> f32 {
        match self {
            DepthConvention::Standard => 1.0,
            DepthConvention::Reversed | DepthConvention::ReversedInfinite => 0.0,
        }
    }

    /// Whether nearer geometry stores larger values.
    pub fn is_reversed(self) -> bool {
        self != DepthConvention::Standard
    }

    /// Whether `depth` is geometry rather than the cleared value.
    pub fn has_geometry(self, depth: f32) -> bool {
        if self.is_reversed() {
            depth > 0.0
        } else {
            depth < 1.0
        }
    }

    /// The depth compare function that keeps nearer fragments.
    pub fn compare(self) -> wgpu::CompareFunction {
        if self.is_reversed() {
            wgpu::CompareFunction::Greater
        } else {
            wgpu::CompareFunction::Less
        }
    }

    /// The depth-buffer value of a point `distance_m` straight ahead under `clip_from_view`.
    pub fn depth_of_distance(self, clip_from_view: &Mat4, distance_m: f32) -> f32 {
        let clip = *clip_from_view * Vec4::new(0.0, 0.0, -distance_m, 1.0);
        clip.z / clip.w
    }
}
