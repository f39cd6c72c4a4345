//! The bind groups every pass shares: the field, the frame and the environment, at the slots of
//! [`crate::shader`].

use super::FrameGpu;
use crate::environment::EnvironmentGpu;
use crate::field::gpu::FieldGpu;

/// The field, frame and environment groups of one frame, borrowed for encoding.
#[derive(Clone, Copy)]
pub struct Shared<'a> {
    /// The cloud field (group 0).
    pub field: &'a FieldGpu,
    /// The frame (group 1).
    pub frame: &'a FrameGpu,
    /// The environment (group 2).
    pub environment: &'a EnvironmentGpu,
}

impl<'a> Shared<'a> {
    /// Pipeline layouts: the shared groups, then the pass's own at [`crate::shader::PASS_GROUP`].
    pub fn layouts(
        &self,
        pass: &'a wgpu::BindGroupLayout,
    ) -> [Option<&'a wgpu::BindGroupLayout>; 4] {
        [
            Some(self.field.layout()),
            Some(self.frame.layout()),
            Some(self.environment.layout()),
            Some(pass),
        ]
    }

    /// Bind groups in the order of [`Shared::layouts`].
    pub fn bind_groups(&self, pass: &'a wgpu::BindGroup) -> [Option<&'a wgpu::BindGroup>; 4] {
        [
            Some(self.field.bind_group()),
            Some(self.frame.bind_group()),
            Some(self.environment.bind_group()),
            Some(pass),
        ]
    }
}
