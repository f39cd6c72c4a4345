// Depth-aware upsampling of a coarse cloud output to full resolution for frames without temporal
// reuse (post/upsample.rs): every pixel takes upsample.wgsl's estimate, so cloud edges against the
// host's geometry stay sharp.

@group(3) @binding(0) var upsample_host_depth: texture_2d<f32>;
// The coarse output that upsample.wgsl reads.
@group(3) @binding(1) var coarse_clouds: texture_2d<f32>;
@group(3) @binding(2) var coarse_distance: texture_2d<f32>;
@group(3) @binding(3) var upsampled_clouds: texture_storage_2d<rgba16float, write>;
@group(3) @binding(4) var upsampled_distance: texture_storage_2d<r32float, write>;

@compute @workgroup_size(8, 8)
fn upsample_clouds(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(frame.viewport_px);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    let pixel = vec2<f32>(id.xy) + 0.5;
    let host_m = frame_depth_distance(pixel, textureLoad(upsample_host_depth, vec2<i32>(id.xy), 0).x);
    let estimate = upsample_cloud(id.xy, host_m);
    textureStore(upsampled_clouds, vec2<i32>(id.xy), estimate.radiance_transmittance);
    textureStore(upsampled_distance, vec2<i32>(id.xy), vec4<f32>(estimate.distance_m, 0.0, 0.0, 0.0));
}
