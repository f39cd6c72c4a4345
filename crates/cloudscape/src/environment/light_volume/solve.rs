//! The diffusion solve of one cascade on the CPU: the specification of `light_volume.wgsl`.
//!
//! The δ-Eddington (P1) equations of [`crate::optics::slab`] in three dimensions, with the diffuse
//! radiance `I(x, w) = I0(x) + w . I1(x)` and the current `J = I1 / 3`:
//! `div J + sigma_a I0 = sigma_s E_b / (4 pi)` and `J = -D grad I0 + B`, where `E_b` is the scaled
//! sun beam's irradiance (on a surface facing it), `B = 3 D sigma_s g E_b s / (4 pi)` the current the
//! beam's anisotropic scattering drives along its direction `s`, and `D = 1 / (3 sigma_tr)`,
//! `sigma_tr = sigma_t (1 - omega g)`, all δ-scaled (the moments of the transfer equation, as in
//! Joseph, Wiscombe & Weinman 1976). Where cells are optically thin the diffusion coefficient is
//! flux-limited ([`flux_limited_diffusion`]), which bounds the current by the radiance as free
//! streaming does (Levermore & Pomraning 1981, "A flux-limited diffusion theory", Astrophys. J.
//! 248), and kept below the grid's height.
//!
//! Finite volumes on a cell-centred grid: faces carry `-D_f (I_n - I) / h + B_f . n`, with `D_f`
//! the harmonic mean of the two cells' coefficients (the continuity of flux across a jump) and
//! `B_f` their mean. The top and bottom faces take Marshak's condition `I0 / 2 - J . n = L / 2`
//! (the radiance `L` entering the grid there: the sky's from above; from below the sky's, or the
//! ground's `albedo / pi` times the irradiance reaching it, which depends on the cell above it:
//! `L = albedo (2 I0 + E_direct / pi) / (1 + albedo)` from the hemispherical fluxes of the P1
//! radiance), which after half a cell gives the face current
//! `J . n = (2 D / h (I0 - L) + B . n) / (1 + 4 D / h)`. The sides reflect (no current): the
//! clouds past them are taken to be like those inside.
//!
//! The solver relaxes vertical lines: each column of cells is solved exactly (the tridiagonal
//! system by the Thomas algorithm) with its neighbours' radiance held, red columns then black ones
//! (line Gauss-Seidel). An infinite horizontal slab is solved in one sweep; light that travels
//! sideways needs more. The first sweep of a cold start leaves the neighbours out (independent
//! columns).

use super::{DiffuseOptics, LightVolumeCascade};
use glam::{UVec3, Vec3};
use std::f32::consts::PI;

/// Most cells of a column: the length of the GPU solver's private arrays.
pub const MAX_COLUMN_CELLS: u32 = 64;

/// Longest current over radiance the table holds: free streaming's bound `|J| <= I0`, the one the
/// flux limiter keeps. In thin sheets, where diffusion's gradients are poor, the current asked for
/// more (its beam part alone reached 1.6 `I0` in a 60 m stratus sheet). The tighter bound of the
/// P1 radiance's positivity, `|J| <= I0 / 3`, was tried: it also cuts the light a lit face sends
/// out (Marshak's `J = I0 / 2` there), and it darkened every canonical scene (HDR-FLIP 0.005-0.05
/// worse) and the generated scenes' classes (tower side 0.98 -> 0.88 of the path tracer).
pub const MAX_RELATIVE_CURRENT: f32 = 1.0;

/// Weights of luminance (ITU-R BT.709): the channel mix the limiter and the stored current use.
pub const LUMINANCE: Vec3 = Vec3::new(0.2126, 0.7152, 0.0722);

/// What enters one cascade's grid at its top and bottom faces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Boundaries {
    /// Cosine-weighted mean radiance of the sky entering the top face: the sky the viewpoint
    /// sees (the path tracer lights every point with the camera's sky).
    pub sky_down: Vec3,
    /// Below the bottom face: a Lambertian ground of this albedo, or (None) the sky's radiance
    /// `sky_up` from below.
    pub ground_albedo: Option<Vec3>,
    /// Radiance entering the bottom face without a ground.
    pub sky_up: Vec3,
}

/// One cascade's diffusion problem: its cells' scaled extinction and beam, and its boundaries.
#[derive(Clone, Debug, PartialEq)]
pub struct Diffusion {
    /// Where the cells lie.
    pub cascade: LightVolumeCascade,
    /// Cells along x, y (up) and z.
    pub cells: UVec3,
    /// The δ-scaled optics of the droplets.
    pub optics: DiffuseOptics,
    /// Per cell, x fastest then y then z: the δ-scaled extinction (m^-1) in `w` and the scaled
    /// beam's irradiance on a surface facing the sun in `xyz`.
    pub inputs: Vec<[f32; 4]>,
    /// Unit direction the sunlight travels (away from the sun).
    pub beam_direction: Vec3,
    /// What enters the top and the bottom.
    pub boundaries: Boundaries,
}

/// The solution: per cell, the mean diffuse radiance `I0` and the diffusion coefficient the last
/// sweep used.
#[derive(Clone, Debug, PartialEq)]
pub struct DiffuseField {
    /// `I0` per cell (the order of [`Diffusion::inputs`]).
    pub radiance: Vec<Vec3>,
    /// Flux-limited diffusion coefficient per cell, metres.
    pub diffusion_m: Vec<f32>,
}

impl Diffusion {
    /// Index of cell `c`.
    pub fn index(&self, c: UVec3) -> usize {
        (c.x + self.cells.x * (c.y + self.cells.y * c.z)) as usize
    }

    /// A field of zeros (a cold start).
    pub fn cold_field(&self) -> DiffuseField {
        let n = self.inputs.len();
        DiffuseField {
            radiance: vec![Vec3::ZERO; n],
            diffusion_m: vec![0.0; n],
        }
    }

    /// Runs `sweeps` sweeps from `field`; the first leaves the columns uncoupled when `cold`.
    pub fn solve(&self, field: &mut DiffuseField, sweeps: u32, cold: bool) {
        for s in 0..sweeps {
            self.sweep(field, !(cold && s == 0));
        }
    }

    /// One sweep: the limiter from the current radiance, then red columns, then black ones
    /// (`light_volume_limit`, `light_volume_relax`).
    pub fn sweep(&self, field: &mut DiffuseField, coupled: bool) {
        let limited: Vec<f32> = (0..self.inputs.len())
            .map(|i| self.limited_diffusion(field, self.cell_of(i)))
            .collect();
        field.diffusion_m = limited;
        for colour in 0..2 {
            for z in 0..self.cells.z {
                for x in 0..self.cells.x {
                    if (x + z) % 2 == colour {
                        self.relax_column(field, (x, z), coupled);
                    }
                }
            }
        }
    }

    fn cell_of(&self, i: usize) -> UVec3 {
        let i = i as u32;
        let (nx, ny) = (self.cells.x, self.cells.y);
        UVec3::new(i % nx, (i / nx) % ny, i / (nx * ny))
    }

    /// Transport coefficient `sigma_tr = sigma_t (1 - omega g)` of cell `i`, m^-1.
    fn transport(&self, i: usize) -> f32 {
        self.inputs[i][3] * (1.0 - self.optics.albedo * self.optics.asymmetry)
    }

    /// The flux-limited diffusion coefficient of cell `c` from the radiance's luminance gradient
    /// over the largest luminance of the cells the gradient reads (the cell's own lags behind a
    /// sweep: a dark cell beside a lit one would get no diffusion at all and gather the light it
    /// should pass on), at most the grid's height.
    pub fn limited_diffusion(&self, field: &DiffuseField, c: UVec3) -> f32 {
        let (gradient, brightest) = self.luminance_gradient(field, c);
        let relative = gradient.length() / brightest.max(1e-12);
        let height_m = self.cascade.cell_m.y * self.cells.y as f32;
        flux_limited_diffusion(self.transport(self.index(c)), relative).min(height_m)
    }

    /// The gradient of the radiance's luminance at cell `c` (central differences, one-sided at
    /// the faces), and the largest luminance of the cells it reads (`light_volume_gradient`).
    fn luminance_gradient(&self, field: &DiffuseField, c: UVec3) -> (Vec3, f32) {
        let lum = |c: UVec3| field.radiance[self.index(c)].dot(LUMINANCE);
        let mut gradient = Vec3::ZERO;
        let mut brightest = lum(c);
        for axis in 0..3 {
            let (lo, hi) = (
                c[axis].saturating_sub(1),
                (c[axis] + 1).min(self.cells[axis] - 1),
            );
            let (mut a, mut b) = (c, c);
            a[axis] = lo;
            b[axis] = hi;
            brightest = brightest.max(lum(a)).max(lum(b));
            if hi > lo {
                let h = (hi - lo) as f32 * self.cascade.cell_m[axis];
                gradient[axis] = (lum(b) - lum(a)) / h;
            }
        }
        (gradient, brightest)
    }

    /// The beam's current `B` in cell `i` per unit irradiance, times the irradiance per channel
    /// (`B = 3 D sigma_s g E_b s / (4 pi)`): its component along `axis`.
    fn beam_current(&self, field: &DiffuseField, i: usize, axis: usize) -> Vec3 {
        let o = &self.optics;
        let scattering = o.albedo * self.inputs[i][3];
        let beam = Vec3::new(self.inputs[i][0], self.inputs[i][1], self.inputs[i][2]);
        3.0 * field.diffusion_m[i] * scattering * o.asymmetry * self.beam_direction[axis] * beam
            / (4.0 * PI)
    }

    /// Solves column `(x, z)` with its neighbours' radiance held: per cell
    /// `sum_f D_f / h^2 (I - I_n) + sigma_a I = sigma_s E_b / (4 pi) - sum_f B_f . n / h`.
    fn relax_column(&self, field: &mut DiffuseField, (x, z): (u32, u32), coupled: bool) {
        let ny = self.cells.y as usize;
        let h = self.cascade.cell_m;
        let harmonic = |a: f32, b: f32| 2.0 * a * b / (a + b).max(1e-30);
        let mut lower = vec![0.0f32; ny];
        let mut upper = vec![0.0f32; ny];
        let mut diag = vec![Vec3::ZERO; ny];
        let mut rhs = vec![Vec3::ZERO; ny];
        for y in 0..ny {
            let c = UVec3::new(x, y as u32, z);
            let i = self.index(c);
            let d = field.diffusion_m[i];
            let sigma = self.inputs[i][3];
            let beam = Vec3::new(self.inputs[i][0], self.inputs[i][1], self.inputs[i][2]);
            diag[y] = Vec3::splat(sigma * (1.0 - self.optics.albedo));
            rhs[y] = self.optics.albedo * sigma * beam / (4.0 * PI);
            for axis in [0usize, 2] {
                for step in [-1i32, 1] {
                    let n = c[axis] as i32 + step;
                    if n < 0 || n >= self.cells[axis] as i32 {
                        continue;
                    }
                    let mut nc = c;
                    nc[axis] = n as u32;
                    let j = self.index(nc);
                    let face_b = 0.5
                        * (self.beam_current(field, i, axis) + self.beam_current(field, j, axis));
                    rhs[y] -= step as f32 * face_b / h[axis];
                    if coupled {
                        let a = harmonic(d, field.diffusion_m[j]) / (h[axis] * h[axis]);
                        diag[y] += Vec3::splat(a);
                        rhs[y] += a * field.radiance[j];
                    }
                }
            }
            for step in [-1i32, 1] {
                let n = y as i32 + step;
                let b_here = self.beam_current(field, i, 1);
                if n < 0 || n >= ny as i32 {
                    let (coefficient, constant) = self.face_current(field, c, step);
                    diag[y] += coefficient / h.y;
                    rhs[y] -= constant / h.y;
                    continue;
                }
                let j = self.index(UVec3::new(x, n as u32, z));
                let face_b = 0.5 * (b_here + self.beam_current(field, j, 1));
                rhs[y] -= step as f32 * face_b / h.y;
                let a = harmonic(d, field.diffusion_m[j]) / (h.y * h.y);
                diag[y] += Vec3::splat(a);
                if step < 0 {
                    lower[y] = -a;
                } else {
                    upper[y] = -a;
                }
            }
        }
        let solved = thomas(&lower, &diag, &upper, &rhs);
        for (y, value) in solved.into_iter().enumerate() {
            let i = self.index(UVec3::new(x, y as u32, z));
            field.radiance[i] = value.max(Vec3::ZERO);
        }
    }

    /// The outward current `J . n` through the top (`step` 1) or bottom (-1) face of cell `c`
    /// as `coefficient I0 + constant` per channel: Marshak's condition with the radiance `L`
    /// entering there, `J . n = (2 D / h (I0 - L) + B . n) / (1 + 4 D / h)`.
    fn face_current(&self, field: &DiffuseField, c: UVec3, step: i32) -> (Vec3, Vec3) {
        let i = self.index(c);
        let conductance = 2.0 * field.diffusion_m[i] / self.cascade.cell_m.y;
        let (alpha, beta) = self.entering(c, step);
        let outward_beam = step as f32 * self.beam_current(field, i, 1);
        let scale = 1.0 / (1.0 + 2.0 * conductance);
        (
            conductance * (Vec3::ONE - alpha) * scale,
            (outward_beam - conductance * beta) * scale,
        )
    }

    /// The current `J = -D grad I0 + B` of cell `c` (luminance, central differences one-sided at
    /// the faces) over its radiance's luminance, at most [`MAX_RELATIVE_CURRENT`] long: what the
    /// table stores beside `I0` (`light_volume_export`).
    pub fn relative_current(&self, field: &DiffuseField, c: UVec3) -> Vec3 {
        let i = self.index(c);
        let (gradient, _) = self.luminance_gradient(field, c);
        let beam = Vec3::from_array(
            [0, 1, 2].map(|axis| self.beam_current(field, i, axis).dot(LUMINANCE)),
        );
        let current = -field.diffusion_m[i] * gradient + beam;
        let luminance = field.radiance[i].dot(LUMINANCE);
        (current / luminance.max(1e-12)).clamp_length_max(MAX_RELATIVE_CURRENT)
    }

    /// Diffuse power leaving the grid through its top and its bottom, `4 pi J . n` summed over
    /// the faces' areas (watts per unit of the radiance's units times m^2).
    pub fn escaping(&self, field: &DiffuseField) -> (Vec3, Vec3) {
        let h = self.cascade.cell_m;
        let area = h.x * h.z;
        let mut out = [Vec3::ZERO; 2];
        for (k, (y, step)) in [(self.cells.y - 1, 1), (0, -1)].into_iter().enumerate() {
            for z in 0..self.cells.z {
                for x in 0..self.cells.x {
                    let c = UVec3::new(x, y, z);
                    let (coefficient, constant) = self.face_current(field, c, step);
                    let current = coefficient * field.radiance[self.index(c)] + constant;
                    out[k] += 4.0 * PI * current * area;
                }
            }
        }
        (out[0], out[1])
    }

    /// The diffuse irradiance leaving the grid downward through the bottom face of column cell
    /// `c` (its bottom row): what enters there from below, `pi L`, plus the net outward flux
    /// `4 pi J . n` of Marshak's face current.
    pub fn bottom_irradiance(&self, field: &DiffuseField, c: UVec3) -> Vec3 {
        let i = self.index(c);
        let (coefficient, constant) = self.face_current(field, c, -1);
        let (alpha, beta) = self.entering(c, -1);
        let radiance = field.radiance[i];
        PI * (alpha * radiance + beta) + 4.0 * PI * (coefficient * radiance + constant)
    }

    /// The radiance entering the face of cell `c` on side `step` (+1 top, -1 bottom) as
    /// `L = alpha I0 + beta` per channel.
    fn entering(&self, c: UVec3, step: i32) -> (Vec3, Vec3) {
        let b = &self.boundaries;
        if step > 0 {
            return (Vec3::ZERO, b.sky_down);
        }
        match b.ground_albedo {
            None => (Vec3::ZERO, b.sky_up),
            Some(albedo) => {
                let i = self.index(c);
                let beam = Vec3::new(self.inputs[i][0], self.inputs[i][1], self.inputs[i][2]);
                let direct = beam * (-self.beam_direction.y).max(0.0);
                let denominator = Vec3::ONE + albedo;
                (
                    2.0 * albedo / denominator,
                    albedo * direct / (PI * denominator),
                )
            }
        }
    }
}

/// The flux-limited diffusion coefficient `D = 1 / max(3 sigma_tr, |grad I0| / I0)` for the
/// transport coefficient `transport` (m^-1) and the relative gradient
/// `relative = |grad I0| / I0` (m^-1): P1's `1 / (3 sigma_tr)` wherever the diffusive current
/// stays below the radiance, and the free-streaming bound `|J| <= I0` where the medium is too thin
/// for that (a clear cell needs no division by its zero coefficient). This is Larsen's limiter
/// `D = ((3 sigma_tr)^n + (|grad I0| / I0)^n)^(-1/n)` with `n -> infinity` (Olson, Auer & Hall
/// 2000, "Diffusion, P1, and other approximate forms of radiation transport", JQSRT 64):
/// Levermore & Pomraning's and Larsen's `n = 2` lower `D` by 5-15 % near a lit face of a thick
/// slab already, which moved the infinite slab 4 % of its peak off the two-stream solution
/// (`light_volume_flux_limited` in `light_volume.wgsl`).
pub fn flux_limited_diffusion(transport: f32, relative: f32) -> f32 {
    1.0 / (3.0 * transport).max(relative).max(1e-30)
}

/// Solves the tridiagonal system `lower[i] x[i-1] + diag[i] x[i] + upper[i] x[i+1] = rhs[i]`
/// (scalar off-diagonals, a diagonal and right side per channel) by the Thomas algorithm.
fn thomas(lower: &[f32], diag: &[Vec3], upper: &[f32], rhs: &[Vec3]) -> Vec<Vec3> {
    let n = diag.len();
    let mut c = vec![Vec3::ZERO; n];
    let mut d = vec![Vec3::ZERO; n];
    for i in 0..n {
        let (prev_c, prev_d) = if i > 0 {
            (c[i - 1], d[i - 1])
        } else {
            (Vec3::ZERO, Vec3::ZERO)
        };
        let m = diag[i] - lower[i] * prev_c;
        c[i] = upper[i] / m;
        d[i] = (rhs[i] - lower[i] * prev_d) / m;
    }
    for i in (0..n.saturating_sub(1)).rev() {
        d[i] = d[i] - c[i] * d[i + 1];
    }
    d
}
