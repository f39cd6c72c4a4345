//! Exposure, tone mapping (ACES fit, AgX) and sRGB encoding: from HDR radiance to display bytes.
//!
//! Every function here has a WGSL twin in `tonemap.wgsl` with the same formula and constants.
//! Tone mappers take linear sRGB radiance (after exposure) and return linear display values in
//! [0, 1]; [`linear_to_srgb`] then encodes them for the display.

use glam::Vec3;

use crate::scene::Tonemap;

/// A 3x3 matrix as published, row by row, applied to a column vector.
type Rows = [[f32; 3]; 3];

fn mul_rows(m: &Rows, v: Vec3) -> Vec3 {
    Vec3::new(
        Vec3::from(m[0]).dot(v),
        Vec3::from(m[1]).dot(v),
        Vec3::from(m[2]).dot(v),
    )
}

/// sRGB to the ACES-like space of the fit, with the RRT saturation folded in
/// (Hill 2016, BakingLab "ACESFitted").
const ACES_INPUT: Rows = [
    [0.59719, 0.35458, 0.04823],
    [0.07600, 0.90834, 0.01566],
    [0.02840, 0.13383, 0.83777],
];
/// Back from the fit's space to linear sRGB (Hill 2016, BakingLab "ACESFitted").
const ACES_OUTPUT: Rows = [
    [1.60475, -0.53108, -0.07367],
    [-0.10208, 1.10813, -0.00605],
    [-0.00327, -0.07276, 1.07602],
];

/// Exposure: radiance times `2^exposure_ev` (exposure in stops).
pub fn apply_exposure(radiance: Vec3, exposure_ev: f32) -> Vec3 {
    radiance * exposure_ev.exp2()
}

/// Hill's rational fit of the ACES RRT + sRGB ODT (Hill 2016, BakingLab "ACESFitted"):
/// `(v (v + 0.0245786) - 0.000090537) / (v (0.983729 v + 0.432951) + 0.238081)`.
fn aces_rrt_odt(v: Vec3) -> Vec3 {
    let a = v * (v + 0.0245786) - 0.000090537;
    let b = v * (0.983729 * v + 0.432951) + 0.238081;
    a / b
}

/// ACES filmic tone mapping, Stephen Hill's fit of the RRT + ODT (Hill 2016, BakingLab
/// "ACESFitted"): linear sRGB radiance to linear display values in [0, 1].
pub fn tonemap_aces(rgb: Vec3) -> Vec3 {
    let fitted = aces_rrt_odt(mul_rows(&ACES_INPUT, rgb.max(Vec3::ZERO)));
    mul_rows(&ACES_OUTPUT, fitted).clamp(Vec3::ZERO, Vec3::ONE)
}

/// AgX inset matrix (Sobotka 2022; values from Wrensch 2023, "Minimal AgX Implementation").
#[allow(
    clippy::excessive_precision,
    reason = "digits as published, to compare with the source"
)]
const AGX_INSET: Rows = [
    [0.842479062253094, 0.0784335999999992, 0.0792237451477643],
    [0.0423282422610123, 0.878468636469772, 0.0791661274605434],
    [0.0423756549057051, 0.0784336, 0.879142973793104],
];
/// AgX outset matrix, the inverse of [`AGX_INSET`] (Wrensch 2023).
#[allow(
    clippy::excessive_precision,
    reason = "digits as published, to compare with the source"
)]
const AGX_OUTSET: Rows = [
    [1.19687900512017, -0.0980208811401368, -0.0990297440797205],
    [-0.0528968517574562, 1.15190312990417, -0.0989611768448433],
    [-0.0529716355144438, -0.0980434501171241, 1.15107367264116],
];
/// Lower end of the log2 range the AgX sigmoid spans, in stops (Sobotka 2022).
const AGX_MIN_EV: f32 = -12.47393;
/// Upper end of the log2 range the AgX sigmoid spans, in stops (Sobotka 2022).
const AGX_MAX_EV: f32 = 4.026069;
/// Smallest value passed to `log2`, far below [`AGX_MIN_EV`] (avoids `log2(0)`).
const AGX_LOG_FLOOR: f32 = 1e-10;
/// Display gamma the AgX sigmoid output is encoded with; removed to return linear values.
const AGX_DISPLAY_GAMMA: f32 = 2.2;

/// 6th-order polynomial fit of AgX's default contrast sigmoid on [0, 1] (Wrensch 2023).
fn agx_sigmoid(x: Vec3) -> Vec3 {
    let x2 = x * x;
    let x4 = x2 * x2;
    15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x
        - 0.00232
}

/// AgX tone mapping, base look (Sobotka 2022, with Wrensch 2023's polynomial sigmoid): linear
/// sRGB radiance to linear display values in [0, 1].
pub fn tonemap_agx(rgb: Vec3) -> Vec3 {
    let inset = mul_rows(&AGX_INSET, rgb.max(Vec3::ZERO));
    let log_ev = inset
        .max(Vec3::splat(AGX_LOG_FLOOR))
        .to_array()
        .map(f32::log2);
    let log_ev = Vec3::from(log_ev).clamp(Vec3::splat(AGX_MIN_EV), Vec3::splat(AGX_MAX_EV));
    let x = (log_ev - AGX_MIN_EV) / (AGX_MAX_EV - AGX_MIN_EV);
    let encoded = mul_rows(&AGX_OUTSET, agx_sigmoid(x)).clamp(Vec3::ZERO, Vec3::ONE);
    encoded.powf(AGX_DISPLAY_GAMMA)
}

/// Applies the tone-mapping operator `op`.
pub fn tonemap(rgb: Vec3, op: Tonemap) -> Vec3 {
    match op {
        Tonemap::Aces => tonemap_aces(rgb),
        Tonemap::Agx => tonemap_agx(rgb),
    }
}

/// The sRGB transfer function (IEC 61966-2-1): linear `x` (clamped to [0, 1]) to its encoding,
/// `12.92 x` up to 0.0031308, else `1.055 x^(1/2.4) - 0.055`.
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// The inverse sRGB transfer function (IEC 61966-2-1): encoded `v` (clamped to [0, 1]) to linear,
/// `v / 12.92` up to 0.04045, else `((v + 0.055) / 1.055)^2.4`.
pub fn srgb_to_linear(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// An encoded value in [0, 1] as an 8-bit code, rounded to nearest.
pub fn quantize_u8(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Display bytes of HDR `radiance`: exposure by `exposure_ev` stops, tone mapping by `op`, sRGB
/// encoding, 8-bit quantisation.
pub fn display_rgb8(radiance: Vec3, exposure_ev: f32, op: Tonemap) -> [u8; 3] {
    let display = tonemap(apply_exposure(radiance, exposure_ev), op);
    display.to_array().map(|c| quantize_u8(linear_to_srgb(c)))
}

/// The tone mapping on the GPU (`tonemap.wgsl`), the twin of this module.
pub static TONEMAP_WGSL: crate::shader::WgslModule =
    crate::shader::wgsl_module!("tonemap", "tonemap.wgsl", []);

#[cfg(test)]
mod tests {
    use super::*;

    const OPERATORS: [Tonemap; 2] = [Tonemap::Aces, Tonemap::Agx];

    #[test]
    fn tonemaps_are_monotone_and_bounded() {
        for op in OPERATORS {
            let f = |c| tonemap(c, op);
            let mut previous = f(Vec3::ZERO);
            for i in 1..=400 {
                // Grey and a saturated colour from 2^-14 to 2^16.
                let level = (i as f32 * 0.075 - 14.0).exp2();
                for colour in [Vec3::ONE, Vec3::new(1.0, 0.4, 0.1)] {
                    let out = f(colour * level);
                    assert!(
                        out.cmpge(Vec3::ZERO).all() && out.cmple(Vec3::ONE).all(),
                        "{op:?}"
                    );
                }
                let grey = f(Vec3::splat(level));
                assert!(grey.cmpge(previous).all(), "{op:?} not monotone at {level}");
                previous = grey;
            }
        }
    }

    #[test]
    fn black_stays_black_and_bright_saturates() {
        for op in OPERATORS {
            let f = |c| tonemap(c, op);
            assert_eq!(f(Vec3::ZERO), Vec3::ZERO, "{op:?}");
            assert_eq!(f(Vec3::splat(-1.0)), Vec3::ZERO, "{op:?} negative input");
            let white = f(Vec3::splat(1e6));
            assert!(
                white.cmpgt(Vec3::splat(0.99)).all() && white.cmple(Vec3::ONE).all(),
                "{op:?}"
            );
        }
    }

    #[test]
    fn mid_grey_lands_mid_screen() {
        // 0.18 linear maps near the middle of the display range in both operators.
        for op in OPERATORS {
            let f = |c| tonemap(c, op);
            let display = linear_to_srgb(f(Vec3::splat(0.18)).x);
            assert!((0.3..0.6).contains(&display), "{op:?}: {display}");
        }
    }

    #[test]
    fn published_matrices_are_consistent() {
        // Hill's matrices keep white white: rows sum to 1.
        for row in ACES_INPUT.iter().chain(&ACES_OUTPUT) {
            assert!((row.iter().sum::<f32>() - 1.0).abs() < 2e-5, "{row:?}");
        }
        // The AgX outset matrix inverts the inset matrix.
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            let back = mul_rows(&AGX_OUTSET, mul_rows(&AGX_INSET, axis));
            assert!((back - axis).abs().max_element() < 1e-6, "{back}");
        }
    }

    #[test]
    fn srgb_known_values_and_round_trip() {
        let known = [
            (0.0, 0.0),
            (0.0031308, 0.04045),
            (0.18, 0.461356),
            (0.5, 0.735357),
            (1.0, 1.0),
        ];
        for (linear, encoded) in known {
            assert!((linear_to_srgb(linear) - encoded).abs() < 1e-5, "{linear}");
            assert!((srgb_to_linear(encoded) - linear).abs() < 1e-5, "{encoded}");
        }
        for code in 0..=255u8 {
            let v = f32::from(code) / 255.0;
            assert_eq!(quantize_u8(linear_to_srgb(srgb_to_linear(v))), code);
        }
    }

    #[test]
    fn exposure_doubles_per_stop() {
        assert_eq!(apply_exposure(Vec3::splat(0.25), 2.0), Vec3::ONE);
        assert_eq!(apply_exposure(Vec3::ONE, -1.0), Vec3::splat(0.5));
        assert_eq!(display_rgb8(Vec3::splat(1e9), 0.0, Tonemap::Aces), [255; 3]);
        assert_eq!(display_rgb8(Vec3::ZERO, 5.0, Tonemap::Agx), [0; 3]);
        let dim = display_rgb8(Vec3::splat(0.1), 0.0, Tonemap::Aces);
        let bright = display_rgb8(Vec3::splat(0.1), 2.0, Tonemap::Aces);
        assert!(bright[0] > dim[0]);
    }
}
