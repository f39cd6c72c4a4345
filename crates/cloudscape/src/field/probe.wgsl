// Samples the GPU field at given points, so tests can hold it against the CPU specification.

@group(1) @binding(0) var<storage, read> probe_points: array<vec4<f32>>;
@group(1) @binding(1) var<storage, read_write> probe_extinction: array<f32>;

@compute @workgroup_size(64)
fn probe_field(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&probe_points) {
        return;
    }
    probe_extinction[id.x] = field_extinction(probe_points[id.x].xyz);
}
