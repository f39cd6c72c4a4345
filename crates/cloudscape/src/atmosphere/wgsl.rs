//! The atmosphere's WGSL module and the constants it shares with the Rust.

/// The atmosphere's medium and tables as WGSL (`atmosphere.wgsl`).
pub static ATMOSPHERE_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "atmosphere",
    "atmosphere.wgsl",
    [&crate::shader::MATH_WGSL, &crate::optics::phase::PHASE_WGSL],
    atmosphere_constants
);

/// The atmosphere's constants ([`super::medium`], [`super::luts`]) as WGSL, `ATMOSPHERE_` names.
fn atmosphere_constants() -> String {
    use super::luts as l;
    use super::medium as m;
    use crate::shader::WgslConst::{F32, U32, UVec2};
    let values = [
        ("RAYLEIGH_SCALE_HEIGHT_M", F32(m::RAYLEIGH_SCALE_HEIGHT_M)),
        ("MIE_SCALE_HEIGHT_M", F32(m::MIE_SCALE_HEIGHT_M)),
        ("OZONE_PEAK_ALTITUDE_M", F32(m::OZONE_PEAK_ALTITUDE_M)),
        ("OZONE_HALF_WIDTH_M", F32(m::OZONE_HALF_WIDTH_M)),
        ("AERIAL_SLICE_M", F32(l::AERIAL_SLICE_M)),
        ("AERIAL_SLICES", U32(l::AERIAL_SLICES)),
        ("AERIAL_STEPS_PER_SLICE", U32(l::AERIAL_STEPS_PER_SLICE)),
        ("TRANSMITTANCE_STEPS", U32(l::TRANSMITTANCE_STEPS)),
        (
            "MULTIPLE_SCATTERING_STEPS",
            U32(l::MULTIPLE_SCATTERING_STEPS),
        ),
        (
            "MULTIPLE_SCATTERING_DIRECTIONS",
            U32(l::MULTIPLE_SCATTERING_DIRECTIONS),
        ),
        ("SKY_VIEW_STEPS", U32(l::SKY_VIEW_STEPS)),
        ("IRRADIANCE_STEPS", U32(l::IRRADIANCE_STEPS)),
        ("IRRADIANCE_DIRECTIONS", U32(l::IRRADIANCE_DIRECTIONS)),
        ("TRANSMITTANCE_SIZE", UVec2(l::TRANSMITTANCE_SIZE)),
        (
            "MULTIPLE_SCATTERING_SIZE",
            UVec2(l::MULTIPLE_SCATTERING_SIZE),
        ),
        ("IRRADIANCE_SIZE", UVec2(l::IRRADIANCE_SIZE)),
        ("SKY_VIEW_SIZE", UVec2(l::SKY_VIEW_SIZE)),
        ("AERIAL_SIZE", UVec2(l::AERIAL_SIZE)),
    ];
    crate::shader::wgsl_consts(values.map(|(name, value)| (format!("ATMOSPHERE_{name}"), value)))
}
