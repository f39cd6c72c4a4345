//! The entry points of cloudscape's fuzz targets: each feeds bytes to one of the readers of
//! untrusted input and says whether the reader accepted them (`Ok`) or refused them with an
//! error (`Err`, its message). A panic, a hang or an allocation beyond the run's bound is a bug.
//!
//! The fuzz targets (`fuzz_targets/`, run by `cargo +nightly fuzz run NAME`) and the regression
//! test of the inputs they found (`crates/cloudscape/tests/fuzz_regressions.rs`, in plain
//! `cargo test`) call these same functions.

use std::path::Path;

use cloudscape::environment::Environment;
use cloudscape::field::BrickGrid;
use cloudscape::field::vdb::read_vdb_bytes;
use cloudscape::field::voxel::{ValuePolicy, VoxelGrid};
use cloudscape::field::weather::Weather;
use cloudscape::particles::ParticleTableSpec;
use cloudscape::particles::store::{optical_depth_from_bytes, scattering_from_bytes};
use cloudscape::particles::table_file::checksum;
use cloudscape::scene::metar::{self, SceneWeather};
use cloudscape::scene::{Scene, SceneDocument};
use cloudscape::sprites::file::ModelFile;

/// Whether a reader accepted the input, or its error message.
pub type Outcome = Result<(), String>;

/// A target's entry point.
pub type Target = fn(&[u8]) -> Outcome;

/// Every target by name, as `fuzz_targets/` and `tests/fuzz-regressions/` name them.
pub const TARGETS: [(&str, Target); 7] = [
    ("scene", scene),
    ("vol", vol),
    ("vdb", vdb),
    ("weather_png", weather_png),
    ("table_file", table_file),
    ("sprite_model", sprite_model),
    ("metar", metar),
];

/// A scene file with `--set` overrides: the text up to the first NUL is the scene (TOML), each
/// line after it one override. A scene that loads must give a finite sun.
pub fn scene(data: &[u8]) -> Outcome {
    let text = String::from_utf8_lossy(data);
    let (toml, overrides) = text.split_once('\0').unwrap_or((&text, ""));
    let overrides: Vec<String> = overrides.lines().map(str::to_string).collect();
    let doc = SceneDocument::parse(toml, "fuzz.toml", Path::new("."), &overrides)
        .map_err(|e| e.to_string())?;
    check_scene(&doc.scene);
    // Locating a later error walks the merged document and the overrides again.
    let _ = doc.error_at("render.width", "probe");
    Ok(())
}

/// A validated scene's environment is finite.
fn check_scene(scene: &Scene) {
    let env = Environment::from_scene(scene);
    assert!(
        env.sun.direction.is_finite() && env.sun.irradiance.is_finite(),
        "a valid scene gave a non-finite sun: {:?}",
        env.sun
    );
}

/// A Mitsuba `.vol` grid, refusing values that are not densities.
pub fn vol(data: &[u8]) -> Outcome {
    let grid = VoxelGrid::from_vol_bytes(data, Path::new("fuzz.vol"), ValuePolicy::Reject)
        .map_err(|e| e.to_string())?;
    assert!(grid.values.iter().all(|v| v.is_finite() && *v >= 0.0));
    Ok(())
}

/// An OpenVDB file: its first float grid, refusing values that are not densities, bricked as the
/// field bricks it.
pub fn vdb(data: &[u8]) -> Outcome {
    let grid = read_vdb_bytes(data, Path::new("fuzz.vdb"), None, ValuePolicy::Reject)
        .map_err(|e| e.to_string())?;
    let bricks = BrickGrid::from_sparse(&grid.voxels).map_err(|e| e.to_string())?;
    assert!((0.0..=65504.0).contains(&bricks.max_value()));
    Ok(())
}

/// A weather-map PNG.
pub fn weather_png(data: &[u8]) -> Outcome {
    let texture = Weather::texture_from_png(data, Path::new("fuzz.png"))?;
    assert_eq!(
        texture.texels.len(),
        (texture.dims.x * texture.dims.y) as usize
    );
    Ok(())
}

/// A particle table file of the default scene's tables. The first byte chooses: bit 0 the
/// optical-depth table (else the scattering tables); bit 1 rewrites the key to the one the
/// table needs and bit 2 the checksum to the one the bytes have, so that inputs reach the checks
/// behind them. The rest is the file.
pub fn table_file(data: &[u8]) -> Outcome {
    let Some((&choice, file)) = data.split_first() else {
        return Err("empty input".into());
    };
    let spec = ParticleTableSpec::from_scene(&Scene::default());
    let mut bytes = file.to_vec();
    let optical_depth = choice & 1 == 1;
    if choice & 2 == 2 && bytes.len() >= 24 {
        let key = if optical_depth {
            spec.optical_depth_key()
        } else {
            spec.scattering_key()
        };
        bytes[16..24].copy_from_slice(&key.to_le_bytes());
    }
    if choice & 4 == 4 && bytes.len() >= 8 {
        let body = bytes.len() - 8;
        let sum = checksum(&bytes[..body]);
        bytes[body..].copy_from_slice(&sum.to_le_bytes());
    }
    let outcome = if optical_depth {
        optical_depth_from_bytes(&bytes, &spec).map(|_| ())
    } else {
        scattering_from_bytes(&bytes, &spec).map(|_| ())
    };
    outcome.map_err(|e| e.to_string())
}

/// A sprite model file (`cloudscape export --sprites`).
pub fn sprite_model(data: &[u8]) -> Outcome {
    let text = std::str::from_utf8(data).map_err(|e| e.to_string())?;
    let model = ModelFile::parse(text, "fuzz.sprites.toml").map_err(|e| e.to_string())?;
    let clouds = model.clouds();
    assert_eq!(clouds.len(), model.clouds.len());
    Ok(())
}

/// A METAR report: parsed, turned into layers and haze, and set as a scene's `weather.metar`.
pub fn metar(data: &[u8]) -> Outcome {
    let text = std::str::from_utf8(data).map_err(|e| e.to_string())?;
    let report = metar::parse(text).map_err(|e| e.to_string())?;
    let weather = SceneWeather::from_report(&report);
    assert!(
        weather
            .visibility_m
            .is_none_or(|v| v.is_finite() && v > 0.0)
    );
    if text.contains("'''") || text.contains('\n') || text.contains('\r') {
        return Ok(());
    }
    let toml = format!("[weather]\nmetar = '''{text}'''\n");
    let doc =
        SceneDocument::parse(&toml, "fuzz.toml", Path::new("."), &[]).map_err(|e| e.to_string())?;
    check_scene(&doc.scene);
    Ok(())
}
