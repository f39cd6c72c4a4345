// Puts the clouds over the background this crate draws when there is no host scene: the sky, the
// sun's disc and the ground in the clouds' shadows. final = background * transmittance + cloud
// radiance.

@group(1) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(1) var compose_clouds: texture_2d<f32>;
@group(1) @binding(2) var compose_out: texture_storage_2d<rgba16float, write>;

// Radiance of the sun's disc, a uniform disc of the sun's irradiance: E / (pi r^2) for small r.
fn compose_sun_disc(d: vec3<f32>) -> vec3<f32> {
    if dot(d, frame.sun_direction.xyz) < frame.sun_direction.w {
        return vec3<f32>(0.0);
    }
    let r = frame.sun_irradiance.w;
    return frame.sun_irradiance.xyz / (3.14159265 * r * r);
}

// Samples of the coarse optical depth from the ground through the layers, and again through the
// voxel-grid boxes: uniform segments (unlike the march's doubling ones, which are fine near a point
// inside the cloud), so the clouds far along the ray are sampled as finely as near ones.
const COMPOSE_SHADOW_STEPS: u32 = 24u;

// Coarse optical depth from ground point g toward dir over the ray stretch [span.x, span.y].
fn compose_span_optical_depth(g: vec3<f32>, dir: vec3<f32>, span: vec2<f32>, jitter: f32) -> f32 {
    if span.x >= span.y {
        return 0.0;
    }
    return field_optical_depth_coarse(g, dir, vec3<f32>(span.x, span.y - span.x, 1.0), COMPOSE_SHADOW_STEPS, jitter);
}

// Coarse optical depth of the clouds from ground point g toward dir (upward): the layers, then the
// voxel-grid boxes.
fn compose_optical_depth(g: vec3<f32>, dir: vec3<f32>, jitter: f32) -> f32 {
    let layers = field_layer_interval(g, dir, FIELD_NO_HIT);
    let volumes = field_volume_interval(g, dir, FIELD_NO_HIT);
    return compose_span_optical_depth(g, dir, layers, jitter) + compose_span_optical_depth(g, dir, volumes, jitter);
}

// Radiance leaving the Lambertian ground at g: the sun's and the sky's share of ground_radiance,
// each dimmed by the clouds' diffuse transmittance between the ground and the light (the sun's
// along its slant path: the direct beam and the light the clouds scatter forward, most of it
// within a few degrees of the sun), as the path tracer's ground sees them through the same field.
fn compose_ground(g: vec3<f32>, jitter: f32) -> vec3<f32> {
    let sun = frame.sun_direction.xyz;
    let sun_part = frame.ground_albedo.xyz / 3.14159265 * frame.sun_irradiance.xyz * max(sun.y, 0.0);
    let sky_part = frame.ground_radiance.xyz - sun_part;
    var sun_t = 0.0;
    if sun.y > 0.0 {
        sun_t = frame_diffuse_transmittance(frame, compose_optical_depth(g, sun, jitter));
    }
    let sky_t = frame_diffuse_transmittance(frame, compose_optical_depth(g, field_up(g), jitter));
    return sun_part * sun_t + sky_part * sky_t;
}

@compute @workgroup_size(8, 8)
fn compose_background(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= u32(frame.viewport.x) || id.y >= u32(frame.viewport.y) {
        return;
    }
    let pixel = vec2<f32>(id.xy) + 0.5;
    let o = frame.camera_position.xyz;
    let d = frame_ray_direction(frame, pixel);
    var background = frame_sky_radiance(frame, d) + compose_sun_disc(d);
    let ground_m = field_ground_distance(o, d, frame.ground_albedo.w > 0.5);
    if ground_m < frame.camera_position.w {
        let jitter = frame_pixel_jitter(id.xy, u32(frame.viewport.w));
        background = frame_haze(frame, compose_ground(o + d * ground_m, jitter), 1.0, ground_m);
    }
    let clouds = textureLoad(compose_clouds, vec2<i32>(id.xy), 0);
    textureStore(compose_out, vec2<i32>(id.xy), vec4<f32>(background * clouds.a + clouds.rgb, 1.0));
}
