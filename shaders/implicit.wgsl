// Implicit Euler (src/sim/integrator/implicit_euler.rs) on the GPU: one linearised backward
// Euler step a substep, `(M − h·∂f/∂v − h²·∂f/∂x)·Δv = h·(f + h·(∂f/∂x)·v)`, solved by
// conjugate gradients with the CPU's block-Jacobi preconditioner, matrix-free: each
// product gathers a particle's springs and recomputes their blocks `h²k·s·I + (h·c +
// h²k·(1 − s))·n nᵀ` (s = max(0, 1 − L/l)) from the substep's positions, so nothing per
// spring is stored. The forces without a derivative (wind, dihedral bending) are explicit,
// as on the CPU. Pinned particles are held out of the solve (their unknowns stay zero).
//
// A substep's dispatches, in order: `ie_begin` (forces, right-hand side, preconditioner,
// first guess), `ie_norm` (‖b‖, the target), `ie_residual` (r, z), `ie_start`, then per
// iteration `ie_product` (the direction p = z + β·p and q = A·p), `ie_alpha`, `ie_update`
// (x, r, z), `ie_beta`, and last `ie_finish` (the state, with the colliders). The host
// encodes the iterations in chunks and reads `cg[2]` between them (src/gpu/implicit_steps.rs);
// the one-workgroup kernels write the particle kernels' workgroup counts into `args`, zero
// once the solve is done, so the iterations of a chunk past convergence dispatch nothing.
// Prepended with shaders/step_common.wgsl.

// The solve's scalars, partial sums and vectors (src/gpu/implicit.rs): [0] x rz, y α,
// z β, w r·r; [1] x the target (tolerance·‖b‖)², y ‖b‖²; [2] x iterations, y 1 when done,
// z the first guess's history (0 none, 1 the last Δv, 2 the last two), w 1 when a collider
// moved a particle (the history is then no guess); from 4 one partial sum per workgroup;
// from params.solver.x the vectors, n entries each: x (Δv), r, z, the direction p of even
// and of odd iterations, q, b, the Δv before the last, then the preconditioner's inverse
// blocks, three columns per particle.
@group(0) @binding(8) var<storage, read_write> cg: array<vec4<f32>>;
// The particle kernels' workgroup counts (x, y, z), read by their indirect dispatches.
@group(1) @binding(1) var<storage, read_write> args: array<u32>;

const PARTIALS: u32 = 4u;
const X: u32 = 0u;
const R: u32 = 1u;
const Z: u32 = 2u;
// The two directions: an iteration reads its last one and writes its own.
const P: u32 = 3u;
const Q: u32 = 5u;
const B: u32 = 6u;
const PREVIOUS: u32 = 7u;
const INVERSE: u32 = 8u;
// `which` meaning this iteration's direction, formed where it is read.
const DIRECTION: u32 = 0xffffffffu;

var<workgroup> sums: array<vec2<f32>, 64>;

// Entry `i` of vector `which`.
fn entry(which: u32, i: u32) -> u32 {
    return params.solver.x + which * params.counts.x + i;
}

fn vec_at(which: u32, i: u32) -> vec3<f32> {
    return cg[entry(which, i)].xyz;
}

fn set_vec(which: u32, i: u32, value: vec3<f32>) {
    cg[entry(which, i)] = vec4<f32>(value, 0.0);
}

fn moves(i: u32) -> bool {
    return i < params.counts.x && src[i].x.w != 0.0;
}

fn done() -> bool {
    return cg[2].y > 0.5;
}

// Sums `mine` over the workgroup into its partial sum.
fn reduce_into(lid: u32, group: u32, mine: vec2<f32>) {
    sums[lid] = mine;
    workgroupBarrier();
    for (var s = 32u; s > 0u; s = s >> 1u) {
        if (lid < s) {
            sums[lid] = sums[lid] + sums[lid + s];
        }
        workgroupBarrier();
    }
    if (lid == 0u) {
        cg[PARTIALS + group] = vec4<f32>(sums[0], 0.0, 0.0);
    }
}

// The sum of every workgroup's partial sum (one workgroup runs this).
fn total(lid: u32) -> vec2<f32> {
    var acc = vec2<f32>(0.0);
    for (var k = lid; k < params.solver.w; k = k + 64u) {
        acc = acc + cg[PARTIALS + k].xy;
    }
    sums[lid] = acc;
    workgroupBarrier();
    for (var s = 32u; s > 0u; s = s >> 1u) {
        if (lid < s) {
            sums[lid] = sums[lid] + sums[lid + s];
        }
        workgroupBarrier();
    }
    return sums[0];
}

// The particle kernels dispatch their workgroups while the solve goes on, none after.
fn dispatch_while(going: bool) {
    args[0] = select(0u, params.solver.w, going);
    args[1] = 1u;
    args[2] = 1u;
}

// A spring's system block `alpha·I + beta·n nᵀ` (the CPU's `SpringBlock`) and the
// stretch `s` it was made with, from particle `i`'s end.
struct Block {
    n: vec3<f32>,
    alpha: f32,
    beta: f32,
    s: f32,
}

fn block_of(x: vec3<f32>, to: Link) -> Block {
    let d = src[to.other].x.xyz - x;
    let len = length(d);
    if (len <= TINY_LENGTH) {
        return Block(vec3<f32>(0.0), 0.0, 0.0, 0.0);
    }
    let inv = 1.0 / len;
    let kc = classes[to.strength];
    let s = max(1.0 - to.rest * inv, 0.0);
    let h = params.gravity.w;
    let alpha = h * h * (kc.x * s);
    let beta = h * kc.y + h * h * (kc.x * (1.0 - s));
    return Block(d * inv, alpha, beta, s);
}

fn times(b: Block, u: vec3<f32>) -> vec3<f32> {
    return u * b.alpha + b.n * (b.beta * dot(b.n, u));
}

// A particle's mass times `1 + h·(air damping rate)`: its diagonal before the springs.
fn own_diagonal(w: f32) -> f32 {
    return (1.0 / w) * (1.0 + params.gravity.w * params.drag.x);
}

// Per free particle: the forces `f` (springs, element forces, gravity, air damping), the
// right-hand side `b = h·(f + h·(∂f/∂x)·v)`, the inverse of its diagonal block, and the
// first guess of Δv: zero, the last step's Δv, or the last two extrapolated
// (`2·Δv₁ − Δv₂`), as far as the history goes. Each workgroup sums its `‖b‖²`.
@compute @workgroup_size(64)
fn ie_begin(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_id) lid: vec3<u32>,
    @builtin(workgroup_id) group: vec3<u32>,
) {
    let i = id.x;
    var norm = 0.0;
    if (moves(i)) {
        let me = src[i];
        let x = me.x.xyz;
        let v = me.v.xyz;
        let w = me.x.w;
        let h = params.gravity.w;
        var f = vec3<f32>(0.0);
        var dfdx_v = vec3<f32>(0.0);
        let own = own_diagonal(w);
        var diag = mat3x3<f32>(own, 0.0, 0.0, 0.0, own, 0.0, 0.0, 0.0, own);
        let links = links_of(i);
        for (var l = 0u; l < links.count; l = l + 1u) {
            let to = link_of(links, l);
            if (!to.ok) {
                continue;
            }
            let o = src[to.other];
            let kc = classes[to.strength];
            f = f + spring_pull(x, v, o, kc, to.rest);
            let b = block_of(x, to);
            let n = b.n;
            diag = diag + mat3x3<f32>(
                vec3<f32>(b.alpha, 0.0, 0.0) + n * (b.beta * n.x),
                vec3<f32>(0.0, b.alpha, 0.0) + n * (b.beta * n.y),
                vec3<f32>(0.0, 0.0, b.alpha) + n * (b.beta * n.z),
            );
            let u = o.v.xyz - v;
            dfdx_v = dfdx_v + u * (kc.x * b.s) + n * (kc.x * (1.0 - b.s) * dot(n, u));
        }
        f = f + element_force(i) + (params.gravity.xyz - params.drag.x * v) * (1.0 / w);
        let rhs = (f + dfdx_v * h) * h;
        set_vec(B, i, rhs);
        norm = dot(rhs, rhs);
        let inverse = inverse3(diag);
        for (var c = 0u; c < 3u; c = c + 1u) {
            cg[entry(INVERSE, 0u) + 3u * i + c] = vec4<f32>(inverse[c], 0.0);
        }
        var history = cg[2].z;
        if (cg[2].w > 0.5) {
            history = 0.0;
        }
        let last = vec_at(X, i);
        if (history < 0.5) {
            set_vec(X, i, vec3<f32>(0.0));
        } else if (history < 1.5) {
            set_vec(PREVIOUS, i, last);
        } else {
            set_vec(X, i, last * 2.0 - vec_at(PREVIOUS, i));
            set_vec(PREVIOUS, i, last);
        }
    } else if (i < params.counts.x) {
        set_vec(X, i, vec3<f32>(0.0));
    }
    reduce_into(lid.x, group.x, vec2<f32>(norm, 0.0));
}

fn inverse3(m: mat3x3<f32>) -> mat3x3<f32> {
    let a = m[0];
    let b = m[1];
    let c = m[2];
    let r0 = cross(b, c);
    let r1 = cross(c, a);
    let r2 = cross(a, b);
    let det = dot(a, r0);
    if (det == 0.0) {
        return mat3x3<f32>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    }
    return transpose(mat3x3<f32>(r0, r1, r2)) * (1.0 / det);
}

// `‖b‖` and the target `tolerance·‖b‖`; the history grows by this step (unless a collider
// moved a particle since the last). A zero right-hand side is solved by Δv = 0: done.
@compute @workgroup_size(64)
fn ie_norm(@builtin(local_invocation_id) lid: vec3<u32>) {
    let sum = total(lid.x);
    if (lid.x == 0u) {
        let tolerance = bitcast<f32>(params.solver.z);
        cg[1] = vec4<f32>(tolerance * tolerance * sum.x, sum.x, 0.0, 0.0);
        var history = cg[2].z;
        if (cg[2].w > 0.5) {
            history = 0.0;
        }
        let zero = sum.x == 0.0;
        cg[2] = vec4<f32>(0.0, select(0.0, 1.0, zero), min(history + 1.0, 2.0), 0.0);
        dispatch_while(!zero);
    }
}

// The preconditioned residual `z = P·r` of the block-Jacobi inverse `P`.
fn preconditioned(i: u32, r: vec3<f32>) -> vec3<f32> {
    let base = entry(INVERSE, 0u) + 3u * i;
    return mat3x3<f32>(cg[base].xyz, cg[base + 1u].xyz, cg[base + 2u].xyz) * r;
}

// Where the direction of the iteration under way (`cg[2].x` done before it) is written,
// and where the last one's is read.
fn direction_slot(last: bool) -> u32 {
    return P + ((u32(cg[2].x) + select(0u, 1u, last)) & 1u);
}

// This iteration's direction at particle `j`: `z` on the first, else `z + β·p` (the last
// direction): formed by each particle that reads it, so no pass of its own writes it first.
fn direction(j: u32) -> vec3<f32> {
    if (cg[2].x < 0.5) {
        return vec_at(Z, j);
    }
    return vec_at(Z, j) + vec_at(direction_slot(true), j) * cg[0].z;
}

fn operand(which: u32, j: u32) -> vec3<f32> {
    if (which == DIRECTION) {
        return direction(j);
    }
    return vec_at(which, j);
}

// Keeps the residual `r` of free particle `i` and its preconditioned `z = P·r`; returns its
// `r·z` and `r·r`.
fn keep_residual(i: u32, r: vec3<f32>) -> vec2<f32> {
    let z = preconditioned(i, r);
    set_vec(R, i, r);
    set_vec(Z, i, z);
    return vec2<f32>(dot(r, z), dot(r, r));
}

// `A·u` for free particle `i`, `u` read from vector `which` or, for [`DIRECTION`], this
// iteration's direction (zero at pinned particles).
fn product(i: u32, which: u32) -> vec3<f32> {
    let x = src[i].x.xyz;
    let mine = operand(which, i);
    var sum = mine * own_diagonal(src[i].x.w);
    let links = links_of(i);
    for (var l = 0u; l < links.count; l = l + 1u) {
        let to = link_of(links, l);
        if (to.ok) {
            sum = sum + times(block_of(x, to), mine - operand(which, to.other));
        }
    }
    return sum;
}

// `r = b − A·x`, `z = P·r`; each workgroup sums `r·z` and `r·r`.
@compute @workgroup_size(64)
fn ie_residual(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_id) lid: vec3<u32>,
    @builtin(workgroup_id) group: vec3<u32>,
) {
    let i = id.x;
    var mine = vec2<f32>(0.0);
    if (moves(i)) {
        mine = keep_residual(i, vec_at(B, i) - product(i, X));
    } else if (i < params.counts.x) {
        set_vec(R, i, vec3<f32>(0.0));
        set_vec(Z, i, vec3<f32>(0.0));
        set_vec(P, i, vec3<f32>(0.0));
        set_vec(P + 1u, i, vec3<f32>(0.0));
    }
    reduce_into(lid.x, group.x, mine);
}

// Done when the residual's `r·r` meets the target; the particle kernels dispatch nothing
// from then on.
fn done_at(rr: f32) {
    let finished = !(rr > cg[1].x);
    cg[2].y = select(0.0, 1.0, finished);
    dispatch_while(!finished);
}

// `r·z` and `r·r` of the first guess; done when it already meets the target.
@compute @workgroup_size(64)
fn ie_start(@builtin(local_invocation_id) lid: vec3<u32>) {
    let sum = total(lid.x);
    if (lid.x == 0u && !done()) {
        cg[0] = vec4<f32>(sum.x, 0.0, 0.0, sum.y);
        done_at(sum.y);
    }
}

// This iteration's direction `p` (kept for the update and the next direction) and `q = A·p`
// (zero at pinned particles); each workgroup sums `p·q`.
@compute @workgroup_size(64)
fn ie_product(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_id) lid: vec3<u32>,
    @builtin(workgroup_id) group: vec3<u32>,
) {
    let i = id.x;
    var mine = vec2<f32>(0.0);
    if (moves(i)) {
        let p = direction(i);
        let q = product(i, DIRECTION);
        set_vec(direction_slot(false), i, p);
        set_vec(Q, i, q);
        mine = vec2<f32>(dot(p, q), 0.0);
    } else if (i < params.counts.x) {
        set_vec(Q, i, vec3<f32>(0.0));
    }
    reduce_into(lid.x, group.x, mine);
}

// `α = r·z / p·q`; a curvature that is not positive and finite ends the solve (the state
// it leaves is then judged by the guard).
@compute @workgroup_size(64)
fn ie_alpha(@builtin(local_invocation_id) lid: vec3<u32>) {
    let sum = total(lid.x);
    if (lid.x == 0u && !done()) {
        let curvature = sum.x;
        cg[2].x = cg[2].x + 1.0;
        if (!(curvature > 0.0) || curvature > 3.0e38) {
            cg[2].y = 1.0;
            dispatch_while(false);
        } else {
            cg[0].y = cg[0].x / curvature;
        }
    }
}

// `x += α·p`, `r −= α·q`, `z = P·r`; each workgroup sums `r·z` and `r·r`.
@compute @workgroup_size(64)
fn ie_update(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_id) lid: vec3<u32>,
    @builtin(workgroup_id) group: vec3<u32>,
) {
    let i = id.x;
    var mine = vec2<f32>(0.0);
    if (moves(i)) {
        let alpha = cg[0].y;
        // The iteration is counted by now: its direction is the "last" one.
        set_vec(X, i, vec_at(X, i) + vec_at(direction_slot(true), i) * alpha);
        mine = keep_residual(i, vec_at(R, i) - vec_at(Q, i) * alpha);
    }
    reduce_into(lid.x, group.x, mine);
}

// `β = r·z (new) / r·z (old)`; done at the target. (The cap is the host's: it encodes that
// many iterations.)
@compute @workgroup_size(64)
fn ie_beta(@builtin(local_invocation_id) lid: vec3<u32>) {
    let sum = total(lid.x);
    if (lid.x == 0u && !done()) {
        cg[0] = vec4<f32>(sum.x, cg[0].y, sum.x / cg[0].x, sum.y);
        done_at(sum.y);
    }
}

// Last, into `dst`: a free particle takes `v + Δv` and moves by it, the colliders resolved
// (a collider that moves a particle leaves no history for the next guess, as on the CPU);
// a pinned one goes where its handle puts it, if one does. A zero right-hand side's Δv is
// zero.
@compute @workgroup_size(64)
fn ie_finish(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (held(i)) {
        return;
    }
    var dv = vec_at(X, i);
    if (cg[1].y == 0.0) {
        dv = vec3<f32>(0.0);
        set_vec(X, i, dv);
    }
    if (advance(i, src[i].v.xyz + dv)) {
        cg[2].w = 1.0;
    }
}
