//! The frame on the GPU: one uniform in a bind group of its own, rewritten each frame.

use super::{Frame, FrameSettings};
use crate::gpu::uniform::UniformGroup;
use crate::output::SampleGrid;
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, UVec2, Vec2, Vec3};

/// GPU layout of a [`Frame`]: the `Frame` struct of `frame.wgsl`, member for member.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniform {
    clip_from_world: Mat4,
    view_from_clip: Mat4,
    world_from_view: Mat4,
    camera_position_m: Vec3,
    far_m: f32,
    ground_albedo: Vec3,
    has_ground: u32,
    viewport_px: Vec2,
    time_s: f32,
    frame_index: u32,
    grid_subpixel: UVec2,
    grid_divisor: u32,
    depth_far_value: f32,
    depth_reversed: u32,
    cloud_mean_cosine: f32,
    reserved: UVec2,
}

impl FrameUniform {
    /// The uniform of `frame` with a technique output sampled on `grid`, and the renderer's
    /// `settings`.
    pub fn new(frame: &Frame, grid: &SampleGrid, settings: &FrameSettings) -> FrameUniform {
        FrameUniform {
            clip_from_world: frame.clip_from_world(),
            view_from_clip: frame.clip_from_view.inverse(),
            world_from_view: frame.view_from_world.inverse(),
            camera_position_m: frame.camera_position_m,
            far_m: frame.far_m,
            ground_albedo: settings.ground_albedo.unwrap_or(Vec3::ZERO),
            has_ground: settings.ground_albedo.is_some() as u32,
            viewport_px: frame.size.as_vec2(),
            time_s: frame.time_s,
            frame_index: frame.frame_index,
            grid_subpixel: grid.subpixel,
            grid_divisor: grid.divisor,
            depth_far_value: frame.depth.far_value(),
            depth_reversed: frame.depth.is_reversed() as u32,
            cloud_mean_cosine: settings.cloud_mean_cosine,
            reserved: UVec2::ZERO,
        }
    }
}

/// The frame's uniform buffer and bind group ([`crate::shader::FRAME_GROUP`] in every program):
/// `FrameGpu::new(ctx, "frame")`, then `write(ctx, &frame.uniform(&grid, &settings))` once per
/// frame.
pub type FrameGpu = UniformGroup<FrameUniform>;

/// The frame on the GPU (`frame.wgsl`, group [`crate::shader::FRAME_GROUP`]).
pub static FRAME_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "frame",
    "frame.wgsl",
    [&crate::field::noise::NOISE_WGSL],
    frame_constants
);

/// The frame's constants as WGSL: the step of the R2 sequence ([`super::FOOTPRINT_STEP`]) of the
/// footprint, and the golden-ratio step of the ray offsets over frames
/// ([`super::FRAME_OFFSET_STEP`]).
fn frame_constants() -> String {
    use crate::shader::WgslConst::F32;
    crate::shader::wgsl_consts([
        (
            "FRAME_FOOTPRINT_STEP_X",
            F32(super::FOOTPRINT_STEP[0] as f32),
        ),
        (
            "FRAME_FOOTPRINT_STEP_Y",
            F32(super::FOOTPRINT_STEP[1] as f32),
        ),
        ("FRAME_OFFSET_STEP", F32(super::FRAME_OFFSET_STEP as f32)),
    ])
}

impl crate::pass::SharedGroup for FrameGpu {
    fn layout(&self) -> &wgpu::BindGroupLayout {
        FrameGpu::layout(self)
    }

    fn bind_group(&self) -> &wgpu::BindGroup {
        FrameGpu::bind_group(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout_check::assert_wgsl_layout;

    #[test]
    fn frame_uniform_matches_its_wgsl_layout() {
        assert_wgsl_layout!(
            &crate::probe::PROBE_WGSL,
            "Frame",
            FrameUniform {
                clip_from_world,
                view_from_clip,
                world_from_view,
                camera_position_m,
                far_m,
                ground_albedo,
                has_ground,
                viewport_px,
                time_s,
                frame_index,
                grid_subpixel,
                grid_divisor,
                depth_far_value,
                depth_reversed,
                cloud_mean_cosine,
                reserved,
            }
        );
    }
}
