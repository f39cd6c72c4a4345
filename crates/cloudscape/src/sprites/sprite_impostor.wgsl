// The impostor ring in the main pass (sprites/impostors.rs): each of the 8 sectors' quads, at the
// ring radius from the eye it was rendered from, textured with the clouds beyond the ring as that
// eye saw them. Drawn first, behind every sprite within the ring.

// One sector (sprites::impostors::GpuSector).
struct Sector {
    corners_m: array<vec4<f32>, 4>, // world corners: bottom-left, bottom-right, top-left, top-right
    ready: u32,                     // 1 once rendered
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

struct Ring {
    sectors: array<Sector, 8>,
}

@group(3) @binding(0) var<uniform> view: View;
@group(3) @binding(1) var<uniform> ring: Ring;
@group(3) @binding(2) var impostor_radiance: texture_2d_array<f32>;
@group(3) @binding(3) var impostor_distance: texture_2d_array<f32>;
@group(3) @binding(4) var impostor_sampler: sampler;
@group(3) @binding(5) var host_depth: texture_2d<f32>;

struct Varying {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) sector: u32,
}

@vertex
fn vs_impostor(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> Varying {
    let sector = ring.sectors[i];
    var out: Varying;
    out.sector = i;
    out.uv = vec2<f32>(f32(v & 1u), 1.0 - f32(v >> 1u));
    out.clip = sprite_clip(view, sector.corners_m[v].xyz);
    if sector.ready == 0u {
        out.clip = vec4<f32>(0.0, 0.0, 0.0, -1.0);
    }
    return out;
}

@fragment
fn fs_impostor(in: Varying) -> SpriteTargets {
    let radiance = textureSample(impostor_radiance, impostor_sampler, in.uv, in.sector);
    let pair = textureSample(impostor_distance, impostor_sampler, in.uv, in.sector);
    let distance_m = pair.x / max(pair.y, 1e-6) * SPRITE_DISTANCE_UNIT_M;
    let texel = in.clip.xy;
    let depth = textureLoad(host_depth, vec2<i32>(sprite_frame_pixel(texel)), 0).x;
    // A select, not a branch on the uniform alone (sprite_render.wgsl's sprite_max_colours says why).
    let fade = select(1.0, sprite_host_fade(depth, texel, distance_m, 200.0), view.host_depth_test == 1u);
    var out: SpriteTargets;
    out.radiance = radiance * fade;
    out.distance = vec4<f32>(pair.x, pair.y, 0.0, pair.y) * fade;
    return out;
}
