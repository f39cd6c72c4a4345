// The sprite pass (sprites/render.rs): every sprite of the view's sorted list, back to front, as
// a textured quad blended over the ones behind it. Shading follows Wang 2003 with physically
// derived numbers (sprites/shading.rs, the CPU specification), or, for the field's sprites in a
// frame with a light volume, as the ray marcher lights the field; the in-cloud lock, fades and
// formation are per vertex.

// One sprite (sprites::render::GpuSprite).
struct Sprite {
    position_m: vec3<f32>,      // centre at time 0, in its layer's wind frame, m
    layer: u32,                 // the layer whose wind carries it; 4 or more: none
    size_m: vec2<f32>,          // width, height
    rotation_rad: f32,          // about the view axis
    texture: u32,               // tile of the puff sheet, 0..15
    cloud: u32,                 // index into `clouds`
    optical_depth: f32,         // through its densest column (cloud_set.rs); may exceed the blend's cap
    directional: f32,           // its shading group's directional factor, 0..1
    sun_transmittance: f32,     // direct sun reaching its group, 0..1 (silver lining)
}

// One cloud's colour levels (sprites::render::GpuCloud).
struct Cloud {
    colors: array<vec4<f32>, 5>, // ambient fraction (rgb) and opacity (a) of each level
    level_heights: vec4<f32>,    // height fractions of levels 0..3
    top_level_height: f32,       // height fraction of level 4
    bottom_y_m: f32,             // world y of the cloud's bottom
    height_m: f32,               // bottom to top
    pad: f32,
}

// Settings every view shares (sprites::render::SpriteSettings).
struct Settings {
    wind_offset_m: array<vec4<f32>, 4>, // xy: each layer's drift (east, south) at this time, m
    ambient_override: vec3<f32>,        // replaces the maximum ambient colour when set
    ambient_overridden: u32,
    directional_override: vec3<f32>,    // replaces the maximum directional colour when set
    directional_overridden: u32,
    phase_lobes: vec4<f32>,             // the scene's phase function (phase.wgsl)
    albedo: f32,                        // single-scattering albedo
    lit_by_volume: u32,                 // 1: field sprites read the frame's light volume
    blend_optical_depth_max: f32,       // a puff's opacity stops growing here (its soft rim)
    pad2: f32,
    slab_params: vec4<f32>,             // the forward peak's beam (slab.wgsl, SunSlab)
}

@group(3) @binding(0) var<uniform> view: View;
@group(3) @binding(1) var<uniform> settings: Settings;
@group(3) @binding(2) var<storage, read> sprites: array<Sprite>;
@group(3) @binding(3) var<storage, read> clouds: array<Cloud>;
@group(3) @binding(4) var<storage, read> order: array<u32>;
@group(3) @binding(5) var puffs: texture_2d<f32>;
@group(3) @binding(6) var puff_sampler: sampler;
@group(3) @binding(7) var host_depth: texture_2d<f32>;

struct Varying {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,                 // on the puff sheet
    @location(1) diffuse: vec3<f32>,            // Wang's ambient + directional radiance
    @location(2) single: vec3<f32>,             // albedo x the sun's irradiance reaching the sprite (Wang: its group's)
    @location(9) tau_sun: f32,                  // volume: the optical depth toward the sun outside the sprite
    @location(7) thin_only: f32,                // 1: Wang's model (the sun lights thin parts only); 0: physics
    @location(8) position_m: vec3<f32>,         // world position (the view ray's direction, per fragment)
    @location(10) disc: vec2<f32>,              // on the puff's disc, in radii (its sphere's chords)
    @location(11) sun_local: vec3<f32>,         // the sun in the quad's frame: right, up, toward the eye
    @location(3) opacity: f32,                  // fades and the level's opacity
    @location(6) optical_depth: f32,            // the sprite's, through its densest column
    @location(4) distance_m: f32,
    @location(5) soft_m: f32,
}

// Sheet layout (sprites/textures.rs).
const SHEET_TILES: f32 = 4.0;
// Samples of a vertex's light path toward the sun (the ray marcher's High preset's, raymarch::preset).
const SPRITE_LIGHT_STEPS: u32 = 6u;

// Where the sprite's centre is now: its wind frame moved by its layer's drift.
fn sprite_centre(s: Sprite) -> vec3<f32> {
    if s.layer >= 4u {
        return s.position_m;
    }
    let drift = settings.wind_offset_m[s.layer].xy;
    return s.position_m + vec3<f32>(drift.x, 0.0, drift.y);
}

// Wang 2003's maximum ambient and directional colours, or the scene's overrides: the sky's mean
// radiance from above and the sun's irradiance over pi, times the albedo (shading.rs). Selects,
// not branches: lavapipe recompiles a shader with a branch on uniform values alone each time they
// are uploaded, and leaks the compilation (docs/hardening.md, "Soak").
fn sprite_max_colours(p: vec3<f32>) -> array<vec3<f32>, 2> {
    let ambient = settings.albedo * environment_sky_mean_radiance_up(p);
    let directional = settings.albedo * environment_sun_irradiance(p) / PI;
    return array<vec3<f32>, 2>(
        select(ambient, settings.ambient_override, settings.ambient_overridden == 1u),
        select(directional, settings.directional_override, settings.directional_overridden == 1u),
    );
}

@vertex
fn vs_sprite(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> Varying {
    let s = sprites[order[i]];
    let centre = sprite_centre(s);
    let to_eye = view.eye_m - centre;
    let d = max(length(to_eye), 1e-3);
    // Far sprites face the eye; within the lock distance they turn to face along the view (Wang's
    // lock), blending over one more lock distance so nothing pops.
    let lock = 1.0 - smoothstep(view.lock_distance_m, 2.0 * view.lock_distance_m, d);
    let normal = normalize(mix(to_eye / d, -view.forward, lock) + vec3<f32>(0.0, 1e-5, 0.0));
    var up_hint = vec3<f32>(0.0, 1.0, 0.0);
    if abs(normal.y) > 0.99 {
        up_hint = vec3<f32>(0.0, 0.0, -1.0);
    }
    let right = normalize(cross(up_hint, normal));
    let up = cross(normal, right);
    let corner = vec2<f32>(f32(v & 1u), f32(v >> 1u)) * 2.0 - 1.0;
    let turn = vec2<f32>(cos(s.rotation_rad), sin(s.rotation_rad));
    let turned = vec2<f32>(corner.x * turn.x - corner.y * turn.y, corner.x * turn.y + corner.y * turn.x);
    let p = centre + (right * turned.x * s.size_m.x + up * turned.y * s.size_m.y) * 0.5;

    // Fades: the sprite vanishes as the eye passes through it (Wang 2003; FlightGear fades sprites
    // between 100 m and 10 m from the eye); a locked sprite seen edge-on turns transparent (Wang: the dot
    // product of the lock angle and the angle to the camera); distant clouds fade out.
    // A locked sprite faces along the view, so the eye passes through it when its plane reaches
    // the eye: it fades with its distance ahead, and stays whole until then (no hole opens).
    let radius = 0.5 * max(s.size_m.x, s.size_m.y);
    let ahead = dot(-to_eye, view.forward);
    let through = mix(smoothstep(0.1 * radius, 0.6 * radius, d), smoothstep(0.0, 0.35 * radius, ahead), lock);
    let edge_on = mix(1.0, abs(dot(normal, to_eye / d)), lock);
    let horizontal = length(to_eye.xz);
    let far = 1.0 - smoothstep(view.fade_start_m, view.fade_end_m, horizontal);

    let c = clouds[s.cloud];
    let heights = array<f32, 5>(c.level_heights.x, c.level_heights.y, c.level_heights.z, c.level_heights.w, c.top_level_height);
    let level = sprite_level(c.colors, heights, clamp((p.y - c.bottom_y_m) / max(c.height_m, 1.0), 0.0, 1.0));
    let maxima = sprite_max_colours(p);
    let wang_diffuse = level.rgb * maxima[0] + s.directional * maxima[1];
    let wang_single = settings.albedo * environment_sun_irradiance(p) * s.sun_transmittance;
    // Field sprites in a frame with a light volume: lit as the ray marcher lights a sample of
    // the field (fs_sprite): the volume's diffuse light, and the sun's beam (single scattering
    // and the forward peak) after the optical depth toward the sun from where the beam enters
    // the sprite's matter, by the ray marcher's own light path (march_sun_optical_depth, through
    // the eroded density's mean: the cloud shadow map's coarse density is its upper bound and
    // dimmed the beam by 1.2-2 times the matter), read halfway between the sprite's centre and
    // this corner, so a sprite shades from its sunlit to its shadowed side. sprite_beam dims it
    // through the sprite itself, so the path starts at the sunward side of the sprite's sphere
    // through q, sqrt(r^2 - |q - centre|^2) = r / sqrt(2) sunward of q (corners lie r sqrt(2)
    // out).
    let q = mix(centre, p, 0.5);
    let half_chord_m = radius * 0.70710678;
    let volume = s.layer < 4u && settings.lit_by_volume == 1u && environment_has_light_volume();
    let tau_sun = march_sun_optical_depth(q + environment_sun_direction() * half_chord_m, SPRITE_LIGHT_STEPS, 0.5);
    let volume_single = settings.albedo * environment_sun_irradiance(q);

    var out: Varying;
    out.clip = sprite_clip(view, p);
    let tile = vec2<f32>(f32(s.texture % 4u), f32(s.texture / 4u));
    out.uv = (tile + corner * vec2<f32>(0.5, -0.5) + 0.5) / SHEET_TILES;
    out.diffuse = wang_diffuse;
    out.single = select(wang_single, volume_single, volume);
    out.thin_only = select(1.0, 0.0, volume);
    out.tau_sun = tau_sun;
    out.position_m = p;
    out.disc = turned;
    let sun = environment_sun_direction();
    out.sun_local = vec3<f32>(dot(sun, right), dot(sun, up), dot(sun, normal));
    out.opacity = level.a * through * edge_on * far;
    out.optical_depth = s.optical_depth;
    out.distance_m = length(p - view.eye_m);
    out.soft_m = 0.25 * radius;
    return out;
}

// Half the chord through a puff's sphere at `disc` on its disc, in radii.
fn sprite_half_chord(disc: vec2<f32>) -> f32 {
    return sqrt(max(1.0 - dot(disc, disc), 0.0));
}

// Nodes of the beam's quadrature along a puff's chord.
const BEAM_NODES: u32 = 4u;

// The sun's beam that a puff scatters toward the eye through one point of its disc, per unit of
// the beam's irradiance times the albedo and per unit of the puff's opacity there, after `tau_sun`
// of cloud toward the sun outside it: the ray marcher's per-sample beam (single scattering and the
// forward peak's beam, slab_peak_beam) averaged over where the eye's light is scattered along the
// chord. The puff is a sphere of uniform matter, its column `tau` along the chord through `disc`
// (in radii); a point at optical depth t from the eye's side is reached through the matter
// between it and the sphere's surface toward the sun (`sun_local`, in the quad's frame, z toward
// the eye), so a puff's sunlit side is lit and its far side shadowed by the puff itself, and a
// dense puff against the sun passes only what its whole depth passes. The chord's points are
// taken at equal shares of the light the eye gets from it (t = -ln(1 - u (1 - e^-tau))).
fn sprite_beam(tau: f32, disc: vec2<f32>, sun_local: vec3<f32>, c: f32, tau_sun: f32) -> f32 {
    let slab = SlabModel(settings.phase_lobes, settings.slab_params);
    let half = sprite_half_chord(disc);
    let per_radius = tau / max(2.0 * half, 1e-3);
    let seen = 1.0 - exp(-tau);
    let phase = phase_eval(settings.phase_lobes, c);
    var sum = 0.0;
    for (var i = 0u; i < BEAM_NODES; i++) {
        let t = -log(1.0 - (f32(i) + 0.5) / f32(BEAM_NODES) * seen);
        let point = vec3<f32>(disc, half - t / max(per_radius, 1e-6));
        let b = dot(point, sun_local);
        let to_surface = -b + sqrt(max(b * b - dot(point, point) + 1.0, 0.0));
        let through = tau_sun + per_radius * to_surface;
        sum += phase * exp(-through) + slab_peak_beam(slab, c, through);
    }
    return sum / f32(BEAM_NODES);
}

@fragment
fn fs_sprite(in: Varying) -> SpriteTargets {
    // The sheet holds column density normalised to 1 (sprites/textures.rs).
    let cover = textureSample(puffs, puff_sampler, in.uv).r;
    let texel = in.clip.xy;
    let depth = textureLoad(host_depth, vec2<i32>(sprite_frame_pixel(texel)), 0).x;
    let fade = sprite_host_fade(depth, texel, in.distance_m, in.soft_m);
    // A select, not a branch on the uniform alone (sprite_max_colours says why).
    let visible = in.opacity * select(1.0, fade, view.host_depth_test == 1u);
    // The puff's opacity stops at the blend's cap, so that its rim stays soft however dense its
    // cell (sprites/textures.rs tests the rim there); the light it sends per unit of opacity is
    // its whole matter's (sprite_beam): a dense puff against the sun passes only what its full
    // depth passes (with the cap's depth of 3 in its light too, every dense puff against the sun
    // scattered p tau e^-tau = 0.15 p of the beam).
    let tau = in.optical_depth * cover;
    let tau_blend = min(in.optical_depth, settings.blend_optical_depth_max) * cover;
    let alpha = (1.0 - exp(-tau_blend)) * visible;
    // Wang's model: thin parts of a puff scatter the direct sun once toward the eye (premultiplied,
    // E p tau ~ E p alpha for thin matter), its thick core's light is the diffuse term's. Lit from
    // physics: the sun's beam through the sprite, as the ray marcher's samples scatter it.
    let thin = alpha * (1.0 - cover) * (1.0 - cover);
    // The phase function peaks sharply toward the sun: the angle is the fragment's own, not
    // interpolated across a quad that may span tens of degrees.
    let view_dir = normalize(in.position_m - view.eye_m);
    let cos_sun = dot(view_dir, environment_sun_direction());
    let beam = sprite_beam(tau, in.disc, normalize(in.sun_local), cos_sun, in.tau_sun) * alpha;
    let silver = thin * phase_eval(settings.phase_lobes, cos_sun);
    // The light volume's diffuse light at the fragment's point on the sprite's plane, a smooth
    // function of where it lies in the cloud, as the ray marcher reads it at its samples. Read at
    // the depth of first scattering along the chord through the puff's own sphere, it was
    // brightest at every puff's rim and darkest at its centre, whose point lay a radius out toward
    // the eye, outside the cloud, where the P1 field's flux runs into the cloud and its radiance
    // toward the eye falls: a deck of overlapping discs with rims ("bubble wrap"); read here,
    // cloud-region HDR-FLIP mean over the eight scenes 0.371 -> 0.369, inside the layer 0.461 ->
    // 0.441 (docs/sprites.md).
    let fragment_diffuse = settings.albedo * environment_light_volume_diffuse(in.position_m, -view_dir);
    let diffuse = select(in.diffuse, fragment_diffuse, in.thin_only < 0.5);
    let radiance = alpha * diffuse + mix(beam, silver, in.thin_only) * in.single;
    return sprite_targets(radiance, alpha, in.distance_m);
}
