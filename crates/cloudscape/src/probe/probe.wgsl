// Evaluates one WGSL function that has a CPU twin at given inputs, so tests can hold the GPU
// against the specification (probe/mod.rs lists the functions and their twins).

struct ProbeInput {
    a: vec4<f32>,
    b: vec4<f32>,
    c: vec4<f32>,
    d: vec4<f32>,
}

struct Probe {
    function: u32,
}

@group(3) @binding(0) var<uniform> probe: Probe;
@group(3) @binding(1) var<storage, read> probe_inputs: array<ProbeInput>;
@group(3) @binding(2) var<storage, read_write> probe_outputs: array<vec4<f32>>;

fn probe_eval(f: u32, a: vec4<f32>, b: vec4<f32>, c: vec4<f32>, d: vec4<f32>) -> vec4<f32> {
    switch f {
        case 0u: { return vec4<f32>(field_extinction(a.xyz)); }
        case 1u: { return vec4<f32>(field_extinction_coarse(a.xyz)); }
        case 2u: { return vec4<f32>(field_optical_depth_mean(a.xyz, b.xyz, vec3<f32>(0.0, a.w, b.w), 16u, 0.5)); }
        case 3u: { return vec4<f32>(frame_ray_direction(a.xy), 0.0); }
        case 4u: { return vec4<f32>(min(frame_depth_distance(a.xy, a.z), 1.0e30)); }
        case 5u: { return vec4<f32>(environment_aerial_perspective(a.xyz, a.w, b.yz, b.x), 0.0); }
        case 6u: { return vec4<f32>(environment_sun_disc_radiance(a.xyz), 0.0); }
        case 7u: { return vec4<f32>(environment_sky_radiance(a.xyz), 0.0); }
        case 8u: { return vec4<f32>(environment_ground_radiance(a.xyz, b.xyz), 0.0); }
        case 9u: { return vec4<f32>(tonemap_aces(a.xyz), 0.0); }
        case 10u: { return vec4<f32>(tonemap_agx(a.xyz), 0.0); }
        case 11u: { return vec4<f32>(linear_to_srgb(a.xyz), 0.0); }
        case 12u: { return vec4<f32>(frame_diffuse_transmittance(a.x)); }
        case 13u: { return vec4<f32>(phase_eval(phase_scaled(a, b.y), b.x)); }
        case 14u: { return vec4<f32>(field_height_gradient(a.x, a.y)); }
        case 15u: { return vec4<f32>(environment_sun_irradiance(a.xyz), 0.0); }
        case 16u: { return vec4<f32>(environment_sky_irradiance_up(a.xyz), 0.0); }
        case 17u: { return vec4<f32>(environment_sky_mean_radiance_up(a.xyz), 0.0); }
        case 18u: { return vec4<f32>(environment_cloud_sun_optical_depth(a.xyz)); }
        case 19u: { return vec4<f32>(environment_cloud_sky_optical_depth(a.xyz)); }
        case 20u: { return vec4<f32>(frame_two_stream_share_from_below(a.x, a.y)); }
        case 21u: { return vec4<f32>(phase_octaves(a, b.xyz, u32(c.z), c.x, c.y)); }
        case 22u: { return vec4<f32>(slab_scattering(SlabModel(a, b), c.x, c.y, c.z)); }
        case 23u: { return vec4<f32>(march_sun_optical_depth(a.xyz, u32(b.x), b.y)); }
        case 24u: { return vec4<f32>(march_back_optical_depth(a.xyz, u32(b.x), b.y)); }
        case 25u: {
            let merged = blend_merge(BlendSegment(a.x, a.y, a.z, b.xyz), BlendSegment(c.x, c.y, c.z, d.xyz));
            return vec4<f32>(merged.colour, merged.far_m);
        }
        case 26u: {
            let colors = array<vec4<f32>, 5>(a, a + b, a + 4.0 * b, a + 9.0 * b, a + 16.0 * b);
            return sprite_level(colors, array<f32, 5>(c.x, c.y, c.z, c.w, d.x), d.y);
        }
        case 27u: { return vec4<f32>(environment_sun_disc_pixel_radiance(a.xyz, b.xyz, c.xyz), 0.0); }
        case 28u: { return vec4<f32>(environment_light_volume_diffuse(a.xyz, b.xyz), 0.0); }
        case 29u: { return vec4<f32>(environment_light_volume_ground_irradiance(a.xyz), 0.0); }
        case 30u: { return vec4<f32>(phase_broad_share(a, b.z, b.x)); }
        case 31u: { return frame_round_to_half(a, b.x); }
        case 32u: { return vec4<f32>(frame_footprint_point(u32(a.x), u32(a.y)), 0.0, 0.0); }
        default: { return vec4<f32>(-1.0); }
    }
}

@compute @workgroup_size(64)
fn probe_functions(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&probe_inputs) {
        return;
    }
    let input = probe_inputs[id.x];
    probe_outputs[id.x] = probe_eval(probe.function, input.a, input.b, input.c, input.d);
}
