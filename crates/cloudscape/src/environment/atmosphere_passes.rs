//! The atmosphere's table passes: transmittance, multiple scattering and irradiance once per air,
//! the sky view and the aerial perspective every frame (Hillaire 2020). They fill the tables that
//! [`super::EnvironmentGpu`] binds.

use super::{EnvironmentGpu, EnvironmentTable, TablePass};
use crate::atmosphere::ATMOSPHERE_WGSL;
use crate::atmosphere::Air;
use crate::atmosphere::luts::{
    AERIAL_SIZE, IRRADIANCE_SIZE, MULTIPLE_SCATTERING_SIZE, SKY_VIEW_SIZE, TRANSMITTANCE_SIZE,
};
use crate::gpu::{GpuContext, PassTimer};
use crate::pass::Shared;
use glam::UVec2;

/// Labels of the passes that run when the air changes, in order.
pub const TABLE_PASS_NAMES: [&str; 3] = [
    "sky: transmittance table",
    "sky: multiple scattering table",
    "sky: irradiance table",
];
/// Labels of the passes that run every frame, in order.
pub const FRAME_PASS_NAMES: [&str; 2] = ["sky: view table", "sky: aerial perspective"];

fn size((w, h): (u32, u32)) -> UVec2 {
    UVec2::new(w, h)
}

/// The five table passes, and which air (and which set of tables) the static ones last filled.
pub struct AtmospherePasses {
    transmittance: TablePass,
    multiple_scattering: TablePass,
    irradiance: TablePass,
    sky_view: TablePass,
    aerial: TablePass,
    filled_for: Option<(Air, u64)>,
}

impl AtmospherePasses {
    /// Builds the pipelines against the shared groups.
    pub fn new(ctx: &GpuContext, shared: &Shared) -> AtmospherePasses {
        let luts = |entry, label, table| {
            TablePass::new(ctx, shared, (&ATMOSPHERE_LUTS_WGSL, entry), (label, table))
        };
        let [t, ms, irr] = TABLE_PASS_NAMES;
        let [view, aerial] = FRAME_PASS_NAMES;
        AtmospherePasses {
            transmittance: luts(
                "atmosphere_build_transmittance",
                t,
                EnvironmentTable::Transmittance,
            ),
            multiple_scattering: luts(
                "atmosphere_build_multiple_scattering",
                ms,
                EnvironmentTable::MultipleScattering,
            ),
            irradiance: luts(
                "atmosphere_build_irradiance",
                irr,
                EnvironmentTable::Irradiance,
            ),
            sky_view: luts("atmosphere_build_sky_view", view, EnvironmentTable::SkyView),
            aerial: TablePass::new(
                ctx,
                shared,
                (&ATMOSPHERE_AERIAL_WGSL, "atmosphere_build_aerial"),
                (aerial, EnvironmentTable::Aerial),
            ),
            filled_for: None,
        }
    }

    /// Records the frame's passes for `air`, after the static tables when the air (or the
    /// tables) changed since they were last filled.
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        (shared, environment): (&Shared, &EnvironmentGpu),
        air: &Air,
        mut timer: Option<&mut PassTimer>,
    ) {
        let key = (*air, environment.generation());
        if self.filled_for != Some(key) {
            let statics = [
                (&mut self.transmittance, TRANSMITTANCE_SIZE),
                (&mut self.multiple_scattering, MULTIPLE_SCATTERING_SIZE),
                (&mut self.irradiance, IRRADIANCE_SIZE),
            ];
            for (pass, texels) in statics {
                pass.encode(
                    ctx,
                    encoder,
                    (shared, environment),
                    size(texels),
                    timer.as_deref_mut(),
                );
            }
            self.filled_for = Some(key);
        }
        let view = size(SKY_VIEW_SIZE);
        let groups = (shared, environment);
        self.sky_view
            .encode(ctx, encoder, groups, view, timer.as_deref_mut());
        self.aerial
            .encode(ctx, encoder, groups, size(AERIAL_SIZE), timer);
    }
}

/// Marches through the air that the table passes share (`atmosphere_march.wgsl`).
pub static ATMOSPHERE_MARCH_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "atmosphere_march",
    "atmosphere_march.wgsl",
    [
        &crate::shader::MATH_WGSL,
        &ATMOSPHERE_WGSL,
        &super::ENVIRONMENT_WGSL,
        &crate::optics::phase::PHASE_WGSL
    ]
);

/// The passes that fill the atmosphere's tables (`atmosphere_luts.wgsl`).
pub static ATMOSPHERE_LUTS_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "atmosphere_luts",
    "atmosphere_luts.wgsl",
    [
        &crate::shader::MATH_WGSL,
        &ATMOSPHERE_WGSL,
        &super::ENVIRONMENT_WGSL,
        &ATMOSPHERE_MARCH_WGSL
    ]
);

/// The pass that fills the aerial-perspective volume (`atmosphere_aerial.wgsl`).
pub static ATMOSPHERE_AERIAL_WGSL: crate::shader::WgslModule = crate::shader::wgsl_module!(
    "atmosphere_aerial",
    "atmosphere_aerial.wgsl",
    [
        &crate::frame::FRAME_WGSL,
        &ATMOSPHERE_WGSL,
        &super::ENVIRONMENT_WGSL,
        &ATMOSPHERE_MARCH_WGSL
    ]
);
