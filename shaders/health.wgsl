// The stability guard's measure of a frame, as a reduction in two passes: `partial` gives
// each workgroup's particles one record, `total` folds those records into the last one.
// A record holds what the CPU guard measures in one pass (src/sim/guard.rs): whether every
// position and velocity is finite, the fastest speed squared, the largest relative
// extension of a spring, the lowest height along `up` and the kinetic energy. No atomics:
// the records fold in a fixed order, so the sums do not depend on how the GPU schedules.
// Prepended with shaders/cloth_layout.wgsl (the particles and spring ends).

const GROUP: u32 = 64u;

struct Health {
    // x: fastest speed² (m²/s²); y: largest strain; z: lowest height (m); w: joules.
    motion: vec4<f32>,
    // x: 1 when a position or velocity is not finite.
    flags: vec4<u32>,
}

struct Params {
    // xyz: the guard's unit `up`.
    up: vec4<f32>,
    // x: particle count; y: records of the first pass (the total goes after them).
    counts: vec4<u32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> particles: array<Particle>;
@group(0) @binding(2) var<storage, read> offsets: array<u32>;
@group(0) @binding(3) var<storage, read> neighbours: array<Neighbour>;
@group(0) @binding(4) var<storage, read_write> records: array<Health>;

var<workgroup> motion: array<vec4<f32>, GROUP>;
var<workgroup> flags: array<u32, GROUP>;

// Whether no component of `v` is an infinity or a NaN (WGSL has no isnan): its bits
// without the sign are below those of infinity.
fn finite(v: vec3<f32>) -> bool {
    let bits = bitcast<vec3<u32>>(v) & vec3<u32>(0x7fffffffu);
    return all(bits < vec3<u32>(0x7f800000u));
}

fn combine(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(max(a.x, b.x), max(a.y, b.y), min(a.z, b.z), a.w + b.w);
}

const NOTHING: vec4<f32> = vec4<f32>(0.0, 0.0, 3.0e38, 0.0);

// Folds the workgroup's values into slot 0.
fn fold(lid: u32) {
    for (var s = GROUP / 2u; s > 0u; s = s >> 1u) {
        workgroupBarrier();
        if (lid < s) {
            motion[lid] = combine(motion[lid], motion[lid + s]);
            flags[lid] = flags[lid] | flags[lid + s];
        }
    }
}

@compute @workgroup_size(64)
fn partial(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(local_invocation_id) lid: vec3<u32>,
    @builtin(workgroup_id) wid: vec3<u32>,
) {
    let i = gid.x;
    var m = NOTHING;
    var bad = 0u;
    if (i < params.counts.x) {
        let p = particles[i];
        let x = p.x.xyz;
        let v = p.v.xyz;
        if (!finite(x) || !finite(v)) {
            bad = 1u;
        }
        var strain = 0.0;
        for (var s = offsets[i]; s < offsets[i + 1u]; s = s + 1u) {
            let nb = neighbours[s];
            let o = particles[nb.other >> CLASS_BITS].x.xyz;
            strain = max(strain, distance(o, x) / max(nb.rest, 1e-12) - 1.0);
        }
        let v2 = dot(v, v);
        let mass = select(0.0, 1.0 / p.x.w, p.x.w > 0.0);
        m = vec4<f32>(v2, strain, dot(params.up.xyz, x), 0.5 * mass * v2);
    }
    motion[lid.x] = m;
    flags[lid.x] = bad;
    fold(lid.x);
    if (lid.x == 0u) {
        records[wid.x] = Health(motion[0], vec4<u32>(flags[0], 0u, 0u, 0u));
    }
}

@compute @workgroup_size(64)
fn total(@builtin(local_invocation_id) lid: vec3<u32>) {
    var m = NOTHING;
    var bad = 0u;
    for (var r = lid.x; r < params.counts.y; r = r + GROUP) {
        let rec = records[r];
        m = combine(m, rec.motion);
        bad = bad | rec.flags.x;
    }
    motion[lid.x] = m;
    flags[lid.x] = bad;
    fold(lid.x);
    if (lid.x == 0u) {
        records[params.counts.y] = Health(motion[0], vec4<u32>(flags[0], 0u, 0u, 0u));
    }
}
