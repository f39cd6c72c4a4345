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

// `texel` clamped to the coarse output.
fn upsample_grid_texel(texel: vec2<i32>) -> vec2<i32> {
    return clamp(texel, vec2<i32>(0), vec2<i32>(textureDimensions(coarse_clouds)) - 1);
}

// The estimate at full-resolution pixel `px` from the coarse output:
// bilinear weights over the four nearest grid samples, zeroed where a sample's cloud lies behind
// this pixel's host geometry (`host_m` away). Grid texel i was rendered through full-resolution
// pixel i * divisor + grid_subpixel, so that is where it is weighted from: an estimate that
// assumed the block's centre would shift by up to 1.5 pixels from frame to frame as the temporal
// grid's sub-pixel moves, and shimmer. The cloud's distance averages over the samples that
// see cloud, by how much they see: a clear sample (distance 0) would pull an edge's distance
// halfway to the camera.
fn upsample_cloud(px: vec2<u32>, host_m: f32) -> UpsampledCloud {
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
        let w = w2.x * w2.y * select(1.0, 0.0, depth_m > host_m) + 1.0e-6;
        let sample = textureLoad(coarse_clouds, texel, 0);
        value += sample * w;
        weight += w;
        cloud_m += depth_m * w * (1.0 - sample.a);
        cloud_weight += w * (1.0 - sample.a);
    }
    return UpsampledCloud(value / weight, select(0.0, cloud_m / cloud_weight, cloud_weight > 1.0e-6));
}
