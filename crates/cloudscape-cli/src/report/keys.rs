//! Keys of the stored references: stable hashes of everything the path tracer reads, so that
//! tuning a real-time technique keeps the references and any change to what is traced retraces
//! them.

use anyhow::{Context, Result, anyhow};
use cloudscape::field::CloudField;
use cloudscape::particles::generate::Particle;
use cloudscape::scene::{Scene, SceneDocument};
use cloudscape::stable_hash::StableHasher;
use cloudscape::temporal::halton;
use glam::Vec3;

/// The key of the path-traced cloud field of `doc`: the scene as the path tracer reads it, the
/// voxel files' bytes, the field's extinction at fixed points, the image size and
/// [`cloudscape_reference::TRACER_REVISION`].
pub fn field_key(doc: &SceneDocument) -> Result<String> {
    let mut hasher = StableHasher::new();
    hasher
        .u32(cloudscape_reference::TRACER_REVISION)
        .str(&path_traced_part(&doc.scene)?.to_string());
    for path in doc.scene.volumes.iter().map(|v| doc.resolve_path(&v.path)) {
        let bytes = std::fs::read(&path).with_context(|| path.display().to_string())?;
        hasher.u64(bytes.len() as u64).bytes(&bytes);
    }
    hash_field(doc, &mut hasher)?;
    Ok(format!("{:016x}", hasher.finish()))
}

/// The key of the particle set `particles` made from the field keyed `field_key` (the particle
/// technique's reference particle included).
pub fn particle_key(
    field_key: &str,
    particle_seed: u32,
    style: u32,
    particles: &[Particle],
) -> String {
    let mut hasher = StableHasher::new();
    hasher.str(field_key).u32(particle_seed).u32(style);
    let mut sorted: Vec<&Particle> = particles.iter().collect();
    sorted.sort_by_key(|p| p.id);
    for p in sorted {
        hasher.u64(u64::from(p.id));
        for v in p.centre_m.to_array() {
            hasher.f32(v);
        }
        hasher.f32(p.radius_m).f32(p.height_m).f32(p.density);
    }
    format!("{:016x}", hasher.finish())
}

/// Hashes the scene's cloud field itself, its extinction at a fixed scatter of points through the
/// layers and the voxel boxes, so that a change to the field's code (noise, profiles, coverage)
/// retraces the references as a change to the scene does.
fn hash_field(doc: &SceneDocument, hasher: &mut StableHasher) -> Result<()> {
    let field = CloudField::new(&doc.scene, &doc.resolve_path(""))
        .map_err(|e| anyhow!(doc.error_at(&e.key_path, e.message)))?;
    let (bottom_m, top_m) = field.altitude_range_m().unwrap_or((0.0, 0.0));
    let layer_box = (
        Vec3::new(-20_000.0, bottom_m, -20_000.0),
        Vec3::new(40_000.0, top_m - bottom_m, 40_000.0),
    );
    let boxes = field.volumes.iter().map(|v| (v.min_m, v.size_m));
    for (min_m, size_m) in std::iter::once(layer_box).chain(boxes) {
        for i in 0..512_u32 {
            let unit = Vec3::new(halton(i + 1, 2), halton(i + 1, 3), halton(i + 1, 5));
            let p = min_m + unit * size_m;
            hasher.f32(field.extinction_per_m(p, doc.scene.render.time_s));
        }
    }
    Ok(())
}

/// Keys of the `[lighting]` and `[render]` tables that the path tracer reads; the others only
/// steer the real-time techniques.
const PATH_TRACED_KEYS: [(&str, &[&str]); 2] = [
    ("lighting", &["albedo"]),
    ("render", &["width", "height", "time_s"]),
];

/// `scene` as a TOML table without the settings only the real-time techniques read.
fn path_traced_part(scene: &Scene) -> Result<toml::Table> {
    let mut table = toml::Table::try_from(scene)?;
    for real_time_only in ["particles", "sprites", "sprite_clouds"] {
        table.remove(real_time_only);
    }
    for (section, kept) in PATH_TRACED_KEYS {
        if let Some(toml::Value::Table(t)) = table.get_mut(section) {
            t.retain(|key, _| kept.contains(&key));
        }
    }
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;
    use cloudscape::scene::Quality;

    #[test]
    fn keys_ignore_what_only_the_real_time_techniques_read() {
        let scene = Scene::default();
        let key = |s: &Scene| path_traced_part(s).expect("a scene serialises");
        let mut tuned = scene.clone();
        tuned.lighting.octaves += 1;
        tuned.lighting.ambient_scale *= 0.5;
        tuned.render.quality = Quality::Ultra;
        tuned.render.exposure_ev = 2.0;
        tuned.sprites.ring_radius_m = 0.0;
        tuned.particles.radius_m *= 2.0;
        assert_eq!(key(&scene), key(&tuned));
        let mut absorbing = scene.clone();
        absorbing.lighting.albedo = 0.9;
        assert_ne!(key(&scene), key(&absorbing));
        let mut wider = scene.clone();
        wider.render.width += 1;
        assert_ne!(key(&scene), key(&wider));
    }
}
