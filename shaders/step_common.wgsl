// What the step shaders share (prepended, after shaders/cloth_layout.wgsl and
// shaders/contact.wgsl, to
// shaders/substep.wgsl, shaders/vbd.wgsl and shaders/implicit.wgsl when their pipelines
// are built, src/gpu/kernel.rs): the uniform parameters, the bindings every step kernel
// has, a particle's springs (from the grid or its spring ends) and a spring's pull, the
// element forces' gather, the colliders, and a substep's end for a pinned particle and a
// free one.

struct Params {
    // xyz: gravity (m/s²); w: substep length h (s).
    gravity: vec4<f32>,
    // x: air damping rate (1/s); y: collision offset (m).
    drag: vec4<f32>,
    // x: particle count; y: collider count; z: constraints (XPBD); w: invocations a
    // particle dispatch has (each zeroes the multipliers a stride of it apart).
    counts: vec4<u32>,
    // VBD: where the stencil's spans, links and per-particle memory start in its words, and
    // 1 when the memory holds no last acceleration (the first step after a change).
    // Implicit Euler: where the vectors start in its buffer, the bits of the tolerance (y
    // unused), and the workgroups a particle dispatch has.
    solver: vec4<u32>,
    // A grid cloth: x its width (0: not a grid), y its height, z its links.
    grid: vec4<u32>,
    // Handles: x where their targets start in `element_forces`, y how many particles they
    // carry.
    handles: vec4<u32>,
    // Per link: the other particle x columns and y rows away (i32 bits), z the spring's
    // strength class, w the bits of its rest length.
    links: array<vec4<u32>, 16>,
    colliders: array<Collider, 4>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> src: array<Particle>;
@group(0) @binding(2) var<storage, read_write> dst: array<Particle>;
@group(0) @binding(3) var<storage, read> offsets: array<u32>;
@group(0) @binding(4) var<storage, read> neighbours: array<Neighbour>;
// Per strength class: x stiffness (N/m), y damping (N·s/m).
@group(0) @binding(5) var<uniform> classes: array<vec4<f32>, CLASSES>;
// [0].x: substeps the submission has taken (`tick` counts them after each: the element
// pass's clock, the handles' targets); then the element forces' slots, then the handles'
// targets (position, velocity) per substep and carried particle.
@group(0) @binding(6) var<storage, read_write> element_forces: array<vec4<f32>>;
// Per particle its range of slots (the first particle count + 1 entries), then the slots.
@group(0) @binding(7) var<storage, read> incidence: array<u32>;

// The colour one dispatch of XPBD's projection or VBD's descent takes: x its first entry
// (constraint or particle in colour order), y how many, z 1 when they may share a particle
// (then one invocation takes them in order), w the invocations dispatched (each takes the
// entries a stride of it apart).
@group(1) @binding(0) var<uniform> colour: vec4<u32>;

// Lengths at or below this are taken as zero (the CPU's `Real::TINY_LENGTH` for f32).
const TINY_LENGTH: f32 = 1e-9;

// The pull (N) of a spring of stiffness and damping `kc.xy` and rest length `rest` from a
// particle at `x` moving at `v` to the particle `o`.
fn spring_pull(x: vec3<f32>, v: vec3<f32>, o: Particle, kc: vec4<f32>, rest: f32) -> vec3<f32> {
    let d = o.x.xyz - x;
    let len = length(d);
    if (len > 1e-9) {
        let n = d / len;
        return (kc.x * (len - rest) + kc.y * dot(o.v.xyz - v, n)) * n;
    }
    return vec3<f32>(0.0);
}

// Particle `i`'s springs: on a grid its column and row, from which its links follow (no
// spring end is read to find them), else where its spring ends start and how many.
struct Links {
    col: i32,
    row: i32,
    first: u32,
    count: u32,
}

fn links_of(i: u32) -> Links {
    if (params.grid.x > 0u) {
        return Links(i32(i % params.grid.x), i32(i / params.grid.x), 0u, params.grid.z);
    }
    return Links(0, 0, offsets[i], offsets[i + 1u] - offsets[i]);
}

// Spring `l` of `links`: the other particle, its strength class and rest length; `ok` false
// for a grid link that leaves the cloth.
struct Link {
    other: u32,
    strength: u32,
    rest: f32,
    ok: bool,
}

fn link_of(links: Links, l: u32) -> Link {
    if (params.grid.x > 0u) {
        let link = params.links[l];
        let width = i32(params.grid.x);
        let col = links.col + bitcast<i32>(link.x);
        let row = links.row + bitcast<i32>(link.y);
        let ok = col >= 0 && row >= 0 && col < width && row < i32(params.grid.y);
        return Link(select(0u, u32(row * width + col), ok), link.z, bitcast<f32>(link.w), ok);
    }
    let nb = neighbours[links.first + l];
    return Link(nb.other >> CLASS_BITS, nb.other & (CLASSES - 1u), nb.rest, true);
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

// `end` (position and velocity after a substep that started at `x`) with the sphere and
// plane colliders resolved against the substep's path, with friction.
fn collide(x: vec3<f32>, end: Motion) -> Motion {
    return collide_among(params.colliders, params.counts.y, params.drag.y, x, end);
}

// A pinned particle `me` where its handle puts it at the end of the submission's current
// substep (`me` itself when no handle carries it): the host's targets for this substep, the
// particle's slot among them in `me.v.w` (slot + 1).
fn placed(me: Particle) -> Particle {
    let slot = u32(me.v.w);
    if (slot == 0u) {
        return me;
    }
    let substep = u32(element_forces[0].x);
    let at = params.handles.x + 2u * (substep * params.handles.y + slot - 1u);
    let target_x = element_forces[at].xyz;
    return Particle(vec4<f32>(target_x, me.x.w), vec4<f32>(element_forces[at + 1u].xyz, me.v.w));
}

// True when invocation `i` has no free particle to step: none at all, or a pinned one,
// which then goes where its handle puts it, if one does (from `src` into `dst`).
fn held(i: u32) -> bool {
    if (i >= params.counts.x) {
        return true;
    }
    let me = src[i];
    if (me.x.w == 0.0) {
        dst[i] = placed(me);
        return true;
    }
    return false;
}

// Free particle `i` (read from `src`) takes the velocity `v` and moves by `v·h` into `dst`,
// the colliders resolved against that path; true when they changed where it ends or how
// it moves.
fn advance(i: u32, v: vec3<f32>) -> bool {
    let me = src[i];
    let x = me.x.xyz;
    let free = Motion(x + v * params.gravity.w, v);
    let out = collide(x, free);
    dst[i] = Particle(vec4<f32>(out.x, me.x.w), vec4<f32>(out.v, 0.0));
    return any(out.x != free.x) || any(out.v != free.v);
}

// The last pass of XPBD and VBD for particle `i`, with the state bound as `dst`: a free
// particle moves by its displacement `d` with velocity d / h and the colliders are
// resolved; a pinned one goes where its handle puts it, if one does. Returns the particle's
// velocity before and after.
fn move_by(i: u32, d: vec3<f32>) -> array<vec3<f32>, 2> {
    let me = dst[i];
    let w = me.x.w;
    if (w == 0.0) {
        let to = placed(me);
        dst[i] = to;
        return array<vec3<f32>, 2>(me.v.xyz, to.v.xyz);
    }
    let x = me.x.xyz;
    let out = collide(x, Motion(x + d, d * (1.0 / params.gravity.w)));
    dst[i] = Particle(vec4<f32>(out.x, w), vec4<f32>(out.v, 0.0));
    return array<vec3<f32>, 2>(me.v.xyz, out.v);
}

// Whether invocation `i` has a particle.
fn finishing(i: u32) -> bool {
    return i < params.counts.x;
}
