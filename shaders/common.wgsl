// Shared declarations, prepended to every shader at build time (see render/pipelines.rs).

struct Globals {
    view_proj: mat4x4<f32>,
    // Camera position (xyz).
    eye: vec4<f32>,
    // Direction towards the key light (xyz, unit).
    light_dir: vec4<f32>,
    // Target width and height in pixels, particle dot diameter in pixels, unused.
    viewport: vec4<f32>,
    front_color: vec4<f32>,
    back_color: vec4<f32>,
    // x: checker on (1) or off (0); y: checker squares per UV unit; z: ambient term.
    options: vec4<f32>,
};

@group(0) @binding(0) var<uniform> globals: Globals;

// Colours are computed in linear space and written sRGB-encoded: the target is Rgba8Unorm
// so its bytes are directly what a PNG or the GUI shows.
fn to_srgb(c: vec3<f32>) -> vec3<f32> {
    let x = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    let low = x * 12.92;
    let high = 1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(high, low, x <= vec3<f32>(0.0031308));
}

// Blinn-Phong with one key light and an ambient term; `n` faces the viewer's side.
fn blinn_phong(base: vec3<f32>, n: vec3<f32>, world: vec3<f32>, shininess: f32, specular: f32) -> vec3<f32> {
    let l = normalize(globals.light_dir.xyz);
    let v = normalize(globals.eye.xyz - world);
    let h = normalize(l + v);
    let diffuse = max(dot(n, l), 0.0);
    let spec = select(0.0, pow(max(dot(n, h), 0.0), shininess) * specular, diffuse > 0.0);
    return base * (globals.options.z + (1.0 - globals.options.z) * diffuse) + vec3<f32>(spec);
}
