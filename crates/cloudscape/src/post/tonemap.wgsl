// Exposure, tone mapping and sRGB encoding: the GPU twin of post/tonemap.rs (same formulas).
// Functions only (no bindings, no entry points).
//
// Matrices are written row by row as published and applied as `c * M`, which in WGSL's
// column-major convention is the published `M c`.

// Stephen Hill, BakingLab "ACESFitted" (2016): sRGB -> ACES-like input matrix (RRT saturation
// folded in), the RRT+ODT rational fit, and the output matrix back to sRGB.
const TONEMAP_ACES_INPUT: mat3x3<f32> = mat3x3<f32>(
    0.59719, 0.35458, 0.04823,
    0.07600, 0.90834, 0.01566,
    0.02840, 0.13383, 0.83777,
);
const TONEMAP_ACES_OUTPUT: mat3x3<f32> = mat3x3<f32>(
    1.60475, -0.53108, -0.07367,
    -0.10208, 1.10813, -0.00605,
    -0.00327, -0.07276, 1.07602,
);

// AgX (Sobotka 2022), base look, with the inset/outset matrices and the 6th-order polynomial fit
// of the contrast sigmoid from Wrensch 2023, "Minimal AgX Implementation".
const TONEMAP_AGX_INSET: mat3x3<f32> = mat3x3<f32>(
    0.842479062253094, 0.0784335999999992, 0.0792237451477643,
    0.0423282422610123, 0.878468636469772, 0.0791661274605434,
    0.0423756549057051, 0.0784336, 0.879142973793104,
);
const TONEMAP_AGX_OUTSET: mat3x3<f32> = mat3x3<f32>(
    1.19687900512017, -0.0980208811401368, -0.0990297440797205,
    -0.0528968517574562, 1.15190312990417, -0.0989611768448433,
    -0.0529716355144438, -0.0980434501171241, 1.15107367264116,
);
// Log2 exposure range the AgX sigmoid spans, in stops relative to 0.18 mid grey.
const TONEMAP_AGX_MIN_EV: f32 = -12.47393;
const TONEMAP_AGX_MAX_EV: f32 = 4.026069;
// Smallest value passed to log2, far below TONEMAP_AGX_MIN_EV.
const TONEMAP_AGX_LOG_FLOOR: f32 = 1e-10;
// Display gamma AgX's sigmoid output is encoded with.
const TONEMAP_AGX_DISPLAY_GAMMA: f32 = 2.2;

// Radiance scaled by an exposure of exposure_ev stops: c * 2^ev.
fn tonemap_exposure(c: vec3<f32>, exposure_ev: f32) -> vec3<f32> {
    return c * exp2(exposure_ev);
}

fn tonemap_aces_rrt_odt(v: vec3<f32>) -> vec3<f32> {
    let a = v * (v + 0.0245786) - 0.000090537;
    let b = v * (0.983729 * v + 0.4329510) + 0.238081;
    return a / b;
}

// ACES filmic (Hill's fit): linear sRGB radiance -> linear display values in [0, 1].
fn tonemap_aces(c: vec3<f32>) -> vec3<f32> {
    let fitted = tonemap_aces_rrt_odt(max(c, vec3<f32>(0.0)) * TONEMAP_ACES_INPUT);
    return clamp(fitted * TONEMAP_ACES_OUTPUT, vec3<f32>(0.0), vec3<f32>(1.0));
}

fn tonemap_agx_sigmoid(x: vec3<f32>) -> vec3<f32> {
    let x2 = x * x;
    let x4 = x2 * x2;
    return 15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2
        + 0.1191 * x - 0.00232;
}

// AgX base look: linear sRGB radiance -> linear display values in [0, 1].
fn tonemap_agx(c: vec3<f32>) -> vec3<f32> {
    let inset = max(c, vec3<f32>(0.0)) * TONEMAP_AGX_INSET;
    let log_ev = clamp(
        log2(max(inset, vec3<f32>(TONEMAP_AGX_LOG_FLOOR))),
        vec3<f32>(TONEMAP_AGX_MIN_EV),
        vec3<f32>(TONEMAP_AGX_MAX_EV),
    );
    let x = (log_ev - TONEMAP_AGX_MIN_EV) / (TONEMAP_AGX_MAX_EV - TONEMAP_AGX_MIN_EV);
    let encoded = clamp(tonemap_agx_sigmoid(x) * TONEMAP_AGX_OUTSET, vec3<f32>(0.0), vec3<f32>(1.0));
    return pow(encoded, vec3<f32>(TONEMAP_AGX_DISPLAY_GAMMA));
}

// Linear -> sRGB transfer function (IEC 61966-2-1), per channel, input clamped to [0, 1].
fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {
    let x = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    let low = 12.92 * x;
    let high = 1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(high, low, x <= vec3<f32>(0.0031308));
}
