// Volume-aware blending's merge of two overlapping particle segments (Yusov 2014): no bindings, so
// the probe evaluates it as the particle pass does (particles/blend.rs is its CPU twin).

// The seed's per-pixel record (particles/blend.rs Segment).
struct BlendSegment {
    near_m: f32,
    far_m: f32,
    optical_depth: f32,
    colour: vec3<f32>,
}

fn blend_segment_density(s: BlendSegment) -> f32 {
    return s.optical_depth / max(s.far_m - s.near_m, 1e-6);
}

// blend::merge.
fn blend_merge(a: BlendSegment, b: BlendSegment) -> BlendSegment {
    var first = a;
    var second = b;
    if b.near_m < a.near_m {
        first = b;
        second = a;
    }
    let rho_first = blend_segment_density(first);
    let rho_second = blend_segment_density(second);
    let front_m = min(second.near_m, first.far_m) - first.near_m;
    let isec_m = max(min(first.far_m, second.far_m) - second.near_m, 0.0);
    var back = second;
    var back_m = second.far_m - max(first.far_m, second.near_m);
    if first.far_m > second.far_m {
        back = first;
        back_m = first.far_m - second.far_m;
    }
    let t_front = exp(-rho_first * front_m);
    let rho_isec = rho_first + rho_second;
    let t_isec = exp(-rho_isec * isec_m);
    let t_back = exp(-blend_segment_density(back) * back_m);
    var isec_colour = first.colour;
    if rho_isec > 0.0 {
        isec_colour = (first.colour * rho_first + second.colour * rho_second) / rho_isec;
    }
    let premultiplied = first.colour * (1.0 - t_front) + isec_colour * (1.0 - t_isec) * t_front + back.colour * (1.0 - t_back) * t_front * t_isec;
    let t = t_front * t_isec * t_back;
    var colour = isec_colour;
    if t < 1.0 {
        colour = premultiplied / (1.0 - t);
    }
    return BlendSegment(first.near_m, max(first.far_m, second.far_m), a.optical_depth + b.optical_depth, colour);
}
