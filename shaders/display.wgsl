// Builds the renderer's vertex buffers on the device from particle positions that live there
// (the GPU backend's state), so drawing a frame reads nothing back. Each output has the
// layout the CPU path uploads (`ClothVertex`, `ColorVertex` in render/geometry.rs), so the
// same render pipelines draw both. Not prefixed with common.wgsl (no `globals` here).

struct Info {
    // Particles, vec4s per particle in `source`, lines, where the corners start in `topo`.
    count: u32,
    stride: u32,
    lines: u32,
    corners_at: u32,
    particle_color: vec4<f32>,
    pinned_color: vec4<f32>,
};

// A line to draw: its ends, the spring's rest length, 1 to colour it by strain (else `color`).
struct Line {
    a: u32,
    b: u32,
    rest: f32,
    by_strain: u32,
    color: vec4<f32>,
};

@group(0) @binding(0) var<uniform> info: Info;
// Particle i's position is the xyz of source[i * stride].
@group(0) @binding(1) var<storage, read> source: array<vec4<f32>>;
// count + 1 offsets into the list that follows: the triangles around each particle, in
// increasing order; from `corners_at`, three corners per triangle.
@group(0) @binding(2) var<storage, read> topo: array<u32>;
@group(0) @binding(3) var<storage, read> uvs: array<vec2<f32>>;
// Eight floats per particle: position, normal, uv.
@group(0) @binding(4) var<storage, read_write> cloth_out: array<f32>;
@group(0) @binding(5) var<storage, read> lines: array<Line>;
// Seven floats per line end (`line_ends`) or per particle (`points`): position, colour.
// The two entry points bind their own output buffers here.
@group(0) @binding(6) var<storage, read_write> color_out: array<f32>;
// One flag per particle: pinned (1) or not (0).
@group(0) @binding(7) var<storage, read> pinned: array<u32>;

const WORKGROUP: u32 = 64u;

fn position(i: u32) -> vec3<f32> {
    return source[i * info.stride].xyz;
}

// The item of this invocation; dispatches wider than one dimension allows wrap into y.
fn item(id: vec3<u32>, groups: vec3<u32>) -> u32 {
    return id.x + id.y * groups.x * WORKGROUP;
}

// A line end or a particle: seven floats, position then colour.
fn write_color_vertex(at: u32, p: vec3<f32>, c: vec4<f32>) {
    color_out[at] = p.x;
    color_out[at + 1u] = p.y;
    color_out[at + 2u] = p.z;
    color_out[at + 3u] = c.x;
    color_out[at + 4u] = c.y;
    color_out[at + 5u] = c.z;
    color_out[at + 6u] = c.w;
}

// Area-weighted normals as `vertex_normals` (mesh/normals.rs) makes them on the CPU: each triangle's unnormalised
// face normal, summed in triangle order, normalised; +Y where they cancel.
@compute @workgroup_size(64)
fn cloth(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = item(id, groups);
    if (i >= info.count) {
        return;
    }
    var n = vec3<f32>(0.0);
    for (var s = topo[i]; s < topo[i + 1u]; s++) {
        let t = info.corners_at + 3u * topo[info.count + 1u + s];
        let a = position(topo[t]);
        n += cross(position(topo[t + 1u]) - a, position(topo[t + 2u]) - a);
    }
    let len = length(n);
    let normal = select(vec3<f32>(0.0, 1.0, 0.0), n * (1.0 / len), len > 0.0 && len < 3.0e38);
    let p = position(i);
    let uv = uvs[i];
    let at = 8u * i;
    cloth_out[at] = p.x;
    cloth_out[at + 1u] = p.y;
    cloth_out[at + 2u] = p.z;
    cloth_out[at + 3u] = normal.x;
    cloth_out[at + 4u] = normal.y;
    cloth_out[at + 5u] = normal.z;
    cloth_out[at + 6u] = uv.x;
    cloth_out[at + 7u] = uv.y;
}

// As `strain_color` in render/renderer.rs: grey at 0, red at ≥ +10 %, blue at ≤ −10 %.
fn strain_color(strain: f32) -> vec4<f32> {
    let t = clamp(strain / 0.1, -1.0, 1.0);
    let grey = vec3<f32>(0.45);
    let stretched = grey + (vec3<f32>(1.0, 0.08, 0.02) - grey) * t;
    let compressed = grey + (vec3<f32>(0.05, 0.3, 1.0) - grey) * -t;
    return vec4<f32>(select(compressed, stretched, t >= 0.0), 1.0);
}

@compute @workgroup_size(64)
fn line_ends(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let l = item(id, groups);
    if (l >= info.lines) {
        return;
    }
    let line = lines[l];
    let a = position(line.a);
    let b = position(line.b);
    var color = line.color;
    if (line.by_strain != 0u) {
        color = strain_color((distance(a, b) - line.rest) / max(line.rest, 1.0e-9));
    }
    write_color_vertex(14u * l, a, color);
    write_color_vertex(14u * l + 7u, b, color);
}

@compute @workgroup_size(64)
fn points(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let i = item(id, groups);
    if (i >= info.count) {
        return;
    }
    let color = select(info.particle_color, info.pinned_color, pinned[i] != 0u);
    write_color_vertex(7u * i, position(i), color);
}
