//! The atmosphere's table passes: transmittance, multiple scattering and irradiance once per air,
//! the sky view and the aerial perspective every frame (Hillaire 2020). They fill the tables that
//! [`crate::environment::EnvironmentGpu`] binds.

use super::Air;
use super::luts::{
    AERIAL_SIZE, IRRADIANCE_SIZE, MULTIPLE_SCATTERING_SIZE, SKY_VIEW_SIZE, TRANSMITTANCE_SIZE,
};
use crate::environment::{EnvironmentTable, TablePass};
use crate::frame::Shared;
use crate::gpu::{GpuContext, PassTimer};
use glam::UVec2;
use wgpu::TextureViewDimension::D2;

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
        let luts = |entry, label, table, outputs: &[wgpu::TextureViewDimension]| {
            TablePass::new(
                ctx,
                shared,
                ("atmosphere_luts", entry),
                (label, table),
                outputs,
            )
        };
        let [t, ms, irr] = TABLE_PASS_NAMES;
        let [view, aerial] = FRAME_PASS_NAMES;
        AtmospherePasses {
            transmittance: luts(
                "atmosphere_build_transmittance",
                t,
                EnvironmentTable::Transmittance,
                &[D2],
            ),
            multiple_scattering: luts(
                "atmosphere_build_multiple_scattering",
                ms,
                EnvironmentTable::MultipleScattering,
                &[D2],
            ),
            irradiance: luts(
                "atmosphere_build_irradiance",
                irr,
                EnvironmentTable::Irradiance,
                &[D2, D2],
            ),
            sky_view: luts(
                "atmosphere_build_sky_view",
                view,
                EnvironmentTable::SkyView,
                &[D2],
            ),
            aerial: TablePass::new(
                ctx,
                shared,
                ("atmosphere_aerial", "atmosphere_build_aerial"),
                (aerial, EnvironmentTable::Aerial),
                &[D2, D2],
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
        shared: &Shared,
        air: &Air,
        mut timer: Option<&mut PassTimer>,
    ) {
        let key = (*air, shared.environment.generation());
        if self.filled_for != Some(key) {
            let statics = [
                (&mut self.transmittance, TRANSMITTANCE_SIZE),
                (&mut self.multiple_scattering, MULTIPLE_SCATTERING_SIZE),
                (&mut self.irradiance, IRRADIANCE_SIZE),
            ];
            for (pass, texels) in statics {
                pass.encode(ctx, encoder, shared, size(texels), timer.as_deref_mut());
            }
            self.filled_for = Some(key);
        }
        let view = size(SKY_VIEW_SIZE);
        self.sky_view
            .encode(ctx, encoder, shared, view, timer.as_deref_mut());
        self.aerial
            .encode(ctx, encoder, shared, size(AERIAL_SIZE), timer);
    }
}
