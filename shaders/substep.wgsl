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
// Prepended with shaders/step_common.wgsl.

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

@compute @workgroup_size(64)
fn substep(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (held(i)) {
        return;
    }
    let me = src[i];
    let w = me.x.w;
    let x = me.x.xyz;
    let v = me.v.xyz;
    var f = vec3<f32>(0.0);
    let links = links_of(i);
    for (var l = 0u; l < links.count; l = l + 1u) {
        let to = link_of(links, l);
        if (to.ok) {
            f = f + spring_pull(x, v, src[to.other], classes[to.strength], to.rest);
        }
    }
    f = f + element_force(i);
    let a = f * w + params.gravity.xyz - params.drag.x * v;
    advance(i, v + a * params.gravity.w);
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
// resolved; a pinned particle goes where its handle puts it, if one does.
@compute @workgroup_size(64)
fn xpbd_finish(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (finishing(i)) {
        move_by(i, src[i].v.xyz);
    }
}

// After each substep, whatever the integrator: one invocation counts it.
@compute @workgroup_size(1)
fn tick() {
    element_forces[0].x = element_forces[0].x + 1.0;
}
