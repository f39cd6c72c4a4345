// Turns the sprite pass's blended targets into the cloud-output contract (output/mod.rs): the
// premultiplied radiance with transmittance 1 - opacity, and the opacity-weighted mean distance.
// Inside a cloud, the fog that stands for the sprites the eye has passed (sprites/inside.rs) lies
// in front of them.

struct Resolve {
    origin: vec2<u32>,              // first output texel of this band
    size: vec2<u32>,                // texels of this band
    fog_box_min_m: vec3<f32>,       // the fog ends where the view ray leaves this box...
    fog_extinction_per_m: f32,      // the cloud's extinction at the eye (0: no fog)
    fog_box_max_m: vec3<f32>,
    fog_depth_m: f32,               // ...or this far from the eye
    fog_ambient: f32,               // Wang's colour level at the eye
    fog_directional: f32,           // Wang's directional factor at the eye
    fog_lit_by_volume: u32,         // 1: lit as the field's sprites are, from the light volume
    albedo: f32,
    phase_lobes: vec4<f32>,         // the scene's phase function (phase.wgsl)
    slab_params: vec4<f32>,         // the forward peak's beam (slab.wgsl)
}

@group(3) @binding(0) var<uniform> resolve: Resolve;
@group(3) @binding(1) var accumulated: texture_2d<f32>;
@group(3) @binding(2) var accumulated_distance: texture_2d<f32>;
@group(3) @binding(3) var cloud_out: texture_storage_2d<rgba16float, write>;
@group(3) @binding(4) var cloud_distance_out: texture_storage_2d<r32float, write>;

// Where the ray from `o` along `d` leaves the fog's box, m.
fn fog_exit_m(o: vec3<f32>, d: vec3<f32>) -> f32 {
    let inv = 1.0 / select(d, vec3<f32>(1e-9), abs(d) < vec3<f32>(1e-9));
    let far = max((resolve.fog_box_min_m - o) * inv, (resolve.fog_box_max_m - o) * inv);
    return max(min(far.x, min(far.y, far.z)), 0.0);
}

// The fog's in-scattered radiance toward the eye along `d`: as a field sprite is lit (the light
// volume's diffuse light and the sun's beam after the cloud shadow map), or by Wang's colour level
// and directional factor at the eye. Selects, not branches (sprite_render.wgsl says why).
fn fog_radiance(eye: vec3<f32>, d: vec3<f32>) -> vec3<f32> {
    let sun = environment_sun_irradiance(eye);
    let wang = environment_sky_mean_radiance_up(eye) * resolve.fog_ambient + sun / PI * resolve.fog_directional;
    let slab = SlabModel(resolve.phase_lobes, resolve.slab_params);
    let tau_sun = environment_cloud_sun_optical_depth(eye);
    let beam = sun * slab_beam_scattering(slab, dot(d, environment_sun_direction()), tau_sun);
    let volume = environment_light_volume_diffuse(eye, -d) + beam;
    let lit = resolve.fog_lit_by_volume == 1u && environment_has_light_volume();
    return resolve.albedo * select(wang, volume, lit);
}

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
    let eye = frame.camera_position_m;
    let pixel = vec2<f32>(sprite_frame_pixel(vec2<f32>(texel) + 0.5)) + 0.5;
    let ray = frame_ray_direction(pixel);
    let fog_m = min(resolve.fog_depth_m, fog_exit_m(eye, ray));
    let fog_opacity = 1.0 - exp(-resolve.fog_extinction_per_m * fog_m);
    let behind = 1.0 - fog_opacity;
    let radiance = fog_radiance(eye, ray) * fog_opacity + behind * max(c.rgb, vec3<f32>(0.0));
    let weight = fog_opacity + behind * opacity;
    if weight > 1e-4 {
        distance_m = (fog_opacity * 0.5 * fog_m + behind * opacity * distance_m) / weight;
    }
    textureStore(cloud_out, texel, vec4<f32>(radiance, behind * (1.0 - opacity)));
    textureStore(cloud_distance_out, texel, vec4<f32>(distance_m, 0.0, 0.0, 0.0));
}
