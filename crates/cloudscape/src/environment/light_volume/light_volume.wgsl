// The light volume's solve (environment/light_volume): per cell the scaled extinction and beam,
// then sweeps of the flux limiter and the red-black line relaxation, then the table the
// environment reads. solve.rs and inputs.rs are the CPU twins and derive every formula.
//
// Cells are numbered x fastest, then y (up), then z, then the cascade; dispatches over cells run
// on a 2-D grid of (x, the rest) and over columns on (x, z + the cascade's z).

// Per cell: the scaled sun beam's irradiance (rgb) and the scaled extinction (w), m^-1.
@group(3) @binding(0) var<storage, read_write> volume_cells: array<vec4<f32>>;
// Per cell: the mean diffuse radiance I0 (rgb).
@group(3) @binding(1) var<storage, read_write> volume_radiance: array<vec4<f32>>;
// Per cell: the flux-limited diffusion coefficient, metres.
@group(3) @binding(2) var<storage, read_write> volume_diffusion: array<f32>;
// The environment's table as rgba16float texels (two packed u32 each), rows padded to
// LIGHT_VOLUME_ROW_TEXELS for the copy into the 3-D texture: I0 of each cascade side by side along
// z, then J / I0 the same way, then the ground's irradiance under each column in the bottom row.
@group(3) @binding(3) var<storage, read_write> volume_table_out: array<vec2<u32>>;
// What this frame's passes solve (light_volume::pass::SolveUniform).
struct LightVolumeSolve {
    shift_cells: array<vec4<i32>, LIGHT_VOLUME_MAX_CASCADES>, // xy: where this frame's cells lay in the grid last solved, in whole cells along x and z
    first_swept: u32,                                         // the first cascade the sweeps and the table cover
    swept: u32,                                               // how many, from it
    cell_slice: u32,                                          // the slice of the swept cells' rows a warm turn updates
    pad0: u32,
}
@group(3) @binding(4) var<uniform> volume_solve: LightVolumeSolve;

// The cell and cascade of an invocation of a dispatch over the cells of the cascades swept this
// frame (x, the rest): a warm turn sweeps one cascade, in turn, and its dispatches cover that
// cascade alone.
fn light_volume_swept_cell_of(id: vec2<u32>) -> vec4<u32> {
    return light_volume_cell_of(id) + vec4<u32>(0u, 0u, 0u, volume_solve.first_swept);
}

fn light_volume_in_swept_cells(id: vec2<u32>) -> bool {
    let n = light_volume_cells_of();
    return id.x < n.x && id.y < n.y * n.z * volume_solve.swept;
}

const LIGHT_VOLUME_LUMINANCE = vec3<f32>(0.2126, 0.7152, 0.0722);

fn light_volume_cells_of() -> vec3<u32> {
    return environment.light_volume.cells;
}

// Index of cell c of cascade k.
fn light_volume_index(c: vec3<u32>, k: u32) -> u32 {
    let n = light_volume_cells_of();
    return c.x + n.x * (c.y + n.y * (c.z + n.z * k));
}

// The cell and cascade of a cell dispatch's invocation id (x, the rest); false past the end.
fn light_volume_cell_of(id: vec2<u32>) -> vec4<u32> {
    let n = light_volume_cells_of();
    let rest = id.y;
    return vec4<u32>(id.x, rest % n.y, (rest / n.y) % n.z, rest / (n.y * n.z));
}

fn light_volume_in_cells(id: vec2<u32>) -> bool {
    let n = light_volume_cells_of();
    return id.x < n.x && id.y < n.y * n.z * environment.light_volume.cascades;
}

// Centre of cell c of cascade k (LightVolumeCascade::centre).
fn light_volume_centre(c: vec3<u32>, k: u32) -> vec3<f32> {
    let v = environment.light_volume;
    return v.cascade_min_m[k].xyz + (vec3<f32>(c) + 0.5) * v.cascade_cell_m[k].xyz;
}

// Cell inputs (inputs::cell_inputs): the mean field's extinction averaged over eight points, scaled,
// and the sun's irradiance through the air times exp(-tau') of the mean field toward the sun.
@compute @workgroup_size(8, 8)
fn light_volume_cells(@builtin(global_invocation_id) id: vec3<u32>) {
    light_volume_cell_inputs(id.xy);
}

// The cells' inputs of one slice of the swept cascade's rows: every LIGHT_VOLUME_CELL_SLICES-th,
// from the frame's cell_slice. A warm turn updates one slice and keeps the others' inputs from
// the last turns (under a second old: the clouds move 0.13 m a frame at 60 fps in an 8 m/s wind).
@compute @workgroup_size(8, 8)
fn light_volume_cells_slice(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = light_volume_cells_of();
    let row = id.y * LIGHT_VOLUME_CELL_SLICES + volume_solve.cell_slice;
    if row >= n.y * n.z * volume_solve.swept {
        return;
    }
    light_volume_cell_inputs(vec2<u32>(id.x, row + n.y * n.z * volume_solve.first_swept));
}

fn light_volume_cell_inputs(id: vec2<u32>) {
    if !light_volume_in_cells(id) {
        return;
    }
    let v = environment.light_volume;
    let ck = light_volume_cell_of(id);
    let c = ck.xyz;
    let k = ck.w;
    let p = light_volume_centre(c, k);
    let cell_m = v.cascade_cell_m[k].xyz;
    var sum = 0.0;
    for (var s = 0u; s < 8u; s++) {
        let corner = vec3<f32>(f32(s & 1u), f32((s >> 1u) & 1u), f32((s >> 2u) & 1u));
        sum += field_extinction_mean(p + (corner * 2.0 - 1.0) * LIGHT_VOLUME_CELL_SAMPLE_OFFSET * cell_m);
    }
    let thinning = v.optics.z;
    let extinction = thinning * sum / 8.0;
    let sun = environment.sun_direction;
    let top_m = v.cascade_min_m[k].y + cell_m.y * f32(v.cells.y);
    let length_m = clamp((top_m - p.y) / max(sun.y, LIGHT_VOLUME_BEAM_MIN_SUN_Y), 0.0, LIGHT_VOLUME_BEAM_PATH_MAX_M);
    let tau = field_optical_depth_mean(p, sun, vec3<f32>(0.0, length_m, LIGHT_VOLUME_BEAM_GROWTH), v.beam_steps, 0.5);
    let beam = environment_sun_irradiance(p) * exp(-thinning * tau);
    var cell = vec4<f32>(beam, extinction);
    if v.enabled == 0u {
        cell = vec4<f32>(0.0);
    }
    volume_cells[light_volume_index(c, k)] = cell;
}

fn light_volume_luminance(c: vec3<u32>, k: u32) -> f32 {
    return dot(volume_radiance[light_volume_index(c, k)].rgb, LIGHT_VOLUME_LUMINANCE);
}

// Transport coefficient sigma_tr of a cell's scaled extinction (Diffusion::transport).
fn light_volume_transport(extinction: f32) -> f32 {
    let o = environment.light_volume.optics;
    return extinction * (1.0 - o.x * o.y);
}

// solve::flux_limited_diffusion.
fn light_volume_flux_limited(transport: f32, relative: f32) -> f32 {
    return 1.0 / max(max(3.0 * transport, relative), 1e-30);
}

// The gradient of the radiance's luminance at cell c of cascade k (central differences, one-sided
// at the faces) in xyz, and the largest luminance of the cells it reads in w
// (Diffusion::luminance_gradient).
fn light_volume_gradient(c: vec3<u32>, k: u32) -> vec4<f32> {
    let v = environment.light_volume;
    let h = v.cascade_cell_m[k].xyz;
    var gradient = vec3<f32>(0.0);
    var brightest = light_volume_luminance(c, k);
    for (var axis = 0u; axis < 3u; axis++) {
        let lo_i = max(c[axis], 1u) - 1u;
        let hi_i = min(c[axis] + 1u, v.cells[axis] - 1u);
        var a = c;
        var b = c;
        a[axis] = lo_i;
        b[axis] = hi_i;
        brightest = max(brightest, max(light_volume_luminance(a, k), light_volume_luminance(b, k)));
        if hi_i > lo_i {
            gradient[axis] = (light_volume_luminance(b, k) - light_volume_luminance(a, k)) / (f32(hi_i - lo_i) * h[axis]);
        }
    }
    return vec4<f32>(gradient, brightest);
}

// The flux-limited diffusion coefficient of every cell from the radiance's luminance gradient over
// the brightest cell it reads (Diffusion::limited_diffusion).
@compute @workgroup_size(8, 8)
fn light_volume_limit(@builtin(global_invocation_id) id: vec3<u32>) {
    if !light_volume_in_swept_cells(id.xy) {
        return;
    }
    let v = environment.light_volume;
    let ck = light_volume_swept_cell_of(id.xy);
    let c = ck.xyz;
    let k = ck.w;
    let gradient = light_volume_gradient(c, k);
    let relative = length(gradient.xyz) / max(gradient.w, 1e-12);
    let height_m = v.cascade_cell_m[k].y * f32(v.cells.y);
    let extinction = volume_cells[light_volume_index(c, k)].w;
    volume_diffusion[light_volume_index(c, k)] = min(light_volume_flux_limited(light_volume_transport(extinction), relative), height_m);
}

// The beam's current in cell i per unit of the beam's direction along an axis: its current B along
// that axis is this times -sun[axis] (Diffusion::beam_current).
fn light_volume_beam(i: u32) -> vec3<f32> {
    let o = environment.light_volume.optics;
    let cell = volume_cells[i];
    return 3.0 * volume_diffusion[i] * o.x * cell.w * o.y * cell.rgb / (4.0 * PI);
}

// The radiance entering the top (step 1) or bottom (-1) face of cell i as alpha I0 + beta
// (Diffusion::entering): the sky from above as the viewpoint sees it (the path tracer's sky).
struct LightVolumeEntering {
    alpha: vec3<f32>,
    beta: vec3<f32>,
}

fn light_volume_entering(i: u32, step: i32) -> LightVolumeEntering {
    if step > 0 {
        return LightVolumeEntering(vec3<f32>(0.0), environment_sky_irradiance_up(environment.viewpoint_m) / PI);
    }
    if frame.has_ground == 0u {
        return LightVolumeEntering(vec3<f32>(0.0), environment_sky_radiance(vec3<f32>(0.0, -1.0, 0.0)));
    }
    let albedo = frame.ground_albedo;
    let direct = volume_cells[i].rgb * max(environment.sun_direction.y, 0.0);
    let denominator = 1.0 + albedo;
    return LightVolumeEntering(2.0 * albedo / denominator, albedo * direct / (PI * denominator));
}

// Outward current through the top or bottom face of cell i as coefficient I0 + constant
// (Diffusion::face_current).
fn light_volume_face_current(i: u32, step: i32, h_y: f32) -> array<vec3<f32>, 2> {
    let conductance = 2.0 * volume_diffusion[i] / h_y;
    let entering = light_volume_entering(i, step);
    let outward_beam = f32(step) * light_volume_beam(i) * -environment.sun_direction.y;
    let scale = 1.0 / (1.0 + 2.0 * conductance);
    return array<vec3<f32>, 2>(conductance * (1.0 - entering.alpha) * scale, (outward_beam - conductance * entering.beta) * scale);
}

fn light_volume_harmonic(a: f32, b: f32) -> f32 {
    return 2.0 * a * b / max(a + b, 1e-30);
}

// Solves column (x, z) of cascade k with its neighbours held (Diffusion::relax_column), by the
// Thomas algorithm with a diagonal and right side per channel. Each cell's beam current and
// diffusion coefficient are read once and carried to the next cell up, where they are the one
// below's.
fn light_volume_relax_column(x: u32, z: u32, k: u32, coupled: bool) {
    let v = environment.light_volume;
    let n = v.cells;
    let h = v.cascade_cell_m[k].xyz;
    let beam_direction = -environment.sun_direction;
    var c_prime: array<vec3<f32>, LIGHT_VOLUME_MAX_COLUMN_CELLS>;
    var d_prime: array<vec3<f32>, LIGHT_VOLUME_MAX_COLUMN_CELLS>;
    var previous_c = vec3<f32>(0.0);
    var previous_d = vec3<f32>(0.0);
    // The beams and diffusion coefficients of the cells below (0), here (1) and above (2).
    let first = light_volume_index(vec3<u32>(x, 0u, z), k);
    var beams = array<vec3<f32>, 3>(vec3<f32>(0.0), light_volume_beam(first), vec3<f32>(0.0));
    var diffusions = array<f32, 3>(0.0, volume_diffusion[first], 0.0);
    for (var y = 0u; y < n.y; y++) {
        let c = vec3<u32>(x, y, z);
        let i = light_volume_index(c, k);
        if y + 1u < n.y {
            let above = light_volume_index(vec3<u32>(x, y + 1u, z), k);
            beams[2] = light_volume_beam(above);
            diffusions[2] = volume_diffusion[above];
        }
        let d = diffusions[1];
        let cell = volume_cells[i];
        var diag = vec3<f32>(cell.w * (1.0 - v.optics.x));
        var rhs = v.optics.x * cell.w * cell.rgb / (4.0 * PI);
        var lower = 0.0;
        var upper = 0.0;
        for (var a = 0u; a < 2u; a++) {
            let axis = a * 2u;
            for (var s = 0; s < 2; s++) {
                let step = s * 2 - 1;
                let neighbour = i32(c[axis]) + step;
                if neighbour < 0 || neighbour >= i32(n[axis]) {
                    continue;
                }
                var nc = c;
                nc[axis] = u32(neighbour);
                let j = light_volume_index(nc, k);
                let face_b = 0.5 * (beams[1] + light_volume_beam(j)) * beam_direction[axis];
                rhs -= f32(step) * face_b / h[axis];
                if coupled {
                    let conductance = light_volume_harmonic(d, volume_diffusion[j]) / (h[axis] * h[axis]);
                    diag += vec3<f32>(conductance);
                    rhs += conductance * volume_radiance[j].rgb;
                }
            }
        }
        for (var s = 0; s < 2; s++) {
            let step = s * 2 - 1;
            let neighbour = i32(y) + step;
            if neighbour < 0 || neighbour >= i32(n.y) {
                let face = light_volume_face_current(i, step, h.y);
                diag += face[0] / h.y;
                rhs -= face[1] / h.y;
                continue;
            }
            let face_b = 0.5 * (beams[1] + beams[s * 2]) * beam_direction.y;
            rhs -= f32(step) * face_b / h.y;
            let conductance = light_volume_harmonic(d, diffusions[s * 2]) / (h.y * h.y);
            diag += vec3<f32>(conductance);
            if step < 0 {
                lower = -conductance;
            } else {
                upper = -conductance;
            }
        }
        let m = diag - lower * previous_c;
        previous_c = upper / m;
        previous_d = (rhs - lower * previous_d) / m;
        c_prime[y] = previous_c;
        d_prime[y] = previous_d;
        beams = array<vec3<f32>, 3>(beams[1], beams[2], vec3<f32>(0.0));
        diffusions = array<f32, 3>(diffusions[1], diffusions[2], 0.0);
    }
    var next = vec3<f32>(0.0);
    for (var r = 0u; r < n.y; r++) {
        let y = n.y - 1u - r;
        var value = d_prime[y];
        if r > 0u {
            value -= c_prime[y] * next;
        }
        next = value;
        volume_radiance[light_volume_index(vec3<u32>(x, y, z), k)] = vec4<f32>(max(value, vec3<f32>(0.0)), 0.0);
    }
}

// Relaxes the columns of one colour ((x + z) % 2 == colour) of every cascade swept: invocation
// (i, row) takes column x = 2 i + (colour + z) % 2 of its row, so no invocation idles on the
// other colour's columns (a dispatch over half of x).
fn light_volume_relax(id: vec2<u32>, colour: u32, coupled: bool) {
    let n = light_volume_cells_of();
    if id.y >= n.z * volume_solve.swept {
        return;
    }
    let z = id.y % n.z;
    let k = id.y / n.z + volume_solve.first_swept;
    let x = 2u * id.x + (colour + z) % 2u;
    if x >= n.x {
        return;
    }
    light_volume_relax_column(x, z, k, coupled);
}

@compute @workgroup_size(8, 8)
fn light_volume_relax_red(@builtin(global_invocation_id) id: vec3<u32>) {
    light_volume_relax(id.xy, 0u, true);
}

@compute @workgroup_size(8, 8)
fn light_volume_relax_black(@builtin(global_invocation_id) id: vec3<u32>) {
    light_volume_relax(id.xy, 1u, true);
}

@compute @workgroup_size(8, 8)
fn light_volume_relax_red_uncoupled(@builtin(global_invocation_id) id: vec3<u32>) {
    light_volume_relax(id.xy, 0u, false);
}

@compute @workgroup_size(8, 8)
fn light_volume_relax_black_uncoupled(@builtin(global_invocation_id) id: vec3<u32>) {
    light_volume_relax(id.xy, 1u, false);
}

// Writes texel t of the table as rgba16float (two halves to a u32, the first in the low bits).
fn light_volume_store(t: vec3<u32>, value: vec4<f32>) {
    let n = light_volume_cells_of();
    let row_texels = (n.x + LIGHT_VOLUME_ROW_TEXELS - 1u) / LIGHT_VOLUME_ROW_TEXELS * LIGHT_VOLUME_ROW_TEXELS;
    let packed = vec2<u32>(light_volume_half(value.x) | (light_volume_half(value.y) << 16u), light_volume_half(value.z) | (light_volume_half(value.w) << 16u));
    volume_table_out[(t.z * n.y + t.y) * row_texels + t.x] = packed;
}

// The IEEE half-precision bits of x, rounded to nearest, below the smallest normal half (6.1e-5)
// flushed to zero and above the largest (65504) clamped to it (WGSL's pack2x16float needs a
// capability not every adapter offers).
fn light_volume_half(x: f32) -> u32 {
    let bits = bitcast<u32>(x);
    let sign = (bits >> 16u) & 0x8000u;
    let exponent = i32((bits >> 23u) & 0xffu) - 112;
    if exponent <= 0 {
        return sign;
    }
    let half = (u32(exponent) << 10u) + (((bits & 0x7fffffu) + 0x1000u) >> 13u);
    return sign | min(half, 0x7bffu);
}

// A cell's weight in the table's interpolation (read::interpolation_weight).
fn light_volume_weight(extinction: f32, h: vec3<f32>) -> f32 {
    return clamp(extinction * min(h.x, min(h.y, h.z)), LIGHT_VOLUME_MIN_WEIGHT, 1.0);
}

// The table the environment reads (Diffusion::relative_current): I0 per cell, and the current
// J = -D grad I0 + B of luminance over I0's luminance, each times the cell's weight, which alpha
// holds, so that filtering interpolates them weighted.
@compute @workgroup_size(8, 8)
fn light_volume_export(@builtin(global_invocation_id) id: vec3<u32>) {
    if !light_volume_in_swept_cells(id.xy) {
        return;
    }
    let v = environment.light_volume;
    let ck = light_volume_swept_cell_of(id.xy);
    let c = ck.xyz;
    let k = ck.w;
    let i = light_volume_index(c, k);
    let h = v.cascade_cell_m[k].xyz;
    let beam = dot(light_volume_beam(i), LIGHT_VOLUME_LUMINANCE) * -environment.sun_direction;
    let current = -volume_diffusion[i] * light_volume_gradient(c, k).xyz + beam;
    let radiance = volume_radiance[i].rgb;
    var relative = current / max(dot(radiance, LIGHT_VOLUME_LUMINANCE), 1e-12);
    relative *= min(1.0, LIGHT_VOLUME_MAX_RELATIVE_CURRENT / max(length(relative), 1e-20));
    let weight = light_volume_weight(volume_cells[i].w, h);
    let slice = c.z + v.cells.z * k;
    light_volume_store(vec3<u32>(c.x, c.y, slice), vec4<f32>(radiance, 1.0) * weight);
    light_volume_store(vec3<u32>(c.x, c.y, slice + v.cells.z * v.cascades), vec4<f32>(relative, 1.0) * weight);
    if c.y == 0u {
        light_volume_store(vec3<u32>(c.x, 0u, slice + 2u * v.cells.z * v.cascades), vec4<f32>(light_volume_bottom_irradiance(i, h.y), 1.0));
    }
}

// The diffuse irradiance leaving the grid downward through the bottom face of bottom-row cell i
// (Diffusion::bottom_irradiance): pi L entering from below plus the outward flux 4 pi J . n.
fn light_volume_bottom_irradiance(i: u32, h_y: f32) -> vec3<f32> {
    let face = light_volume_face_current(i, -1, h_y);
    let entering = light_volume_entering(i, -1);
    let radiance = volume_radiance[i].rgb;
    return PI * (entering.alpha * radiance + entering.beta) + 4.0 * PI * (face[0] * radiance + face[1]);
}

// Scrolls the solution of a grid recentred by whole cells (LightVolumePass), so that the solve
// starts warm instead of cold: each cell takes the radiance the last solution held at the same
// place, and a cell new to the grid that of the nearest old cell in its row. The last solution
// is read from the table's buffer, where the pass copied it (the export overwrites it later in
// the frame): two of its texels hold one cell's vec4<f32>.
@compute @workgroup_size(8, 8)
fn light_volume_scroll(@builtin(global_invocation_id) id: vec3<u32>) {
    if !light_volume_in_cells(id.xy) {
        return;
    }
    let c = light_volume_cell_of(id.xy);
    let last = vec2<i32>(light_volume_cells_of().xz) - 1;
    let at = clamp(vec2<i32>(c.xz) + volume_solve.shift_cells[c.w].xy, vec2<i32>(0), last);
    let texel = 2u * light_volume_index(vec3<u32>(u32(at.x), c.y, u32(at.y)), c.w);
    let radiance = vec4<f32>(bitcast<vec2<f32>>(volume_table_out[texel]), bitcast<vec2<f32>>(volume_table_out[texel + 1u]));
    volume_radiance[light_volume_index(c.xyz, c.w)] = radiance;
}
