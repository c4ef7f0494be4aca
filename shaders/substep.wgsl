// One semi-implicit Euler substep of the mass-spring cloth, one invocation per particle:
// gather the particle's spring forces (no atomics: each particle sums its own springs) and
// the element forces in the slots it is in (shaders/elements.wgsl), add gravity and air
// damping, step the velocity then the position, then resolve the
// sphere and plane colliders against the path of the substep, with friction.
// Reads `src`, writes `dst`; the host swaps them every substep (ping-pong).
// XPBD (src/sim/integrator/xpbd.rs) takes three entry points a substep: `xpbd_predict`
// moves each particle by the forces that are not springs into `dst` (predicted position,
// displacement), `xpbd_project` projects one colour of the springs as distance
// constraints there (one dispatch per colour, in the CPU's order), and `xpbd_finish`,
// bound the other way round, turns the displacement into the state and its velocity and
// resolves the colliders as the semi-implicit step does.
// The constants below are the host's (src/gpu/packing.rs; a test compares them).

// Low bits of a spring end's `other` that hold its strength class.
const CLASS_BITS: u32 = 4u;
// Strength classes the table holds: 1 << CLASS_BITS.
const CLASSES: u32 = 16u;

struct Particle {
    // xyz: position (m); w: inverse mass (1/kg), 0 for a pinned particle.
    x: vec4<f32>,
    // xyz: velocity (m/s).
    v: vec4<f32>,
}

struct Neighbour {
    // Low CLASS_BITS bits: the strength class; the bits above: the other end's index.
    other: u32,
    // Rest length (m).
    rest: f32,
}

struct Collider {
    // x: kind (0 none, 1 sphere, 2 plane); y: radius; z: friction.
    info: vec4<f32>,
    // Sphere: centre; plane: a point on it.
    a: vec4<f32>,
    // Sphere: angular velocity (rad/s); plane: unit normal.
    b: vec4<f32>,
}

struct Params {
    // xyz: gravity (m/s²); w: substep length h (s).
    gravity: vec4<f32>,
    // x: air damping rate (1/s); y: collision offset (m).
    drag: vec4<f32>,
    // x: particle count; y: collider count; z: constraints (XPBD); w: invocations a
    // particle dispatch has (each zeroes the multipliers a stride of it apart).
    counts: vec4<u32>,
    colliders: array<Collider, 4>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> src: array<Particle>;
@group(0) @binding(2) var<storage, read_write> dst: array<Particle>;
@group(0) @binding(3) var<storage, read> offsets: array<u32>;
@group(0) @binding(4) var<storage, read> neighbours: array<Neighbour>;
// Per strength class: x stiffness (N/m), y damping (N·s/m).
@group(0) @binding(5) var<uniform> classes: array<vec4<f32>, CLASSES>;
// [0].x: substeps the submission has taken (invocation 0 counts them for the element pass's
// clock); then the element forces' slots.
@group(0) @binding(6) var<storage, read_write> element_forces: array<vec4<f32>>;
// Per particle its range of slots (the first particle count + 1 entries), then the slots.
@group(0) @binding(7) var<storage, read> incidence: array<u32>;

struct Constraint {
    a: u32,
    b: u32,
    // Rest length (m), compliance 1/k (m/N), compliance × dashpot (s).
    rest: f32,
    compliance: f32,
    damped: f32,
    // The Lagrange multiplier of the substep so far.
    lambda: f32,
}

// XPBD's springs as constraints, in colour order.
@group(0) @binding(8) var<storage, read_write> constraints: array<Constraint>;
// The colour one `xpbd_project` dispatch projects: x its first constraint, y how many, z 1
// when they may share a particle (then one invocation projects them in order), w the
// invocations dispatched (each takes the constraints a stride of it apart).
@group(1) @binding(0) var<uniform> colour: vec4<u32>;

// Lengths at or below this are taken as zero (the CPU's `Real::TINY_LENGTH` for f32).
const TINY_LENGTH: f32 = 1e-9;

// The first point where the segment a→b (relative to the centre) enters the sphere of
// radius r, if it starts outside and crosses in during the segment.
fn first_entry(a: vec3<f32>, b: vec3<f32>, r: f32) -> vec4<f32> {
    let d = b - a;
    let aa = dot(a, a);
    let dd = dot(d, d);
    if (aa < r * r || dd == 0.0) {
        return vec4<f32>(0.0);
    }
    let half_b = dot(a, d);
    let disc = half_b * half_b - dd * (aa - r * r);
    if (half_b >= 0.0 || disc < 0.0) {
        return vec4<f32>(0.0);
    }
    let t = (-half_b - sqrt(disc)) / dd;
    if (t < 0.0 || t > 1.0) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(a + t * d, 1.0);
}

fn unit_or_up(p: vec3<f32>) -> vec3<f32> {
    let len = length(p);
    if (len > 1e-9) {
        return p / len;
    }
    return vec3<f32>(0.0, 1.0, 0.0);
}

// The element forces (wind, dihedral bending) on particle `i`: its slots, summed.
fn element_force(i: u32) -> vec3<f32> {
    var f = vec3<f32>(0.0);
    let slots = params.counts.x + 1u;
    for (var s = incidence[i]; s < incidence[i + 1u]; s = s + 1u) {
        f = f + element_forces[1u + incidence[slots + s]].xyz;
    }
    return f;
}

struct Motion {
    x: vec3<f32>,
    v: vec3<f32>,
}

// `end` (position and velocity after a substep that started at `x`) with the sphere and
// plane colliders resolved against the substep's path, with friction.
fn collide(x: vec3<f32>, end: Motion) -> Motion {
    var nx = end.x;
    var nv = end.v;
    let offset = params.drag.y;
    for (var c = 0u; c < params.counts.y; c = c + 1u) {
        let col = params.colliders[c];
        let mu = col.info.z;
        var caught = false;
        var n = vec3<f32>(0.0, 1.0, 0.0);
        var v_surface = vec3<f32>(0.0);
        if (col.info.x == 1.0) {
            let centre = col.a.xyz;
            let radius = col.info.y;
            let reach = radius + offset;
            let entry = first_entry(x - centre, nx - centre, reach);
            let to = nx - centre;
            if (entry.w == 1.0 || dot(to, to) < reach * reach) {
                var moved = to;
                if (entry.w == 1.0) {
                    let hit = entry.xyz;
                    let hn = unit_or_up(hit);
                    let rest = to - hit;
                    moved = hit + rest - min(dot(rest, hn), 0.0) * hn;
                }
                let len = length(moved);
                n = unit_or_up(moved);
                nx = centre + n * max(reach, len);
                v_surface = cross(col.b.xyz, n * radius);
                caught = true;
            }
        } else if (col.info.x == 2.0) {
            let normal = col.b.xyz;
            let depth = offset - dot(nx - col.a.xyz, normal);
            if (depth > 0.0) {
                nx = nx + depth * normal;
                n = normal;
                caught = true;
            }
        }
        if (caught) {
            let v_rel = nv - v_surface;
            let vn = dot(v_rel, n);
            if (vn < 0.0) {
                let v_t = v_rel - vn * n;
                let t_speed = length(v_t);
                var keep = 0.0;
                if (t_speed > 0.0) {
                    keep = max(1.0 - mu * (-vn) / t_speed, 0.0);
                }
                nv = v_surface + keep * v_t;
            }
        }
    }
    return Motion(nx, nv);
}

@compute @workgroup_size(64)
fn substep(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i == 0u) {
        element_forces[0].x = element_forces[0].x + 1.0;
    }
    if (i >= params.counts.x) {
        return;
    }
    let me = src[i];
    let w = me.x.w;
    if (w == 0.0) {
        dst[i] = me;
        return;
    }
    let x = me.x.xyz;
    let v = me.v.xyz;
    var f = vec3<f32>(0.0);
    for (var s = offsets[i]; s < offsets[i + 1u]; s = s + 1u) {
        let nb = neighbours[s];
        let o = src[nb.other >> CLASS_BITS];
        let kc = classes[nb.other & (CLASSES - 1u)];
        let d = o.x.xyz - x;
        let len = length(d);
        if (len > 1e-9) {
            let n = d / len;
            f = f + (kc.x * (len - nb.rest) + kc.y * dot(o.v.xyz - v, n)) * n;
        }
    }
    f = f + element_force(i);
    let h = params.gravity.w;
    let a = f * w + params.gravity.xyz - params.drag.x * v;
    let nv = v + a * h;
    let out = collide(x, Motion(x + nv * h, nv));
    dst[i] = Particle(vec4<f32>(out.x, w), vec4<f32>(out.v, 0.0));
}

// XPBD, first: zeroes the multipliers and moves each free particle by the forces that are
// not springs to its prediction, into `dst`: x the predicted position (w the inverse
// mass), v the step's displacement.
@compute @workgroup_size(64)
fn xpbd_predict(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    for (var k = i; k < params.counts.z; k = k + params.counts.w) {
        constraints[k].lambda = 0.0;
    }
    if (i >= params.counts.x) {
        return;
    }
    let me = src[i];
    let w = me.x.w;
    var v = me.v.xyz;
    let h = params.gravity.w;
    if (w != 0.0) {
        v = v + (element_force(i) * w + params.gravity.xyz - params.drag.x * v) * h;
    }
    dst[i] = Particle(vec4<f32>(me.x.xyz + v * h, w), vec4<f32>(v * h, 0.0));
}

// Projects constraint `k` on the predictions in `dst` (the CPU's `project`, in its order).
fn project(k: u32) {
    let c = constraints[k];
    let pa = dst[c.a];
    let pb = dst[c.b];
    let wa = pa.x.w;
    let wb = pb.x.w;
    if (wa + wb == 0.0) {
        return;
    }
    let d = pb.x.xyz - pa.x.xyz;
    let len = length(d);
    if (len <= TINY_LENGTH) {
        return;
    }
    let n = d * (1.0 / len);
    let h = params.gravity.w;
    let alpha = c.compliance / (h * h);
    let gamma = c.damped / h;
    let rate = dot(n, pb.v.xyz - pa.v.xyz);
    let stretch = len - c.rest;
    let dl = (-stretch - alpha * c.lambda - gamma * rate) / ((1.0 + gamma) * (wa + wb) + alpha);
    constraints[k].lambda = c.lambda + dl;
    let da = n * (wa * dl);
    let db = n * (wb * dl);
    dst[c.a] = Particle(vec4<f32>(pa.x.xyz - da, wa), vec4<f32>(pa.v.xyz - da, 0.0));
    dst[c.b] = Particle(vec4<f32>(pb.x.xyz + db, wb), vec4<f32>(pb.v.xyz + db, 0.0));
}

// XPBD, second: one colour's constraints, one invocation each (or one for them all, in
// order, when they may share a particle).
@compute @workgroup_size(64)
fn xpbd_project(@builtin(global_invocation_id) id: vec3<u32>) {
    if (colour.z == 1u) {
        if (id.x == 0u) {
            for (var k = colour.x; k < colour.x + colour.y; k = k + 1u) {
                project(k);
            }
        }
        return;
    }
    for (var k = id.x; k < colour.y; k = k + colour.w) {
        project(colour.x + k);
    }
}

// XPBD, last, bound with `src` the predictions and `dst` the state: each free particle
// moves by its displacement, with velocity displacement / h, and the colliders are
// resolved; the first invocation counts the substep for the element pass's clock.
@compute @workgroup_size(64)
fn xpbd_finish(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i == 0u) {
        element_forces[0].x = element_forces[0].x + 1.0;
    }
    if (i >= params.counts.x) {
        return;
    }
    let me = dst[i];
    let w = me.x.w;
    if (w == 0.0) {
        return;
    }
    let d = src[i].v.xyz;
    let x = me.x.xyz;
    let out = collide(x, Motion(x + d, d * (1.0 / params.gravity.w)));
    dst[i] = Particle(vec4<f32>(out.x, w), vec4<f32>(out.v, 0.0));
}
