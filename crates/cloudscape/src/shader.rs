//! WGSL programs assembled from modules that own what they use.
//!
//! Each `.wgsl` file of the crate is a [`WgslModule`], declared as a `static` by the Rust module
//! that owns it, beside its Rust twin ([`wgsl_module!`]). A module names the modules it uses (its
//! imports, Rust references to their statics, so the import graph follows the crate's own module
//! graph) and the WGSL `const`s generated from the Rust values it shares (so a value shared by both
//! sides is written once, by its owner). [`Program::new`] starts from a root module (one with an
//! entry point), puts every module it reaches once, each after its constants and everything it
//! imports, and keeps a map from the program's lines back to each module's file and line, so an
//! error names `raymarch/raymarch.wgsl:120`, not a line of the assembled text. An import cycle is
//! an error that names the cycle.
//!
//! A registry of our own rather than naga_oil (or WESL): the modules prefix their names (`field_`,
//! `frame_`, `march_`), so no name mangling is needed; the programs stay plain WGSL that every
//! wgpu backend (GL included) translates like any other and that [`crate::pass`] reflects with
//! naga; and naga_oil's composer would hold its own copy of naga in step with wgpu's.
//!
//! A module binds resources only in its own group: the field at [`FIELD_GROUP`], the frame at
//! [`FRAME_GROUP`], the environment at [`ENVIRONMENT_GROUP`]; a program's root module alone binds
//! at [`PASS_GROUP`] (checked by the shader tests).

use std::fmt::{self, Write};
use std::path::Path;

/// One WGSL module: a `.wgsl` file, the modules it imports and the constants it owns.
#[derive(Debug)]
pub struct WgslModule {
    /// The module's name (its functions' prefix by convention).
    pub name: &'static str,
    /// The Rust file that declares the module (`file!()`): the `.wgsl` file sits beside it.
    pub declared_in: &'static str,
    /// The `.wgsl` file's name.
    pub file: &'static str,
    /// The WGSL text.
    pub source: &'static str,
    /// The modules this one uses, each put before it in a program.
    pub imports: &'static [&'static WgslModule],
    /// WGSL `const` declarations generated from the Rust values they mirror, put before the
    /// module's own text; None when it owns none.
    pub constants: Option<fn() -> String>,
}

/// Declares a [`WgslModule`] for the `.wgsl` file beside the calling Rust file:
/// `wgsl_module!("raymarch", "raymarch.wgsl", [&FIELD_WGSL, &FRAME_WGSL], constants_fn)`.
macro_rules! wgsl_module {
    ($name:literal, $file:literal, [$($import:expr),* $(,)?] $(, $constants:expr)?) => {
        $crate::shader::WgslModule {
            name: $name,
            declared_in: file!(),
            file: $file,
            source: include_str!($file),
            imports: &[$($import),*],
            constants: $crate::shader::wgsl_module!(@constants $($constants)?),
        }
    };
    (@constants) => { None };
    (@constants $constants:expr) => { Some($constants) };
}
pub(crate) use wgsl_module;

impl WgslModule {
    /// The bind groups the module declares bindings in (`@group(N)`), ascending, each once.
    pub fn groups(&self) -> Vec<u32> {
        let mut groups: Vec<u32> = self
            .source
            .split("@group(")
            .skip(1)
            .filter_map(|rest| rest.split(')').next()?.trim().parse().ok())
            .collect();
        groups.sort_unstable();
        groups.dedup();
        groups
    }

    /// The `.wgsl` file's path from the workspace root.
    pub fn path(&self) -> String {
        Path::new(self.declared_in)
            .with_file_name(self.file)
            .display()
            .to_string()
    }
}

/// The constants every module may use; imported like any other module.
pub static MATH_WGSL: WgslModule = WgslModule {
    name: "math",
    declared_in: file!(),
    file: "(generated)",
    source: "",
    imports: &[],
    constants: Some(math_constants),
};

fn math_constants() -> String {
    wgsl_consts([("PI", WgslConst::F32(std::f32::consts::PI))])
}

/// A Rust value written as a WGSL `const`.
#[derive(Clone, Copy, Debug)]
pub enum WgslConst {
    /// `f32`.
    F32(f32),
    /// `u32` (from any unsigned count).
    U32(u32),
    /// `vec2<u32>`.
    UVec2((u32, u32)),
    /// `array<vec4<f32>, N>`.
    Vec4Array(&'static [[f32; 4]]),
}

/// WGSL `const` declarations, one per `(name, value)`.
pub fn wgsl_consts<N: AsRef<str>>(values: impl IntoIterator<Item = (N, WgslConst)>) -> String {
    let mut text = String::new();
    for (name, value) in values {
        let name = name.as_ref();
        let value = match value {
            WgslConst::F32(v) => format!("f32({v:?})"),
            WgslConst::U32(v) => format!("{v}u"),
            WgslConst::UVec2((x, y)) => format!("vec2<u32>({x}u, {y}u)"),
            WgslConst::Vec4Array(rows) => {
                let rows: Vec<String> = rows
                    .iter()
                    .map(|[x, y, z, w]| format!("vec4<f32>({x:?}, {y:?}, {z:?}, {w:?})"))
                    .collect();
                format!("array<vec4<f32>, {}>({})", rows.len(), rows.join(", "))
            }
        };
        writeln!(text, "const {name} = {value};").expect("writing to a String");
    }
    text
}

/// Bind group slots shared by every program: the field, the frame, the environment; each pass
/// binds its own resources at [`PASS_GROUP`].
pub const FIELD_GROUP: u32 = 0;
/// Slot of the frame's bind group (`frame.wgsl`).
pub const FRAME_GROUP: u32 = 1;
/// Slot of the environment's bind group (`environment.wgsl`).
pub const ENVIRONMENT_GROUP: u32 = 2;
/// Slot of a pass's own bind group.
pub const PASS_GROUP: u32 = 3;

/// An assembled WGSL program and where each of its lines came from.
#[derive(Debug)]
pub struct Program {
    text: String,
    modules: Vec<&'static WgslModule>,
    /// (first line of the part, 1-based; the module; whether the part is its generated constants).
    parts: Vec<(usize, &'static WgslModule, bool)>,
    /// The host's own source (after the modules), by its first line.
    host_from_line: Option<usize>,
}

/// A WGSL program that cannot be assembled or does not validate, located in its module's file.
#[derive(Debug)]
pub struct ShaderError(String);

impl fmt::Display for ShaderError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ShaderError {}

impl Program {
    /// The program of root module `root`: every module it reaches, each after its imports.
    ///
    /// # Panics
    /// On an import cycle ([`Program::try_new`] returns it).
    pub fn new(root: &'static WgslModule) -> Program {
        Program::try_new(root).unwrap_or_else(|e| panic!("{e}"))
    }

    /// [`Program::new`], with an import cycle as an error naming it.
    pub fn try_new(root: &'static WgslModule) -> Result<Program, ShaderError> {
        let mut program = Program::empty();
        program.visit(root, &mut Vec::new())?;
        Ok(program)
    }

    /// A host's own WGSL `source` after the modules `imports` names (and theirs): how a game
    /// engine's shader reaches the environment's functions, e.g. with
    /// [`crate::environment::ENVIRONMENT_WGSL`], `environment_cloud_sun_transmittance(p)` for the
    /// clouds' shadow on its geometry. The host binds the environment's group at
    /// [`ENVIRONMENT_GROUP`] and keeps its own resources at other slots.
    pub fn host(imports: &[&'static WgslModule], source: &str) -> Program {
        let mut program = Program::empty();
        for module in imports {
            program
                .visit(module, &mut Vec::new())
                .unwrap_or_else(|e| panic!("{e}"));
        }
        program.host_from_line = Some(program.line_count() + 1);
        program.text.push_str(source);
        program
    }

    fn empty() -> Program {
        Program {
            text: String::new(),
            modules: Vec::new(),
            parts: Vec::new(),
            host_from_line: None,
        }
    }

    /// The assembled WGSL text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The modules the program holds, each after its imports.
    pub fn modules(&self) -> &[&'static WgslModule] {
        &self.modules
    }

    /// The bind groups the program's modules declare bindings in, ascending, each once.
    pub fn groups(&self) -> Vec<u32> {
        let mut groups: Vec<u32> = self.modules.iter().flat_map(|m| m.groups()).collect();
        groups.sort_unstable();
        groups.dedup();
        groups
    }

    /// Whether the program holds `module`.
    pub fn reaches(&self, module: &WgslModule) -> bool {
        self.modules.iter().any(|m| std::ptr::eq(*m, module))
    }

    /// The file and line of line `line` (1-based) of the program, e.g.
    /// `crates/cloudscape/src/raymarch/raymarch.wgsl:120`.
    pub fn locate(&self, line: usize) -> String {
        if let Some(first) = self.host_from_line.filter(|first| line >= *first) {
            return format!("host source:{}", line + 1 - first);
        }
        match self.parts.iter().rev().find(|(first, ..)| *first <= line) {
            Some((first, module, true)) => format!(
                "constants of WGSL module {:?} (generated from Rust), line {}",
                module.name,
                line + 1 - first
            ),
            Some((first, module, false)) => format!("{}:{}", module.path(), line + 1 - first),
            None => format!("line {line}"),
        }
    }

    /// Parses and validates the program with naga, every error located in its module's file.
    pub fn validate(&self) -> Result<(naga::Module, naga::valid::ModuleInfo), ShaderError> {
        let module = naga::front::wgsl::parse_str(&self.text)
            .map_err(|e| self.error(e.location(&self.text), &e.emit_to_string(&self.text)))?;
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        )
        .validate(&module)
        .map_err(|e| self.error(e.location(&self.text), &e.emit_to_string(&self.text)))?;
        Ok((module, info))
    }

    fn error(&self, at: Option<naga::SourceLocation>, message: &str) -> ShaderError {
        let at = at.map_or_else(
            || "WGSL".to_string(),
            |l| {
                format!(
                    "{}:{}",
                    self.locate(l.line_number as usize),
                    l.line_position
                )
            },
        );
        ShaderError(format!("{at}: {message}"))
    }

    fn line_count(&self) -> usize {
        self.text.lines().count()
    }

    /// Depth-first: `module`'s imports, then its constants and text, each module once; `path` is
    /// the chain of modules being visited, for the cycle's error.
    fn visit(
        &mut self,
        module: &'static WgslModule,
        path: &mut Vec<&'static str>,
    ) -> Result<(), ShaderError> {
        if path.contains(&module.name) {
            path.push(module.name);
            return Err(ShaderError(format!(
                "WGSL import cycle: {} (declared in {})",
                path.join(" -> "),
                module.declared_in
            )));
        }
        if self.reaches(module) {
            return Ok(());
        }
        path.push(module.name);
        for import in module.imports {
            self.visit(import, path)?;
        }
        path.pop();
        if let Some(constants) = module.constants {
            self.push(module, true, &constants());
        }
        self.push(module, false, module.source);
        self.modules.push(module);
        Ok(())
    }

    fn push(&mut self, module: &'static WgslModule, constants: bool, text: &str) {
        self.parts.push((self.line_count() + 1, module, constants));
        for line in text.lines() {
            self.text.push_str(line);
            self.text.push('\n');
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    static A: WgslModule = WgslModule {
        name: "a",
        declared_in: file!(),
        file: "a.wgsl",
        source: "fn a_one() -> f32 { return b_two(); }",
        imports: &[&B],
        constants: None,
    };
    static B: WgslModule = WgslModule {
        name: "b",
        declared_in: file!(),
        file: "b.wgsl",
        source: "fn b_two() -> f32 { return a_one(); }",
        imports: &[&A],
        constants: None,
    };
    static BROKEN: WgslModule = WgslModule {
        name: "broken",
        declared_in: "crates/cloudscape/src/x/mod.rs",
        file: "broken.wgsl",
        source: "fn broken_ok() -> f32 { return PI; }\nfn broken() -> f32 { return nope; }\n",
        imports: &[&MATH_WGSL],
        constants: None,
    };

    #[test]
    fn an_import_cycle_is_named() {
        let error = Program::try_new(&A).expect_err("a imports b imports a");
        assert!(error.to_string().contains("a -> b -> a"), "{error}");
    }

    #[test]
    fn an_error_points_at_the_module_file_and_line() {
        let error = Program::new(&BROKEN)
            .validate()
            .expect_err("nope is undefined");
        assert!(
            error
                .to_string()
                .starts_with("crates/cloudscape/src/x/broken.wgsl:2:"),
            "{error}"
        );
    }

    #[test]
    fn a_module_follows_its_constants_and_imports() {
        let program = Program::new(&BROKEN);
        let text = program.text();
        assert!(text.find("const PI").unwrap() < text.find("fn broken_ok").unwrap());
        assert!(program.reaches(&MATH_WGSL));
        assert!(
            program
                .locate(1)
                .contains("constants of WGSL module \"math\"")
        );
    }

    #[test]
    fn generated_constants_are_wgsl() {
        let text = wgsl_consts([
            ("X", WgslConst::F32(0.5)),
            ("N", WgslConst::U32(3)),
            ("S", WgslConst::UVec2((2, 4))),
        ]);
        assert_eq!(
            text,
            "const X = f32(0.5);\nconst N = 3u;\nconst S = vec2<u32>(2u, 4u);\n"
        );
    }
}
