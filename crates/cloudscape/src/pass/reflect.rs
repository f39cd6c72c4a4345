//! The layout of a pass's own group, read from its WGSL program with naga.

use crate::shader::{PASS_GROUP, Program};
use naga::valid::{GlobalUse, ModuleInfo};
use naga::{AddressSpace, ImageClass, ImageDimension, ScalarKind, TypeInner};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// A validated program: naga's module and its analysis.
type Parsed = Arc<(naga::Module, ModuleInfo)>;

/// One binding of a pass's own group: its WGSL name and its layout entry.
#[derive(Clone, Debug)]
pub struct PassBinding {
    /// The WGSL global's name.
    pub name: String,
    /// The layout entry naga's reflection gives it.
    pub entry: wgpu::BindGroupLayoutEntry,
}

/// The bindings of `program`'s own group ([`PASS_GROUP`]) that its entry points `entries` use, by
/// binding number. A texture sampled through a sampler is filterable, one only loaded is not; a
/// sampler is filtering unless it compares; a binding is visible to the stages that use it.
/// Reflections are kept per program text, so building a pass twice parses it once.
///
/// # Panics
/// When the program does not validate (the error names the module's file and line) or lacks an
/// entry point of `entries`.
pub fn reflect(program: &Program, entries: &[&str]) -> Vec<PassBinding> {
    static KEPT: Mutex<Vec<(String, Parsed)>> = Mutex::new(Vec::new());
    let parsed = {
        let mut kept = KEPT.lock().expect("no panic while reflecting");
        match kept.iter().find(|(text, _)| text == program.text()) {
            Some((_, parsed)) => parsed.clone(),
            None => {
                let parsed = Arc::new(program.validate().unwrap_or_else(|e| panic!("{e}")));
                kept.push((program.text().to_string(), parsed.clone()));
                parsed
            }
        }
    };
    let (module, info) = &*parsed;
    let uses = entry_uses(module, info, entries);
    let mut bindings: Vec<PassBinding> = module
        .global_variables
        .iter()
        .filter_map(|(handle, var)| {
            let binding = var.binding.as_ref().filter(|b| b.group == PASS_GROUP)?;
            let stages = uses.stages.get(&handle).copied()?;
            Some(PassBinding {
                name: var.name.clone().unwrap_or_default(),
                entry: wgpu::BindGroupLayoutEntry {
                    binding: binding.binding,
                    visibility: stages,
                    ty: binding_type(module, var, uses.sampled.contains(&handle)),
                    count: None,
                },
            })
        })
        .collect();
    bindings.sort_by_key(|b| b.entry.binding);
    bindings
}

/// Which globals the entry points use, in which stages, and which are sampled.
struct EntryUses {
    stages: HashMap<naga::Handle<naga::GlobalVariable>, wgpu::ShaderStages>,
    sampled: Vec<naga::Handle<naga::GlobalVariable>>,
}

fn entry_uses(module: &naga::Module, info: &ModuleInfo, entries: &[&str]) -> EntryUses {
    let mut uses = EntryUses {
        stages: HashMap::new(),
        sampled: Vec::new(),
    };
    for name in entries {
        let (index, entry) = module
            .entry_points
            .iter()
            .enumerate()
            .find(|(_, e)| e.name == *name)
            .unwrap_or_else(|| panic!("the program has no entry point {name:?}"));
        let function = info.get_entry_point(index);
        let stage = match entry.stage {
            naga::ShaderStage::Vertex => wgpu::ShaderStages::VERTEX,
            naga::ShaderStage::Fragment => wgpu::ShaderStages::FRAGMENT,
            _ => wgpu::ShaderStages::COMPUTE,
        };
        for (handle, _) in module.global_variables.iter() {
            if function[handle] != GlobalUse::empty() {
                *uses
                    .stages
                    .entry(handle)
                    .or_insert(wgpu::ShaderStages::NONE) |= stage;
            }
        }
        for key in &function.sampling_set {
            uses.sampled.extend([key.image, key.sampler]);
        }
    }
    uses
}

/// The layout type of global `var`; `sampled`: whether a sampler reads it.
fn binding_type(
    module: &naga::Module,
    var: &naga::GlobalVariable,
    sampled: bool,
) -> wgpu::BindingType {
    let buffer = |ty| wgpu::BindingType::Buffer {
        ty,
        has_dynamic_offset: false,
        min_binding_size: None,
    };
    match (&var.space, &module.types[var.ty].inner) {
        (AddressSpace::Uniform, _) => buffer(wgpu::BufferBindingType::Uniform),
        (AddressSpace::Storage { access }, _) => buffer(wgpu::BufferBindingType::Storage {
            read_only: !access.contains(naga::StorageAccess::STORE),
        }),
        (_, TypeInner::Sampler { comparison: true }) => {
            wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison)
        }
        (_, TypeInner::Sampler { comparison: false }) => wgpu::BindingType::Sampler(if sampled {
            wgpu::SamplerBindingType::Filtering
        } else {
            wgpu::SamplerBindingType::NonFiltering
        }),
        (
            _,
            TypeInner::Image {
                dim,
                arrayed,
                class,
            },
        ) => image_type(*dim, *arrayed, class, sampled),
        (space, ty) => panic!("a pass binding of space {space:?} and type {ty:?} is not supported"),
    }
}

fn image_type(
    dim: ImageDimension,
    arrayed: bool,
    class: &ImageClass,
    sampled: bool,
) -> wgpu::BindingType {
    let view_dimension = match (dim, arrayed) {
        (ImageDimension::D1, _) => wgpu::TextureViewDimension::D1,
        (ImageDimension::D2, false) => wgpu::TextureViewDimension::D2,
        (ImageDimension::D2, true) => wgpu::TextureViewDimension::D2Array,
        (ImageDimension::D3, _) => wgpu::TextureViewDimension::D3,
        (ImageDimension::Cube, false) => wgpu::TextureViewDimension::Cube,
        (ImageDimension::Cube, true) => wgpu::TextureViewDimension::CubeArray,
    };
    match class {
        ImageClass::Sampled { kind, multi } => wgpu::BindingType::Texture {
            sample_type: match kind {
                ScalarKind::Sint => wgpu::TextureSampleType::Sint,
                ScalarKind::Uint => wgpu::TextureSampleType::Uint,
                _ => wgpu::TextureSampleType::Float {
                    filterable: sampled,
                },
            },
            view_dimension,
            multisampled: *multi,
        },
        ImageClass::Depth { multi } => wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Depth,
            view_dimension,
            multisampled: *multi,
        },
        ImageClass::Storage { format, access } => wgpu::BindingType::StorageTexture {
            access: if access.contains(naga::StorageAccess::LOAD) {
                wgpu::StorageTextureAccess::ReadWrite
            } else {
                wgpu::StorageTextureAccess::WriteOnly
            },
            format: storage_format(*format),
            view_dimension,
        },
        ImageClass::External => panic!("external textures are not supported in a pass group"),
    }
}

/// The wgpu format of a WGSL storage texture format.
fn storage_format(format: naga::StorageFormat) -> wgpu::TextureFormat {
    use naga::StorageFormat as S;
    use wgpu::TextureFormat as T;
    match format {
        S::Rgba16Float => T::Rgba16Float,
        S::Rgba32Float => T::Rgba32Float,
        S::R32Float => T::R32Float,
        S::Rg32Float => T::Rg32Float,
        S::Rgba8Unorm => T::Rgba8Unorm,
        S::R32Uint => T::R32Uint,
        S::Rgba32Uint => T::Rgba32Uint,
        S::R16Float => T::R16Float,
        S::Rg16Float => T::Rg16Float,
        other => panic!("storage format {other:?} is not supported in a pass group"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shader::WgslModule;

    static REFLECTED: WgslModule = WgslModule {
        name: "reflected",
        declared_in: file!(),
        file: "(test)",
        source: "
            @group(3) @binding(0) var<uniform> settings: vec4<f32>;
            @group(3) @binding(1) var<storage, read> inputs: array<f32>;
            @group(3) @binding(2) var<storage, read_write> outputs: array<f32>;
            @group(3) @binding(3) var loaded: texture_2d<f32>;
            @group(3) @binding(4) var sampled: texture_3d<f32>;
            @group(3) @binding(5) var linear: sampler;
            @group(3) @binding(6) var written: texture_storage_2d<r32float, write>;
            @group(3) @binding(7) var<storage, read> unused_here: array<f32>;
            @compute @workgroup_size(1)
            fn main(@builtin(global_invocation_id) id: vec3<u32>) {
                let s = textureSampleLevel(sampled, linear, vec3<f32>(0.5), 0.0).x;
                let l = textureLoad(loaded, vec2<i32>(0), 0).x;
                outputs[id.x] = inputs[id.x] * settings.x + s + l;
                textureStore(written, vec2<i32>(id.xy), vec4<f32>(s));
            }
        ",
        imports: &[],
        constants: None,
    };

    #[test]
    fn a_pass_layout_follows_its_wgsl() {
        use wgpu::BindingType as B;
        let bindings = reflect(&Program::new(&REFLECTED), &["main"]);
        let names: Vec<&str> = bindings.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "settings", "inputs", "outputs", "loaded", "sampled", "linear", "written"
            ],
            "bindings the entry point does not use are left out"
        );
        let ty = |i: usize| bindings[i].entry.ty;
        assert!(matches!(
            ty(0),
            B::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                ..
            }
        ));
        let storage = |read_only| wgpu::BufferBindingType::Storage { read_only };
        assert!(matches!(ty(1), B::Buffer { ty, .. } if ty == storage(true)));
        assert!(matches!(ty(2), B::Buffer { ty, .. } if ty == storage(false)));
        let float = |filterable| wgpu::TextureSampleType::Float { filterable };
        assert!(matches!(ty(3), B::Texture { sample_type, .. } if sample_type == float(false)));
        assert!(matches!(
            ty(4),
            B::Texture { sample_type, view_dimension: wgpu::TextureViewDimension::D3, .. }
                if sample_type == float(true)
        ));
        assert_eq!(ty(5), B::Sampler(wgpu::SamplerBindingType::Filtering));
        assert!(matches!(
            ty(6),
            B::StorageTexture {
                format: wgpu::TextureFormat::R32Float,
                ..
            }
        ));
        assert!(
            bindings
                .iter()
                .all(|b| b.entry.visibility == wgpu::ShaderStages::COMPUTE)
        );
    }
}
