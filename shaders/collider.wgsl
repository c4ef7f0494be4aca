// Colliders: a shaded sphere whose stripes turn with its spin, and a ground plane with a grid.

struct Solid {
    model: mat4x4<f32>,
    color: vec4<f32>,
    // x: 0 = sphere pattern, 1 = ground grid, 2 = plain (a mesh); y: grid spacing in metres.
    pattern: vec4<f32>,
};

@group(1) @binding(0) var<uniform> solid: Solid;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) object: vec3<f32>,
};

@vertex
fn vs_main(in: VertexIn) -> VertexOut {
    let world = solid.model * vec4<f32>(in.position, 1.0);
    var out: VertexOut;
    out.clip = globals.view_proj * world;
    out.world = world.xyz;
    // The model matrix is a rotation times a uniform scale: it maps normals too.
    out.normal = (solid.model * vec4<f32>(in.normal, 0.0)).xyz;
    out.object = in.position;
    return out;
}

const PI: f32 = 3.14159265;

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let n = normalize(in.normal);
    var base = solid.color.rgb;
    if (solid.pattern.x > 1.5) {
        // A mesh, perhaps open: each face lit from the side the eye sees.
        let facing = select(-n, n, dot(n, globals.eye.xyz - in.world) >= 0.0);
        return vec4<f32>(to_srgb(blinn_phong(base, facing, in.world, 24.0, 0.2)), 1.0);
    }
    if (solid.pattern.x < 0.5) {
        // Eight longitude segments in object space: they rotate with the sphere.
        let lon = atan2(in.object.z, in.object.x);
        let segment = i32(floor((lon + PI) / (2.0 * PI) * 8.0));
        base = base * select(1.0, 0.5, (segment & 1) == 1);
        return vec4<f32>(to_srgb(blinn_phong(base, n, in.world, 48.0, 0.35)), 1.0);
    }
    // Ground: anti-aliased grid lines every `pattern.y` metres in world x and z.
    let coord = in.world.xz / solid.pattern.y;
    let width = fwidth(coord);
    let grid = abs(fract(coord - 0.5) - 0.5) / max(width, vec2<f32>(1e-4));
    let line = 1.0 - min(min(grid.x, grid.y), 1.0);
    base = mix(base, base * 0.55, line);
    // Fade with distance so the horizon does not alias.
    let fade = clamp(length(in.world.xz - globals.eye.xz) / 25.0, 0.0, 1.0);
    base = mix(base, vec3<f32>(0.10, 0.11, 0.13), fade);
    return vec4<f32>(to_srgb(blinn_phong(base, n, in.world, 8.0, 0.0)), 1.0);
}
