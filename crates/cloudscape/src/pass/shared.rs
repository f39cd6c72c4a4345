//! The bind groups every pass shares: the field, the frame and the environment, at the slots of
//! [`crate::shader`].

use crate::shader::Program;

/// A bind group that passes share at a fixed slot: its layout and its group.
pub trait SharedGroup {
    /// The group's layout.
    fn layout(&self) -> &wgpu::BindGroupLayout;
    /// The group.
    fn bind_group(&self) -> &wgpu::BindGroup;
}

/// Which shared groups a program uses: a pass binds only those (an unused slot stays empty).
/// Binding no more than a program reads is also what lavapipe needs: it crashes when a compute pass
/// binds the field's group and samples a texture of a higher group.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SharedSlots {
    used: [bool; 3],
}

impl SharedSlots {
    /// No shared group.
    pub const NONE: SharedSlots = SharedSlots { used: [false; 3] };

    /// The shared groups `program` binds: those its modules declare bindings in (each library
    /// module binds only its own group, [`crate::shader`]).
    pub fn of(program: &Program) -> SharedSlots {
        let groups = program.groups();
        SharedSlots {
            used: std::array::from_fn(|slot| groups.contains(&(slot as u32))),
        }
    }
}

/// The field, frame and environment groups of one frame, borrowed for encoding.
#[derive(Clone, Copy)]
pub struct Shared<'a> {
    /// The cloud field (group 0, [`crate::shader::FIELD_GROUP`]).
    pub field: &'a dyn SharedGroup,
    /// The frame (group 1).
    pub frame: &'a dyn SharedGroup,
    /// The environment (group 2).
    pub environment: &'a dyn SharedGroup,
}

impl<'a> Shared<'a> {
    /// Pipeline layouts: the shared groups `slots` names, then the pass's own at [`crate::shader::PASS_GROUP`].
    pub fn layouts(
        &self,
        slots: SharedSlots,
        pass: &'a wgpu::BindGroupLayout,
    ) -> [Option<&'a wgpu::BindGroupLayout>; 4] {
        let [field, frame, environment] = slots.used;
        [
            field.then_some(self.field.layout()),
            frame.then_some(self.frame.layout()),
            environment.then_some(self.environment.layout()),
            Some(pass),
        ]
    }

    /// Bind groups in the order of [`Shared::layouts`].
    pub fn bind_groups(
        &self,
        slots: SharedSlots,
        pass: &'a wgpu::BindGroup,
    ) -> [Option<&'a wgpu::BindGroup>; 4] {
        self.bind_groups_with(slots, self.environment.bind_group(), pass)
    }

    /// [`Shared::bind_groups`] for a pass that writes one of the environment's tables: with
    /// `environment`, the group that holds a stand-in for it
    /// ([`crate::environment::EnvironmentGpu::bind_group_writing`]).
    pub fn bind_groups_with(
        &self,
        slots: SharedSlots,
        environment: &'a wgpu::BindGroup,
        pass: &'a wgpu::BindGroup,
    ) -> [Option<&'a wgpu::BindGroup>; 4] {
        let [field, frame, uses_environment] = slots.used;
        [
            field.then_some(self.field.bind_group()),
            frame.then_some(self.frame.bind_group()),
            uses_environment.then_some(environment),
            Some(pass),
        ]
    }
}
