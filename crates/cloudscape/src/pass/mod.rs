//! One way to build a pass: a program, its entry points, and its own resources by name.
//!
//! A pass is declared once ([`ComputePass::new`], [`RasterPass::new`]): its root WGSL module
//! ([`crate::shader::WgslModule`]) and entry points. The shared groups it uses ([`SharedSlots`])
//! follow from the modules the program reaches, and the layout of its own group
//! ([`crate::shader::PASS_GROUP`]) from naga's reflection of the program ([`reflect`]): binding
//! types, texture dimensions, whether a texture is sampled (filterable) or only loaded, storage
//! access and formats, and the stages that use each binding. Rust binds the pass's resources by
//! their WGSL names ([`PassGroup::bind`]), and a name that one side has and the other lacks is an
//! error that lists both. One [`BindGroupCache`] type keeps the bind groups of every pass.
//!
//! In the spirit of kajiya's render graph (passes that state what they read and write) and Bevy's
//! atmosphere (each pass's layout beside its shader), with the layout read from the WGSL itself so
//! that it is written once.

mod cache;
mod reflect;
mod shared;

pub use cache::BindGroupCache;
pub use reflect::{PassBinding, reflect};
pub use shared::{Shared, SharedGroup, SharedSlots};

use crate::gpu::GpuContext;
use crate::gpu::pipeline::{RasterDescriptor, compute_pipeline, render_pipeline};
use crate::shader::{Program, WgslModule};

/// A pass's own bind group layout ([`crate::shader::PASS_GROUP`]), reflected from its program,
/// and the names of its bindings.
pub struct PassGroup {
    label: &'static str,
    layout: wgpu::BindGroupLayout,
    bindings: Vec<PassBinding>,
}

impl PassGroup {
    /// The layout of `program`'s own group, as its entry points `entries` use it.
    pub fn new(ctx: &GpuContext, label: &'static str, program: &Program, entries: &[&str]) -> Self {
        let bindings = reflect(program, entries);
        let layout_entries: Vec<_> = bindings.iter().map(|b| b.entry).collect();
        let layout = ctx
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries: &layout_entries,
            });
        PassGroup {
            label,
            layout,
            bindings,
        }
    }

    /// A bind group holding `resources`, each named as its WGSL global.
    ///
    /// # Panics
    /// When the names differ from the program's (one missing, one unknown): Rust and WGSL disagree.
    pub fn bind(
        &self,
        ctx: &GpuContext,
        resources: &[(&str, wgpu::BindingResource)],
    ) -> wgpu::BindGroup {
        let missing: Vec<&str> = self
            .bindings
            .iter()
            .filter(|b| !resources.iter().any(|(name, _)| *name == b.name))
            .map(|b| b.name.as_str())
            .collect();
        let unknown: Vec<&str> = resources
            .iter()
            .filter(|(name, _)| !self.bindings.iter().any(|b| b.name == *name))
            .map(|(name, _)| *name)
            .collect();
        assert!(
            missing.is_empty() && unknown.is_empty(),
            "pass {:?}: Rust and WGSL disagree on its group's bindings: WGSL declares {:?}; \
             not bound by Rust: {missing:?}; not declared in WGSL: {unknown:?}",
            self.label,
            self.bindings.iter().map(|b| &b.name).collect::<Vec<_>>(),
        );
        let entries: Vec<_> = self
            .bindings
            .iter()
            .map(|b| wgpu::BindGroupEntry {
                binding: b.entry.binding,
                resource: resources
                    .iter()
                    .find(|(name, _)| *name == b.name)
                    .map(|(_, r)| r.clone())
                    .expect("checked above"),
            })
            .collect();
        ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(self.label),
            layout: &self.layout,
            entries: &entries,
        })
    }

    /// The names of the group's bindings, by binding number.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.bindings.iter().map(|b| b.name.as_str())
    }

    /// The pipeline layouts of a pass: the shared groups `slots` names, then this group.
    ///
    /// # Panics
    /// When the program uses shared groups and `shared` is None.
    fn layouts<'a>(
        &'a self,
        shared: Option<&Shared<'a>>,
        slots: SharedSlots,
    ) -> [Option<&'a wgpu::BindGroupLayout>; 4] {
        match shared {
            Some(shared) => shared.layouts(slots, &self.layout),
            None => {
                assert!(
                    slots == SharedSlots::NONE,
                    "pass {:?} uses shared groups: build it with them",
                    self.label
                );
                [None, None, None, Some(&self.layout)]
            }
        }
    }
}

/// A compute pass: one pipeline per entry point of one program, its own group reflected.
pub struct ComputePass {
    /// The pass's own group.
    pub group: PassGroup,
    /// The shared groups the program uses.
    pub slots: SharedSlots,
    pipelines: Vec<(&'static str, wgpu::ComputePipeline)>,
}

impl ComputePass {
    /// The pass `label` running the entry points `entries` of program `root`.
    pub fn new(
        ctx: &GpuContext,
        shared: &Shared,
        label: &'static str,
        root: &'static WgslModule,
        entries: &[&'static str],
    ) -> ComputePass {
        ComputePass::build(ctx, Some(shared), label, root, entries)
    }

    /// [`ComputePass::new`] for a program that uses no shared group (a bake, the display).
    pub fn standalone(
        ctx: &GpuContext,
        label: &'static str,
        root: &'static WgslModule,
        entries: &[&'static str],
    ) -> ComputePass {
        ComputePass::build(ctx, None, label, root, entries)
    }

    fn build(
        ctx: &GpuContext,
        shared: Option<&Shared>,
        label: &'static str,
        root: &'static WgslModule,
        entries: &[&'static str],
    ) -> ComputePass {
        let program = Program::new(root);
        let group = PassGroup::new(ctx, label, &program, entries);
        let slots = SharedSlots::of(&program);
        let layouts = group.layouts(shared, slots);
        let pipelines = entries
            .iter()
            .map(|entry| {
                let pipeline = compute_pipeline(ctx, entry, program.text(), entry, &layouts);
                (*entry, pipeline)
            })
            .collect();
        ComputePass {
            group,
            slots,
            pipelines,
        }
    }

    /// The pipeline of entry point `entry`.
    ///
    /// # Panics
    /// When the pass was not built with `entry`.
    pub fn pipeline(&self, entry: &str) -> &wgpu::ComputePipeline {
        self.pipelines
            .iter()
            .find(|(e, _)| *e == entry)
            .map(|(_, p)| p)
            .unwrap_or_else(|| panic!("pass {:?} has no entry {entry:?}", self.group.label))
    }

    /// The pipeline of the pass's only (or first) entry point.
    pub fn main(&self) -> &wgpu::ComputePipeline {
        &self.pipelines[0].1
    }
}

/// A raster pass: one render pipeline from one program, its own group reflected.
pub struct RasterPass {
    /// The pass's own group.
    pub group: PassGroup,
    /// The shared groups the program uses.
    pub slots: SharedSlots,
    /// The render pipeline.
    pub pipeline: wgpu::RenderPipeline,
}

impl RasterPass {
    /// The pass of `raster` (label, entry points, targets, depth) over program `root`.
    pub fn new(
        ctx: &GpuContext,
        shared: &Shared,
        root: &'static WgslModule,
        raster: &RasterDescriptor,
    ) -> RasterPass {
        let program = Program::new(root);
        let (vertex, fragment) = raster.entries;
        let label: &'static str = root.name;
        let group = PassGroup::new(ctx, label, &program, &[vertex, fragment]);
        let slots = SharedSlots::of(&program);
        let layouts = group.layouts(Some(shared), slots);
        let pipeline = render_pipeline(ctx, raster, program.text(), &layouts);
        RasterPass {
            group,
            slots,
            pipeline,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    static PROBED: WgslModule = WgslModule {
        name: "probed",
        declared_in: file!(),
        file: "(test)",
        source: "
            @group(3) @binding(0) var<storage, read_write> values: array<f32>;
            @compute @workgroup_size(1)
            fn main(@builtin(global_invocation_id) id: vec3<u32>) {
                values[id.x] = 1.0;
            }
        ",
        imports: &[],
        constants: None,
    };

    #[test]
    #[should_panic(expected = "not bound by Rust: [\"values\"]; not declared in WGSL: [\"value\"]")]
    fn a_resource_named_unlike_its_wgsl_global_is_refused() {
        let ctx = GpuContext::for_tests();
        let pass = ComputePass::standalone(&ctx, "probed", &PROBED, &["main"]);
        let buffer = crate::gpu::pipeline::storage_buffer(&ctx, "values", 16);
        pass.group
            .bind(&ctx, &[("value", buffer.as_entire_binding())]);
    }
}
