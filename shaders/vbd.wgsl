// Vertex block descent (src/sim/integrator/vbd.rs) on the GPU, three entry points a
// substep: `vbd_predict` writes each particle's inertial displacement and the descent's
// first guess into `dst`; `vbd_descend` moves one colour of particles by their Newton steps
// there (one dispatch per colour, in the CPU's stencil order: no two particles of a colour
// share a spring); `vbd_finish`, bound the other way round, turns the displacement into
// the state and its velocity, resolves the colliders, and keeps each particle's
// acceleration for the next step's first guess. The arithmetic is the CPU's scalar
// descent's, in its order. Prepended with shaders/step_common.wgsl.

// The stencil (src/sim/kernels/vbd_stencil.rs) as words: the particles in colour order
// (from 0), then per entry of that order its links' first, count and stride (from
// params.solver.x), then per link the other particle and the bits of its rest length,
// stiffness and dashpot (from .y), then per particle four words of memory (from .z): the
// bits of its last acceleration and of its mass.
@group(0) @binding(8) var<storage, read_write> stencil: array<u32>;

fn memory_at(p: u32) -> u32 {
    return params.solver.z + 4u * p;
}

// First: per free particle `dst` gets x = the first guess of its displacement (w its mass)
// and v = its inertial displacement `(v + h·a)·h`, `a` the acceleration of the forces that
// are not springs. The first guess takes the particle's acceleration over its last step in
// place of `a`, scaled down to `|a|` where larger (all of `a` without a last step), as the
// CPU's does (src/sim/integrator/vbd.rs).
@compute @workgroup_size(64)
fn vbd_predict(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= params.counts.x) {
        return;
    }
    let me = src[i];
    let w = me.x.w;
    let v = me.v.xyz;
    let h = params.gravity.w;
    let at = memory_at(i);
    let mass = bitcast<f32>(stencil[at + 3u]);
    var a = vec3<f32>(0.0);
    if (w != 0.0) {
        a = element_force(i) * w + params.gravity.xyz - params.drag.x * v;
    }
    let inertial = (v + a * h) * h;
    var guess = vec3<f32>(0.0);
    if (w != 0.0) {
        var taken = a;
        // A last step exists unless the host says the memory is stale and this is the
        // submission's first substep.
        if (params.solver.w == 0u || element_forces[0].x > 0.0) {
            let last = vec3<f32>(
                bitcast<f32>(stencil[at]),
                bitcast<f32>(stencil[at + 1u]),
                bitcast<f32>(stencil[at + 2u]),
            );
            let size = length(last);
            let most = length(a);
            taken = last;
            if (size > most) {
                taken = last * (most / size);
            }
        }
        guess = (v + taken * h) * h;
    }
    dst[i] = Particle(vec4<f32>(guess, mass), vec4<f32>(inertial, 0.0));
}

// Particle `order[i]`'s Newton step on its block: `H·Δd = −∇G`, with `∇G = m(d − ŷ) −
// h²Σ fₛ` over its springs and `H = m·I + Σ (h²k(n nᵀ + max(0, 1 − L/l)(I − n nᵀ)) + h·c·n nᵀ)`.
fn descend(i: u32) {
    let p = stencil[i];
    let w = src[p].x.w;
    if (w == 0.0) {
        return;
    }
    let x = src[p].x.xyz;
    let row = dst[p];
    let d = row.x.xyz;
    let mass = row.x.w;
    let h = params.gravity.w;
    let h2 = h * h;
    let inv_h = 1.0 / h;
    var g = (d - row.v.xyz) * mass;
    var xx = mass;
    var yy = mass;
    var zz = mass;
    var xy = 0.0;
    var xz = 0.0;
    var yz = 0.0;
    let span = params.solver.x + 3u * i;
    let first = stencil[span];
    let count = stencil[span + 1u];
    let stride = stencil[span + 2u];
    for (var t = 0u; t < count; t = t + 1u) {
        let l = params.solver.y + 4u * (first + t * stride);
        let q = stencil[l];
        let moved = dst[q].x.xyz - d;
        let u = (src[q].x.xyz - x) + moved;
        var len = length(u);
        let live = len > TINY_LENGTH;
        var k = 0.0;
        var c = 0.0;
        if (live) {
            k = bitcast<f32>(stencil[l + 2u]);
            c = bitcast<f32>(stencil[l + 3u]);
        } else {
            len = TINY_LENGTH;
        }
        let rest = bitcast<f32>(stencil[l + 1u]);
        let inv_len = 1.0 / len;
        let n = u * inv_len;
        let pull = k * (len - rest) + (c * inv_h) * dot(n, moved);
        g = g - n * (h2 * pull);
        let hk = h2 * k;
        let transverse = hk * max(1.0 - rest * inv_len, 0.0);
        let along = (hk - transverse) + h * c;
        let an = n * along;
        xx = xx + (transverse + an.x * n.x);
        yy = yy + (transverse + an.y * n.y);
        zz = zz + (transverse + an.z * n.z);
        xy = xy + an.x * n.y;
        xz = xz + an.x * n.z;
        yz = yz + an.y * n.z;
    }
    // The inverse by cofactors (the block is symmetric).
    let c00 = yy * zz - yz * yz;
    let c01 = xz * yz - xy * zz;
    let c02 = xy * yz - xz * yy;
    let c11 = xx * zz - xz * xz;
    let c12 = xy * xz - xx * yz;
    let c22 = xx * yy - xy * xy;
    let det = (xx * c00 + xy * c01) + xz * c02;
    if (!(det > 0.0 && det <= 3.4028235e38)) {
        return;
    }
    let s = vec3<f32>(
        (c00 * g.x + c01 * g.y) + c02 * g.z,
        (c01 * g.x + c11 * g.y) + c12 * g.z,
        (c02 * g.x + c12 * g.y) + c22 * g.z,
    );
    dst[p] = Particle(vec4<f32>(d - s / det, mass), row.v);
}

// Second: one colour's particles, one invocation each.
@compute @workgroup_size(64)
fn vbd_descend(@builtin(global_invocation_id) id: vec3<u32>) {
    for (var k = id.x; k < colour.y; k = k + colour.w) {
        descend(colour.x + k);
    }
}

// Last, bound with `src` the displacements and `dst` the state: each free particle moves
// by its displacement, with velocity displacement / h; the colliders are resolved; the
// change of velocity over h is kept for the next step's first guess; a pinned particle
// goes where its handle puts it, if one does.
@compute @workgroup_size(64)
fn vbd_finish(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (!finishing(i)) {
        return;
    }
    let free = dst[i].x.w != 0.0;
    let v = move_by(i, src[i].x.xyz);
    if (!free) {
        return;
    }
    let last = (v[1] - v[0]) / params.gravity.w;
    let at = memory_at(i);
    stencil[at] = bitcast<u32>(last.x);
    stencil[at + 1u] = bitcast<u32>(last.y);
    stencil[at + 2u] = bitcast<u32>(last.z);
}
