// Turns the sprite pass's blended targets into the cloud-output contract (output/mod.rs): the
// premultiplied radiance with transmittance 1 - opacity, and the opacity-weighted mean distance.

struct Resolve {
    origin: vec2<u32>,   // first output texel of this band
    size: vec2<u32>,     // texels of this band
}

@group(3) @binding(0) var<uniform> resolve: Resolve;
@group(3) @binding(1) var accumulated: texture_2d<f32>;
@group(3) @binding(2) var accumulated_distance: texture_2d<f32>;
@group(3) @binding(3) var cloud_out: texture_storage_2d<rgba16float, write>;
@group(3) @binding(4) var cloud_distance_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn resolve_sprites(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= resolve.size) {
        return;
    }
    let texel = vec2<i32>(id.xy + resolve.origin);
    let c = textureLoad(accumulated, texel, 0);
    let d = textureLoad(accumulated_distance, texel, 0);
    let opacity = clamp(c.a, 0.0, 1.0);
    var distance_m = 0.0;
    if d.y > 1e-4 {
        distance_m = d.x / d.y * SPRITE_DISTANCE_UNIT_M;
    }
    textureStore(cloud_out, texel, vec4<f32>(max(c.rgb, vec3<f32>(0.0)), 1.0 - opacity));
    textureStore(cloud_distance_out, texel, vec4<f32>(distance_m, 0.0, 0.0, 0.0));
}
