// The ray marcher's light paths from a point in the clouds, toward the sun and away from it, with
// their step counts as arguments: no bindings of their own, so the probe evaluates them as the
// march does (raymarch/light.rs is their CPU twin).

// Optical depth toward the sun from p, through the eroded density's mean over the detail noise
// (field_extinction_mean; Schneider 2015's cheap light samples read the coarse one, its upper
// bound): `steps` segments whose lengths double, covering the way to the top of the layers
// (MARCH_SUN_PATH_MIN_M..MARCH_SUN_PATH_MAX_M, raymarch::SUN_PATH_M) (VolumeCloud samples the sun
// path at 0.5, 1.5, 3, 6, 12 units with weights 1, 1, 2, 4, 8; peers.md).
fn march_sun_optical_depth(p: vec3<f32>, steps: u32, jitter: f32) -> f32 {
    let sun = environment_sun_direction();
    var length_m = MARCH_SUN_PATH_MAX_M;
    if field.layer_count > 0u {
        length_m = clamp(field_below(p, sun, field.layer_top_m).y, MARCH_SUN_PATH_MIN_M, MARCH_SUN_PATH_MAX_M);
    }
    return field_optical_depth_mean(p, sun, vec3<f32>(0.0, length_m, 2.0), steps, jitter);
}

// Optical depth away from the sun from p, through the mean density, to where the path leaves the
// layers (the bottom, or the top when the sun is below the horizon), within the sun path's bounds:
// the far side of the slab model. `steps` doubling segments, as toward the sun.
fn march_back_optical_depth(p: vec3<f32>, steps: u32, jitter: f32) -> f32 {
    let away = -environment_sun_direction();
    var length_m = MARCH_SUN_PATH_MAX_M;
    if field.layer_count > 0u {
        let below = field_below(p, away, field.layer_bottom_m);
        let through_top = field_below(p, away, field.layer_top_m).y;
        let to_bottom = select(through_top, below.x, below.x <= below.y && below.x > 0.0);
        length_m = clamp(to_bottom, MARCH_SUN_PATH_MIN_M, MARCH_SUN_PATH_MAX_M);
    }
    return field_optical_depth_mean(p, away, vec3<f32>(0.0, length_m, 2.0), steps, jitter);
}
