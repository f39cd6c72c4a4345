// The coarse field read at many points at once (field/read_gpu.rs): one invocation per point, the
// GPU twin of CloudField::coarse_extinction_per_m (field/reader.rs).

@group(3) @binding(0) var<storage, read> read_points: array<vec4<f32>>;
@group(3) @binding(1) var<storage, read_write> read_extinctions: array<f32>;

@compute @workgroup_size(64)
fn read_coarse_extinction(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = id.x + id.y * groups.x * 64u;
    if i >= arrayLength(&read_points) {
        return;
    }
    read_extinctions[i] = field_extinction_coarse(read_points[i].xyz);
}
