//! The types a knob can hold, each seen as a [`Field`] to read and a [`FieldMut`] to change.

use documented::DocumentedVariants;
use serde::Serialize;

use super::{Field, FieldMut};
use crate::scene::model::{
    LightingModel, ParticleBlending, ParticleOcclusion, ParticleStyle, PhaseModel, PlanetShape,
    Quality, SkyModel, SpriteLod, TableResolution, Technique, Tonemap, WeatherSource,
};

/// A type a knob can hold.
pub trait KnobValue {
    /// The value, to read.
    fn field(&self) -> Field<'_>;
    /// The value, to change.
    fn field_mut(&mut self) -> FieldMut<'_>;
}

impl KnobValue for f32 {
    fn field(&self) -> Field<'_> {
        Field::Float(*self)
    }
    fn field_mut(&mut self) -> FieldMut<'_> {
        FieldMut::Float(self)
    }
}

impl KnobValue for u32 {
    fn field(&self) -> Field<'_> {
        Field::Int(*self)
    }
    fn field_mut(&mut self) -> FieldMut<'_> {
        FieldMut::Int(self)
    }
}

impl KnobValue for bool {
    fn field(&self) -> Field<'_> {
        Field::Bool(*self)
    }
    fn field_mut(&mut self) -> FieldMut<'_> {
        FieldMut::Bool(self)
    }
}

impl<const N: usize> KnobValue for [f32; N] {
    fn field(&self) -> Field<'_> {
        Field::Floats(self)
    }
    fn field_mut(&mut self) -> FieldMut<'_> {
        FieldMut::Floats(self)
    }
}

impl KnobValue for Option<u32> {
    fn field(&self) -> Field<'_> {
        self.map_or(Field::Absent, Field::Int)
    }
    fn field_mut(&mut self) -> FieldMut<'_> {
        FieldMut::OptionalInt(self)
    }
}

impl KnobValue for Option<f32> {
    fn field(&self) -> Field<'_> {
        self.map_or(Field::Absent, Field::Float)
    }
    fn field_mut(&mut self) -> FieldMut<'_> {
        self.as_mut().map_or(FieldMut::Unset, FieldMut::Float)
    }
}

impl<const N: usize> KnobValue for Option<[f32; N]> {
    fn field(&self) -> Field<'_> {
        self.as_ref().map_or(Field::Absent, |v| Field::Floats(v))
    }
    fn field_mut(&mut self) -> FieldMut<'_> {
        self.as_mut()
            .map_or(FieldMut::Unset, |v| FieldMut::Floats(v))
    }
}

/// Rows of numbers, checked as one flat array (a sprite cloud's colour levels).
impl<const N: usize> KnobValue for Option<Vec<[f32; N]>> {
    fn field(&self) -> Field<'_> {
        self.as_deref()
            .map_or(Field::Absent, |rows| Field::Floats(rows.as_flattened()))
    }
    fn field_mut(&mut self) -> FieldMut<'_> {
        self.as_deref_mut().map_or(FieldMut::Unset, |rows| {
            FieldMut::Floats(rows.as_flattened_mut())
        })
    }
}

/// A value that is one of a list of names (a Rust enum of unit variants).
pub trait Choice {
    /// The index of the current option in [`Choice::options`].
    fn index(&self) -> usize;
    /// Every option: the name scene files use and its description.
    fn options(&self) -> Vec<(String, &'static str)>;
    /// Selects option `index` (an index past the end changes nothing).
    fn select(&mut self, index: usize);
}

/// An enum whose every variant is listed, in declaration order.
trait Listed: Copy + PartialEq + Serialize + DocumentedVariants + 'static {
    const ALL: &'static [Self];
}

impl<E: Listed> Choice for E {
    fn index(&self) -> usize {
        E::ALL.iter().position(|v| v == self).unwrap_or_default()
    }

    fn options(&self) -> Vec<(String, &'static str)> {
        E::ALL
            .iter()
            .map(|v| (name_of(v), v.get_variant_docs()))
            .collect()
    }

    fn select(&mut self, index: usize) {
        if let Some(v) = E::ALL.get(index) {
            *self = *v;
        }
    }
}

/// The name a scene file gives a variant (serde's).
fn name_of(variant: &impl Serialize) -> String {
    match toml::Value::try_from(variant) {
        Ok(toml::Value::String(name)) => name,
        other => format!("{other:?}"),
    }
}

/// Lists every variant of each enum for [`Choice`], and makes it a [`KnobValue`]; a variant left out
/// fails to compile (the exhaustive match).
macro_rules! listed {
    ($($name:ident { $($variant:ident),+ $(,)? })+) => {$(
        impl Listed for $name {
            const ALL: &'static [Self] = &[$($name::$variant),+];
        }
        const _: fn($name) = |v| match v { $($name::$variant)|+ => () };
        impl KnobValue for $name {
            fn field(&self) -> Field<'_> {
                Field::Choice(self)
            }
            fn field_mut(&mut self) -> FieldMut<'_> {
                FieldMut::Choice(self)
            }
        }
    )+};
}

listed! {
    SkyModel { Constant, Gradient, Atmosphere }
    PlanetShape { Spherical, Flat }
    WeatherSource { Procedural, File }
    PhaseModel { Mie, Hg, DualHg }
    LightingModel { Volume, Slab, Octaves }
    ParticleStyle { Smooth, Thresholded, Pyroclastic }
    TableResolution { Low, Standard, High }
    ParticleBlending { VolumeAware, Alpha }
    ParticleOcclusion { Tiles, March }
    SpriteLod { Clusters, Billboards }
    Technique { Raymarch, Particles, Sprites }
    Quality { Low, Medium, High, Ultra }
    Tonemap { Aces, Agx }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn choices_list_their_names_and_descriptions_in_order() {
        let mut technique = Technique::Raymarch;
        let options = technique.options();
        let names: Vec<&str> = options.iter().map(|(name, _)| name.as_str()).collect();
        assert_eq!(names, ["raymarch", "particles", "sprites"]);
        assert!(options[1].1.contains("Yusov 2014"), "{}", options[1].1);
        technique.select(2);
        assert_eq!((technique, technique.index()), (Technique::Sprites, 2));
        technique.select(9);
        assert_eq!(technique, Technique::Sprites);
        assert_eq!(PhaseModel::DualHg.options()[2].0, "dual_hg");
    }
}
