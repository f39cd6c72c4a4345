// Hi-height traversal (field/hiheight.rs builds the pyramid): how far along a ray the layers are
// provably empty, stepping up and down the max pyramid as hi-Z screen-space reflections do.

struct HiHeightCell {
    top_m: f32,  // highest possible cloud altitude of the layer over the cell
    exit_t: f32, // ray parameter where the ray leaves the cell horizontally
}

// Level-`level` cell of layer `layer` holding point p, and where the ray o + t d leaves it.
fn hiheight_cell(layer: FieldLayer, channel: u32, o: vec3<f32>, d: vec3<f32>, p: vec3<f32>, level: u32) -> HiHeightCell {
    let info = field.hiheight_levels[level];
    let base = field.hiheight_levels[0];
    let dims0 = vec2<i32>(i32(base.y), i32(base.z));
    let wind = layer.wind_m_per_s * field.time_s;
    let uv = (p.xz - wind) / field.weather_extent_m + layer.weather_offset;
    let cell0 = vec2<i32>(floor(uv * vec2<f32>(dims0) - 0.5));
    let wrapped = ((cell0 % dims0) + dims0) % dims0;
    let cell = wrapped >> vec2<u32>(level);
    let top = field_hiheight[info.x + u32(cell.y) * info.y + u32(cell.x)][channel];
    // The level-0 cells this cell covers, unwrapped around cell0, then in world metres.
    let lo = cell0 - wrapped + (cell << vec2<u32>(level));
    let hi = cell0 - wrapped + min((cell + 1) << vec2<u32>(level), dims0);
    let to_world = field.weather_extent_m / vec2<f32>(dims0);
    let world_lo = (vec2<f32>(lo) + 0.5 - layer.weather_offset * vec2<f32>(dims0)) * to_world + wind;
    let world_hi = (vec2<f32>(hi) + 0.5 - layer.weather_offset * vec2<f32>(dims0)) * to_world + wind;
    let inv = 1.0 / d.xz;
    let exits = select((world_lo - o.xz) * inv, (world_hi - o.xz) * inv, d.xz > vec2<f32>(0.0));
    let exit_x = select(exits.x, FIELD_NO_HIT, abs(d.x) < 1.0e-9);
    let exit_z = select(exits.y, FIELD_NO_HIT, abs(d.z) < 1.0e-9);
    return HiHeightCell(top, min(exit_x, exit_z));
}

// Ray parameter where the ray, found above altitude `top_m` at t, first comes down to it. Rounding
// can put a ray that is skimming the altitude on the wrong side of it, so whenever the ray's stretch
// below `top_m` has begun or is under way at t, this answers t: never skip, when in doubt.
fn hiheight_descent_t(o: vec3<f32>, d: vec3<f32>, t: f32, top_m: f32) -> f32 {
    let below = field_below(o, d, top_m);
    if below.x >= below.y || below.y <= t {
        return FIELD_NO_HIT;
    }
    return max(below.x, t);
}

// The layers hold no cloud on [t, field_empty_until(o, d, t, t_end)): climbs the pyramid while
// the ray's cells are empty and steps down where they may hold cloud, until a level-0 cell may.
fn field_empty_until(o: vec3<f32>, d: vec3<f32>, t: f32, t_end: f32) -> f32 {
    let levels = field.hiheight_level_count;
    var level = min(4u, levels - 1u);
    var t_cur = t;
    for (var iteration = 0u; iteration < 32u; iteration++) {
        if t_cur >= t_end {
            return t_end;
        }
        // Look the cell up just past t_cur, so that a t_cur on a cell boundary finds the cell the
        // ray is entering; t_cur itself stays exact, so no sample beyond a boundary is skipped.
        let p = o + d * (t_cur + 1.0e-3 + 1.0e-6 * t_cur);
        let h = field_altitude_m(p);
        var empty = true;
        var exit = FIELD_NO_HIT;
        for (var i = 0u; i < field.layer_count; i++) {
            let cell = hiheight_cell(field.layers[i], i, o, d, p, level);
            exit = min(exit, cell.exit_t);
            if h <= cell.top_m {
                empty = false;
            } else {
                exit = min(exit, hiheight_descent_t(o, d, t_cur, cell.top_m));
            }
        }
        if empty {
            t_cur = max(exit, t_cur + 1.0e-3 + 1.0e-6 * t_cur);
            level = min(level + 1u, levels - 1u);
        } else if level == 0u {
            break;
        } else {
            level -= 1u;
        }
    }
    return t_cur;
}
