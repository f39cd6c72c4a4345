//! The scene's knobs: every value a user sets, with its allowed range, its unit and its description,
//! each written once. Validation and its messages, and any user interface (the viewer's panel), read
//! this registry.
//!
//! A [`Knob`] names a field by its dotted key path within a table type (the [`Scene`], one
//! [`CloudLayer`], ...). Its range and unit are written in the tables of this module; its
//! description is the field's doc comment in [`super::model`], read at run time.

mod tables;
mod values;

pub use tables::{
    CAMERA_KEY, COVERAGE_KEY, LAYER, SCENE, SPRITE_BOX, SPRITE_CLOUD, SUN_KEY, TIME_OF_DAY, VOLUME,
};
pub use values::{Choice, KnobValue};

/// Doc comments at run time: `Scene::get_field_docs("layers")` describes a section of the scene,
/// `Technique::Raymarch.get_variant_docs()` an option of a choice.
pub use documented::{DocumentedFields, DocumentedVariants};

#[cfg(doc)]
use super::model::{CloudLayer, Scene};

/// The values a knob allows; every allowed number is also finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Allowed {
    /// Any finite number.
    Finite,
    /// `min..=max`.
    Between(f32, f32),
    /// `>= min`.
    AtLeast(f32),
    /// `> min`.
    Above(f32),
    /// One of the listed names, or true or false: checked when the file is read.
    Listed,
}

impl Allowed {
    /// Whether the number `value` is allowed (never for [`Allowed::Listed`]).
    pub fn contains(self, value: f64) -> bool {
        match self {
            Allowed::Finite => true,
            Allowed::Between(min, max) => f64::from(min) <= value && value <= f64::from(max),
            Allowed::AtLeast(min) => f64::from(min) <= value,
            Allowed::Above(min) => f64::from(min) < value,
            Allowed::Listed => false,
        }
    }

    /// The lowest and highest allowed numbers, where there are bounds.
    pub fn bounds(self) -> (Option<f32>, Option<f32>) {
        match self {
            Allowed::Between(min, max) => (Some(min), Some(max)),
            Allowed::AtLeast(min) | Allowed::Above(min) => (Some(min), None),
            Allowed::Finite | Allowed::Listed => (None, None),
        }
    }

    /// The range in words, with its unit: `1..179 deg`, `>= 0`, `any finite number (m)`.
    pub fn describe(self, unit: &str) -> String {
        let range = match self {
            Allowed::Finite => "any finite number".to_string(),
            Allowed::Between(min, max) => format!("{min}..{max}"),
            Allowed::AtLeast(min) => format!(">= {min}"),
            Allowed::Above(min) => format!("> {min}"),
            Allowed::Listed => "one of the listed values".to_string(),
        };
        match (self, unit) {
            (_, "") => range,
            (Allowed::Finite, _) => format!("{range} ({unit})"),
            _ => format!("{range} {unit}"),
        }
    }
}

/// A knob's value as read from a table.
pub enum Field<'a> {
    /// A number.
    Float(f32),
    /// A whole number.
    Int(u32),
    /// An array of numbers; each element is checked, and named by its index.
    Floats(&'a [f32]),
    /// A switch.
    Bool(bool),
    /// One of a list of names.
    Choice(&'a dyn Choice),
    /// An optional value that is not set.
    Absent,
}

/// A knob's value, to change in place.
pub enum FieldMut<'a> {
    /// A number.
    Float(&'a mut f32),
    /// A whole number.
    Int(&'a mut u32),
    /// An array of numbers.
    Floats(&'a mut [f32]),
    /// A switch.
    Bool(&'a mut bool),
    /// One of a list of names.
    Choice(&'a mut dyn Choice),
    /// A whole number that may be left unset (to take a preset's value).
    OptionalInt(&'a mut Option<u32>),
    /// An optional value that is not set, and has no value to start from.
    Unset,
}

/// One value a user sets: where it is, what it allows, its unit and its description.
pub struct Knob<T: 'static> {
    /// Dotted key path relative to `T`, e.g. `camera.fov_y_deg` in a [`Scene`], `coverage` in a
    /// [`CloudLayer`].
    pub key: &'static str,
    /// The values allowed.
    pub allowed: Allowed,
    /// Unit for display and messages; empty for dimensionless values.
    pub unit: &'static str,
    read: fn(&T) -> Field<'_>,
    write: fn(&mut T) -> FieldMut<'_>,
    docs: fn() -> &'static str,
}

impl<T> Knob<T> {
    /// The value in `item`.
    pub fn get<'a>(&self, item: &'a T) -> Field<'a> {
        (self.read)(item)
    }

    /// The value in `item`, to change.
    pub fn get_mut<'a>(&self, item: &'a mut T) -> FieldMut<'a> {
        (self.write)(item)
    }

    /// What the value means: the doc comment of its field in [`super::model`].
    pub fn description(&self) -> &'static str {
        (self.docs)()
    }
}

/// The doc comment of `field` in the struct `P` that `parent` leads to (the function is never
/// called: it only names `P`).
pub(crate) fn docs_of<T, P: DocumentedFields>(_parent: fn(&T) -> &P, field: &str) -> &'static str {
    P::get_field_docs(field).unwrap_or_default()
}

/// One row of a knob table: `knob!(Scene, camera.fov_y_deg, Between(1.0, 179.0), "deg")` reads,
/// writes and describes `scene.camera.fov_y_deg`.
macro_rules! knob {
    ($t:ty, $first:ident $(. $rest:ident)*, $allowed:expr, $unit:expr) => {
        $crate::scene::knobs::Knob::new(
            concat!(stringify!($first) $(, ".", stringify!($rest))*),
            $allowed,
            $unit,
            |t: &$t| $crate::scene::knobs::KnobValue::field(&t.$first $(.$rest)*),
            |t: &mut $t| $crate::scene::knobs::KnobValue::field_mut(&mut t.$first $(.$rest)*),
            $crate::scene::knobs::docs_fn!($t; []; $first $(. $rest)*),
        )
    };
}

/// The description function of a knob: the doc comment of the path's last field, in the struct its
/// other fields lead to.
macro_rules! docs_fn {
    ($t:ty; [$($parent:ident)*]; $last:ident) => {
        || $crate::scene::knobs::docs_of(|t: &$t| &(*t) $(.$parent)*, stringify!($last))
    };
    ($t:ty; [$($parent:ident)*]; $next:ident . $($rest:ident).+) => {
        $crate::scene::knobs::docs_fn!($t; [$($parent)* $next]; $($rest).+)
    };
}

pub(crate) use {docs_fn, knob};

impl<T> Knob<T> {
    /// A knob; use [`knob!`], which writes every argument from one key path.
    pub(crate) const fn new(
        key: &'static str,
        allowed: Allowed,
        unit: &'static str,
        read: fn(&T) -> Field<'_>,
        write: fn(&mut T) -> FieldMut<'_>,
        docs: fn() -> &'static str,
    ) -> Knob<T> {
        Knob {
            key,
            allowed,
            unit,
            read,
            write,
            docs,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::model::Scene;

    /// The key and description of every knob of every table.
    fn every_description() -> Vec<(&'static str, &'static str)> {
        fn of<T>(knobs: &[Knob<T>]) -> Vec<(&'static str, &'static str)> {
            knobs.iter().map(|k| (k.key, k.description())).collect()
        }
        [
            of(SCENE),
            of(LAYER),
            of(TIME_OF_DAY),
            of(VOLUME),
            of(SPRITE_CLOUD),
            of(SPRITE_BOX),
            of(CAMERA_KEY),
            of(SUN_KEY),
            of(COVERAGE_KEY),
        ]
        .concat()
    }

    #[test]
    fn every_knob_is_described_by_its_doc_comment() {
        for (key, description) in every_description() {
            assert!(!description.trim().is_empty(), "{key} has no description");
        }
        let coverage = LAYER.iter().find(|k| k.key == "coverage").unwrap();
        assert!(coverage.description().starts_with("Cloud cover, 0..1"));
        let fov = SCENE.iter().find(|k| k.key == "camera.fov_y_deg").unwrap();
        assert_eq!(
            fov.description(),
            "Vertical field of view in degrees, 1..179."
        );
    }

    #[test]
    fn a_knob_reads_and_writes_its_own_field() {
        let mut scene = Scene::default();
        let exposure = SCENE
            .iter()
            .find(|k| k.key == "render.exposure_ev")
            .unwrap();
        match exposure.get_mut(&mut scene) {
            FieldMut::Float(value) => *value = 1.5,
            _ => panic!("exposure is a number"),
        }
        assert_eq!(scene.render.exposure_ev, 1.5);
        assert!(matches!(exposure.get(&scene), Field::Float(v) if v == 1.5));
        let technique = SCENE.iter().find(|k| k.key == "render.technique").unwrap();
        match technique.get_mut(&mut scene) {
            FieldMut::Choice(choice) => choice.select(1),
            _ => panic!("the technique is a choice"),
        }
        assert_eq!(scene.render.technique.name(), "particles");
    }

    #[test]
    fn ranges_are_described_with_their_units() {
        assert_eq!(Allowed::Between(1.0, 179.0).describe("deg"), "1..179 deg");
        assert_eq!(Allowed::AtLeast(0.0).describe(""), ">= 0");
        assert_eq!(Allowed::Finite.describe("m"), "any finite number (m)");
        assert_eq!(Allowed::Above(0.0).bounds(), (Some(0.0), None));
        assert!(!Allowed::Above(0.0).contains(0.0));
    }
}
