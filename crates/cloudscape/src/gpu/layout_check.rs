//! Test support: a Rust struct shared with WGSL has the size and member offsets that naga gives the
//! WGSL struct of the same name, so moving, adding or retyping a field on one side fails a test.

/// Asserts that the WGSL struct `wgsl_name` of the program of `root` ([`crate::shader::Program`])
/// has size `size` and exactly the members `fields` (name, byte offset), in order.
pub fn assert_layout(
    root: &'static crate::shader::WgslModule,
    wgsl_name: &str,
    size: usize,
    fields: &[(&str, usize)],
) {
    let (module, _) = crate::shader::Program::new(root)
        .validate()
        .unwrap_or_else(|e| panic!("{e}"));
    let (_, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(wgsl_name))
        .unwrap_or_else(|| panic!("{} has no struct {wgsl_name}", root.name));
    let naga::TypeInner::Struct { members, span } = &ty.inner else {
        panic!("{wgsl_name} is not a struct");
    };
    let wgsl: Vec<(String, usize)> = members
        .iter()
        .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
        .collect();
    let rust: Vec<(String, usize)> = fields.iter().map(|(n, o)| (n.to_string(), *o)).collect();
    assert_eq!(rust, wgsl, "{wgsl_name}: Rust (name, offset) vs WGSL");
    assert_eq!(size, *span as usize, "{wgsl_name}: Rust size vs WGSL size");
}

/// `assert_wgsl_layout!(root, "WgslName", RustType { field, ... })`: [`assert_layout`] with the
/// Rust type's size and the offsets of the fields named, which must be all of them.
macro_rules! assert_wgsl_layout {
    ($root:expr, $wgsl:expr, $ty:ty { $($field:ident),* $(,)? }) => {
        $crate::gpu::layout_check::assert_layout(
            $root,
            $wgsl,
            size_of::<$ty>(),
            &[$((stringify!($field), std::mem::offset_of!($ty, $field))),*],
        )
    };
}
pub(crate) use assert_wgsl_layout;
