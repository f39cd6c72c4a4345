// Depth-aware upsampling of a coarse cloud output (Yusov 2014, bilateral upsampling): the shared
// pass code that turns an output on a 1/divisor grid into full-resolution estimates, for any
// technique.

// The coarse cloud output it upsamples, `coarse_clouds` (rgba16float) and `coarse_distance`
// (r32float), are globals the importing pass declares in its own group: a library module binds
// nothing in a pass's group. Globals, not function arguments: lavapipe crashes on texture handles
// passed to functions.

struct UpsampledCloud {
    radiance_transmittance: vec4<f32>,
    distance_m: f32,
}

// A full-resolution value the estimate should resemble (the reprojected history), the difference
// per channel at which a coarse sample's weight falls to exp(-1/2) of its share, and how much the
// guide counts (0: plain bilinear).
struct UpsampleGuide {
    value: vec4<f32>,
    scale: vec4<f32>,
    strength: f32,
}

// `texel` clamped to the coarse output.
fn upsample_grid_texel(texel: vec2<i32>) -> vec2<i32> {
    return clamp(texel, vec2<i32>(0), vec2<i32>(textureDimensions(coarse_clouds)) - 1);
}

// The part of its bilinear share a sample keeps however unlike the guide it is.
const UPSAMPLE_GUIDE_FLOOR: f32 = 0.05;

// The estimate at full-resolution pixel `px` from the coarse output:
// bilinear weights over the four nearest grid samples, zeroed where a sample's cloud lies behind
// this pixel's host geometry (`host_m` away). Grid texel i was rendered through full-resolution
// pixel i * divisor + grid_subpixel, so that is where it is weighted from: an estimate that
// assumed the block's centre would shift by up to 1.5 pixels from frame to frame as the temporal
// grid's sub-pixel moves, and shimmer. The cloud's distance averages over the samples that
// see cloud, by how much they see: a clear sample (distance 0) would pull an edge's distance
// halfway to the camera.
fn upsample_cloud(px: vec2<u32>, host_m: f32) -> UpsampledCloud {
    return upsample_cloud_guided(px, host_m, UpsampleGuide(vec4<f32>(0.0), vec4<f32>(1.0), 0.0));
}

// upsample_cloud with each sample's weight scaled by its likeness to `guide` (joint bilateral
// upsampling, Kopf et al. 2007, with the reprojected history as the full-resolution image): at a
// cloud's edge the pixels take the samples on their own side of it, where the history puts the
// edge, instead of a blend across it as wide as the grid's spacing. UPSAMPLE_GUIDE_FLOOR keeps a
// part of every sample, so that where no sample resembles the guide (it shows what has gone) the
// estimate is the plain one.
fn upsample_cloud_guided(px: vec2<u32>, host_m: f32, guide: UpsampleGuide) -> UpsampledCloud {
    let pos = (vec2<f32>(px) - vec2<f32>(frame.grid_subpixel)) / f32(frame.grid_divisor);
    let base = floor(pos);
    let f = pos - base;
    var value = vec4<f32>(0.0);
    var cloud_m = 0.0;
    var weight = 0.0;
    var cloud_weight = 0.0;
    for (var k = 0; k < 4; k++) {
        let offset = vec2<i32>(k & 1, k >> 1u);
        let texel = upsample_grid_texel(vec2<i32>(base) + offset);
        let w2 = select(1.0 - f, f, vec2<bool>(offset == vec2<i32>(1)));
        let depth_m = textureLoad(coarse_distance, texel, 0).x;
        let sample = textureLoad(coarse_clouds, texel, 0);
        let unlike = (sample - guide.value) / guide.scale;
        let likeness = mix(1.0, UPSAMPLE_GUIDE_FLOOR + exp(-0.5 * dot(unlike, unlike)), guide.strength);
        let w = w2.x * w2.y * select(1.0, 0.0, depth_m > host_m) * likeness + 1.0e-6;
        value += sample * w;
        weight += w;
        cloud_m += depth_m * w * (1.0 - sample.a);
        cloud_weight += w * (1.0 - sample.a);
    }
    return UpsampledCloud(value / weight, select(0.0, cloud_m / cloud_weight, cloud_weight > 1.0e-6));
}
