// Mesh obstacles on the GPU (prepended with shaders/cloth_layout.wgsl,
// shaders/contact.wgsl and shaders/geometry.wgsl; src/gpu/obstacles.rs
// builds and dispatches them): the CPU's contact with a mesh obstacle, rigid (placed and
// moved by its keyframes) or deforming (an OBJ sequence, whose surface where each substep
// ends the host writes for each submission, with each vertex's move over the substep and
// velocity). After a substep, `catch` takes each free particle's move from the
// substep's start to its end into the obstacle's frame (the start where the obstacle was
// then, the end where it is now), catches it at its first crossings and pushes its end out
// to the thickness through the obstacle's box tree, and answers with an inelastic velocity
// response and Coulomb friction against the surface's own velocity. Then `edges`, one
// dispatch per colour of the cloth's edges, keeps each cloth edge off the obstacle's sharp
// edges (creases and open borders) as the CPU's sweep over them does. Then `tips`, one
// dispatch per colour of the cloth's triangles, keeps each triangle off the obstacle's
// tips (and, where it is wide enough for the surface to bulge through it, off its smooth
// vertices) as the CPU's tip pass does.

struct Obstacle {
    // In `surface`'s entries: where its tree's nodes, its places (triangles in the tree's
    // order), its sharp edges' tree's nodes and their places start (a deforming obstacle's:
    // from where its surface at the substep's end starts, which its poses give).
    starts: vec4<u32>,
    // x: nodes; y: places; z: edge nodes; w: edge places.
    counts: vec4<u32>,
    // xyz: the pivot its motion turns about.
    pivot: vec4<f32>,
    // x: its thickness (m); y: its friction; z: a deforming obstacle's vertices' moves and
    // velocities (bits; two entries a vertex, after `starts` as they are); w: 1 when it
    // deforms.
    info: vec4<f32>,
    // Where its tips' tree's nodes, its tips (a point each, w unused), its smooth vertices'
    // tree's nodes and its smooth vertices (w: the curvature, 1/m) start, as `starts`.
    tips: vec4<u32>,
    // x: the tips' tree's nodes; y: the smooth vertices' tree's nodes; z: the largest
    // curvature (bits).
    tip_counts: vec4<u32>,
}

struct ObstacleParams {
    // x: particles; y: where the cloth's triangles start in `cloth_edges`; z: the word of
    // self-contact's counters that says whether its pushes moved anything.
    counts: vec4<u32>,
    obstacles: array<Obstacle, 4>,
}

@group(0) @binding(0) var<uniform> op: ObstacleParams;
// The substep's start, and its end, which the contacts move.
@group(0) @binding(1) var<storage, read> start: array<Particle>;
@group(0) @binding(2) var<storage, read_write> state: array<Particle>;
// Every obstacle's tree and triangles: a node is two entries (lo and its first, hi and its
// count, as bits in w); a place four (its corners, each w its vertex's number as bits; its
// unit normal); a sharp edge's place two (its ends); a deforming obstacle's vertex two (its
// move over the substep, its velocity).
@group(0) @binding(3) var<storage, read> surface: array<vec4<f32>>;
// The cloth's edges (structural and shear springs' ends) in colour order; after them,
// where the tip pass runs, its triangles in colour order (two entries each: two corners,
// then the third).
@group(0) @binding(4) var<storage, read> cloth_edges: array<vec2<u32>>;
// Crossings each sweep of the edge pass found (`catch_moves` zeroes them).
@group(0) @binding(5) var<storage, read_write> crossings: array<atomic<u32>, SWEEPS>;
// The solver's words the contacts tell of what they moved (else a stand-in): implicit
// Euler's solve, whose flag (the bits of [2].w) is raised when a contact moves a particle,
// so that its next first guess has no history (as the CPU's forgets it); or VBD's stencil,
// whose memory of each particle's last acceleration takes the contacts' change of
// velocity too (the CPU's reads the velocity after the contacts).
@group(0) @binding(6) var<storage, read_write> solver: array<u32>;
// Self-contact's counters, whose word `op.counts.z` says whether its pushes moved anything
// this substep: the pass's second run in a substep, after them, acts only then, as the
// CPU's solids do.
@group(0) @binding(7) var<storage, read> pushed: array<u32>;
// The colour one dispatch of `edges` takes: x its first edge, y how many, z 1 when they
// may share a particle plus twice the sweep, w the invocations dispatched.
@group(1) @binding(0) var<uniform> colour: vec4<u32>;
// One obstacle's poses in the substep: where it starts (translation, rotation), where it
// ends (translation, rotation, velocity, spin); then its number (x, as bits), what the
// contacts tell the solver (y: 0 nothing, 1 implicit Euler's flag, the word in z; 2 VBD's
// memory, from the word in z) and the substep's length (w); then, for a deforming obstacle
// (whose poses are the identity), where its surface at the substep's end starts in
// `surface` (x, as bits) and the largest move of a vertex over the substep (y); and 1 (z)
// for the pass's second run in the substep, after self-contact's pushes.
@group(2) @binding(0) var<uniform> poses: array<vec4<f32>, 16>;

// Corners a move may be caught at in one substep, and pushes of its end out of the
// thickness (the CPU's `CROSSINGS` and `PUSHES`).
const CROSSINGS: u32 = 3u;
const PUSHES: u32 = 3u;
// Sweeps of the edge pass a substep at most (the host's `EDGE_SWEEPS`; a test compares).
const SWEEPS: u32 = 4u;
// Nodes a walk of a tree holds at once (median splits keep its depth near log2(n / 4)).
const STACK: u32 = 64u;

fn rotate(q: vec4<f32>, v: vec3<f32>) -> vec3<f32> {
    let t = 2.0 * cross(q.xyz, v);
    return v + q.w * t + cross(q.xyz, t);
}

fn unrotate(q: vec4<f32>, v: vec3<f32>) -> vec3<f32> {
    return rotate(vec4<f32>(-q.xyz, q.w), v);
}

struct Pose {
    translation: vec3<f32>,
    rotation: vec4<f32>,
    velocity: vec3<f32>,
    spin: vec3<f32>,
}

fn pose(end: bool) -> Pose {
    let at = select(0u, 2u, end);
    return Pose(poses[at].xyz, poses[at + 1u], poses[4].xyz, poses[5].xyz);
}

// The pass's second run in the substep, after self-contact's pushes, where they moved
// nothing: it leaves the cloth as it is.
fn not_again() -> bool {
    return poses[7].z > 0.5 && pushed[op.counts.z] == 0u;
}

// How far apart invocation `id`'s entries of this dispatch's colour lie: the invocations
// dispatched; where the colour's entries may share a particle, 1 for the first invocation,
// which takes them all in order, and 0 (none) for the rest.
fn colour_stride(id: u32) -> u32 {
    if ((colour.z & 1u) == 1u) {
        return select(0u, 1u, id == 0u);
    }
    return colour.w;
}

// The obstacle this dispatch takes.
fn obstacle() -> u32 {
    return bitcast<u32>(poses[6].x);
}

// Where obstacle `o`'s nodes, places, edge nodes and edge places start in `surface` in
// this substep.
fn starts(o: u32) -> vec4<u32> {
    return op.obstacles[o].starts + vec4<u32>(bitcast<u32>(poses[7].x));
}

fn deforming(o: u32) -> bool {
    return op.obstacles[o].info.w > 0.5;
}

// A deforming obstacle's vertex field (`field` 0: each vertex's move over the substep; 1:
// its velocity) at `point` of place `place` (the CPU's `Moment::at`).
fn field_at(o: u32, place: u32, point: vec3<f32>, field: u32) -> vec3<f32> {
    let first = starts(o).y + 4u * place;
    let fields = bitcast<u32>(op.obstacles[o].info.z) + bitcast<u32>(poses[7].x) + field;
    let a = surface[first];
    let b = surface[first + 1u];
    let c = surface[first + 2u];
    let w = barycentric(point, a.xyz, b.xyz, c.xyz);
    return surface[fields + 2u * bitcast<u32>(a.w)].xyz * w.x
        + surface[fields + 2u * bitcast<u32>(b.w)].xyz * w.y
        + surface[fields + 2u * bitcast<u32>(c.w)].xyz * w.z;
}

// The weights of `p` (a point of the triangle's plane) on a, b, c (a degenerate triangle:
// all on a), as the CPU's `barycentric`.
fn barycentric(p: vec3<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> vec3<f32> {
    let e0 = b - a;
    let e1 = c - a;
    let e2 = p - a;
    let d00 = dot(e0, e0);
    let d01 = dot(e0, e1);
    let d11 = dot(e1, e1);
    let d20 = dot(e2, e0);
    let d21 = dot(e2, e1);
    let denom = d00 * d11 - d01 * d01;
    if (denom <= 1.1920929e-7 * d00 * d11 || denom <= 0.0) {
        return vec3<f32>(1.0, 0.0, 0.0);
    }
    let v = (d11 * d20 - d01 * d21) / denom;
    let w = (d00 * d21 - d01 * d20) / denom;
    return vec3<f32>(1.0 - v - w, v, w);
}

// A contact moved particle `i` and changed its velocity by `dv`: implicit Euler's next
// first guess has no history; VBD's memory of its last acceleration takes the change.
fn moved(i: u32, dv: vec3<f32>) {
    let mode = poses[6].y;
    let word = bitcast<u32>(poses[6].z);
    if (mode > 1.5) {
        let at = word + 4u * i;
        for (var k = 0u; k < 3u; k++) {
            solver[at + k] = bitcast<u32>(bitcast<f32>(solver[at + k]) + dv[k] / poses[6].w);
        }
    } else if (mode > 0.5) {
        solver[word] = bitcast<u32>(1.0);
    }
}

fn apply(p: Pose, pivot: vec3<f32>, x: vec3<f32>) -> vec3<f32> {
    return pivot + p.translation + rotate(p.rotation, x - pivot);
}

fn unapply(p: Pose, pivot: vec3<f32>, moved: vec3<f32>) -> vec3<f32> {
    return pivot + unrotate(p.rotation, moved - pivot - p.translation);
}

// The surface's velocity (world) at `point` of obstacle `o` (its frame where the substep
// ends): a rigid one's motion there; a deforming one's vertices' velocity at its point
// nearest within `reach` (none beyond: the CPU's `Moment::velocity_near`).
fn velocity_near(o: u32, point: vec3<f32>, reach: f32) -> vec3<f32> {
    if (deforming(o)) {
        let near = nearest(o, point, reach);
        if (near.place == 0xffffffffu) {
            return vec3<f32>(0.0);
        }
        return field_at(o, near.place, near.point, 1u);
    }
    let end = pose(true);
    let pivot = op.obstacles[o].pivot.xyz;
    return velocity_at(end, pivot, apply(end, pivot, point));
}

fn velocity_at(p: Pose, pivot: vec3<f32>, moved: vec3<f32>) -> vec3<f32> {
    return p.velocity + cross(p.spin, moved - pivot - p.translation);
}

struct Node {
    lo: vec3<f32>,
    hi: vec3<f32>,
    first: u32,
    count: u32,
}

fn node(base: u32, k: u32) -> Node {
    let a = surface[base + 2u * k];
    let b = surface[base + 2u * k + 1u];
    return Node(a.xyz, b.xyz, bitcast<u32>(a.w), bitcast<u32>(b.w));
}

fn corner(o: u32, place: u32, k: u32) -> vec3<f32> {
    return surface[starts(o).y + 4u * place + k].xyz;
}

fn face_normal(o: u32, place: u32) -> vec3<f32> {
    return surface[starts(o).y + 4u * place + 3u].xyz;
}

// Where along from→to the segment crosses triangle (a, b, c), or -1 (the CPU's
// `segment_crosses`).
fn segment_crosses(origin: vec3<f32>, to: vec3<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> f32 {
    let d = to - origin;
    let e1 = b - a;
    let e2 = c - a;
    let p = cross(d, e2);
    let det = dot(e1, p);
    let eps = 1.1920929e-7;
    if (abs(det) <= eps * max(dot(e1, e1), dot(e2, e2)) * length(d)) {
        return -1.0;
    }
    let inv = 1.0 / det;
    let s = origin - a;
    let u = dot(s, p) * inv;
    if (u < 0.0 || u > 1.0) {
        return -1.0;
    }
    let q = cross(s, e1);
    let v = dot(d, q) * inv;
    if (v < 0.0 || u + v > 1.0) {
        return -1.0;
    }
    let t = dot(e2, q) * inv;
    if (t < 0.0 || t > 1.0) {
        return -1.0;
    }
    return t;
}

fn box_d2(p: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> f32 {
    let d = max(max(lo - p, p - hi), vec3<f32>(0.0));
    return dot(d, d);
}

fn segment_meets_box(origin: vec3<f32>, to: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> bool {
    let d = to - origin;
    var t0 = 0.0;
    var t1 = 1.0;
    for (var k = 0u; k < 3u; k++) {
        if (abs(d[k]) < 1e-12) {
            if (origin[k] < lo[k] || origin[k] > hi[k]) {
                return false;
            }
            continue;
        }
        let inv = 1.0 / d[k];
        let a = (lo[k] - origin[k]) * inv;
        let b = (hi[k] - origin[k]) * inv;
        t0 = max(t0, min(a, b));
        t1 = min(t1, max(a, b));
        if (t0 > t1) {
            return false;
        }
    }
    return true;
}

// The first place of obstacle `o` the segment from→to crosses (x, as bits; none: u32 max)
// and where along it (y): the CPU's `first_crossing`, its tree walked in the same order.
fn first_crossing(o: u32, origin: vec3<f32>, to: vec3<f32>) -> vec2<f32> {
    let base = starts(o).x;
    var best_place = 0xffffffffu;
    var best_t = 2.0;
    var stack: array<u32, 64>;
    var top = 0u;
    if (op.obstacles[o].counts.x > 0u) {
        let root = node(base, 0u);
        if (segment_meets_box(origin, to, root.lo, root.hi)) {
            stack[0] = 0u;
            top = 1u;
        }
    }
    while (top > 0u) {
        top -= 1u;
        let at = stack[top];
        let n = node(base, at);
        // Only the part of the segment before the best crossing so far matters.
        let end = select(to, origin + (to - origin) * best_t, best_place != 0xffffffffu);
        if (!segment_meets_box(origin, end, n.lo, n.hi)) {
            continue;
        }
        if (n.count > 0u) {
            for (var place = n.first; place < n.first + n.count; place++) {
                let t = segment_crosses(origin, to, corner(o, place, 0u), corner(o, place, 1u), corner(o, place, 2u));
                if (t >= 0.0 && (best_place == 0xffffffffu || t < best_t)) {
                    best_place = place;
                    best_t = t;
                }
            }
            continue;
        }
        // The child pushed last is walked first: the one right after it.
        for (var k = 0u; k < 2u; k++) {
            let child = select(at + 1u, n.first, k == 0u);
            let c = node(base, child);
            if (segment_meets_box(origin, end, c.lo, c.hi) && top < STACK) {
                stack[top] = child;
                top += 1u;
            }
        }
    }
    return vec2<f32>(bitcast<f32>(best_place), best_t);
}

struct Near {
    place: u32,
    point: vec3<f32>,
    distance: f32,
}

// The point of obstacle `o` nearest to p within `reach` (place u32 max: none): the CPU's
// `nearest`, nearer children first.
fn nearest(o: u32, p: vec3<f32>, reach: f32) -> Near {
    let base = starts(o).x;
    var best = Near(0xffffffffu, vec3<f32>(0.0), reach * reach);
    var stack: array<u32, 64>;
    var top = 0u;
    if (op.obstacles[o].counts.x > 0u) {
        let root = node(base, 0u);
        if (box_d2(p, root.lo, root.hi) <= best.distance) {
            stack[0] = 0u;
            top = 1u;
        }
    }
    while (top > 0u) {
        top -= 1u;
        let at = stack[top];
        let n = node(base, at);
        if (box_d2(p, n.lo, n.hi) > best.distance) {
            continue;
        }
        if (n.count > 0u) {
            for (var place = n.first; place < n.first + n.count; place++) {
                let q = closest_on_triangle(p, corner(o, place, 0u), corner(o, place, 1u), corner(o, place, 2u));
                let d = p - q;
                let d2 = dot(d, d);
                if (d2 <= best.distance) {
                    best = Near(place, q, d2);
                }
            }
            continue;
        }
        let one = node(base, at + 1u);
        let two = node(base, n.first);
        var last = n.first;
        var first = at + 1u;
        if (box_d2(p, one.lo, one.hi) > box_d2(p, two.lo, two.hi)) {
            last = at + 1u;
            first = n.first;
        }
        for (var k = 0u; k < 2u; k++) {
            let child = select(first, last, k == 0u);
            let c = node(base, child);
            if (box_d2(p, c.lo, c.hi) <= best.distance && top < STACK) {
                stack[top] = child;
                top += 1u;
            }
        }
    }
    best.distance = sqrt(best.distance);
    return best;
}

// The way out for `end`, `distance` from `point` of place `place`: away from the point, or
// on the surface, off it on the side of `from` (the CPU's `away`).
fn away(o: u32, place: u32, point: vec3<f32>, distance: f32, end: vec3<f32>, origin: vec3<f32>, thickness: f32) -> vec3<f32> {
    if (distance > thickness * 1e-3) {
        return (end - point) / distance;
    }
    let face = face_normal(o, place);
    return select(-face, face, dot(origin - point, face) >= 0.0);
}

struct Caught {
    caught: bool,
    at: vec3<f32>,
    normal: vec3<f32>,
    // The place that held it last, and the point of it.
    place: u32,
    on_surface: vec3<f32>,
}

// Where a move from→to (in obstacle `o`'s frame) ends: caught at its first crossings a
// thickness off the side it came from, sliding on along the surface, then pushed out to the
// thickness (the CPU's general catch, `catch_among` with the tree).
fn catch_move(o: u32, origin: vec3<f32>, to: vec3<f32>, thickness: f32) -> Caught {
    var s = origin;
    var e = to;
    var out = Caught(false, to, vec3<f32>(0.0), 0u, vec3<f32>(0.0));
    for (var k = 0u; k < CROSSINGS; k++) {
        let hit = first_crossing(o, s, e);
        let place = bitcast<u32>(hit.x);
        if (place == 0xffffffffu) {
            break;
        }
        let face = face_normal(o, place);
        let at = s + (e - s) * hit.y;
        let facing = dot(s - at, face);
        var side = select(-1.0, 1.0, facing > 0.0);
        if (facing == 0.0) {
            side = select(-1.0, 1.0, dot(e - s, face) < 0.0);
        }
        let n = face * side;
        let rest = e - at;
        let along = rest - min(dot(rest, n), 0.0) * n;
        s = at + n * thickness;
        e = s + along;
        out = Caught(true, e, n, place, at);
    }
    for (var k = 0u; k < PUSHES; k++) {
        let near = nearest(o, e, thickness);
        if (near.place == 0xffffffffu || near.distance >= thickness * (1.0 - 1e-4)) {
            break;
        }
        let n = away(o, near.place, near.point, near.distance, e, s, thickness);
        e = near.point + n * thickness;
        out = Caught(true, e, n, near.place, near.point);
    }
    out.at = e;
    return out;
}

@compute @workgroup_size(64)
fn catch_moves(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= op.counts.x || not_again()) {
        return;
    }
    if (i == 0u) {
        for (var k = 0u; k < SWEEPS; k++) {
            atomicStore(&crossings[k], 0u);
        }
    }
    var p = state[i];
    if (p.x.w <= 0.0) {
        return;
    }
    let o = obstacle();
    let ob = op.obstacles[o];
    let pivot = ob.pivot.xyz;
    let end = pose(true);
    let thickness = ob.info.x;
    var begin = unapply(pose(false), pivot, start[i].x.xyz);
    // A deforming obstacle's: a start near the surface is carried by the surface's own move
    // over the substep, where it moves as much as half the thickness (the CPU's
    // `Deforming::contact`).
    let largest = poses[7].y;
    if (deforming(o) && largest >= 0.5 * thickness) {
        let near = nearest(o, begin, 2.0 * (thickness + largest));
        if (near.place != 0xffffffffu) {
            begin += field_at(o, near.place, near.point, 0u);
        }
    }
    let c = catch_move(o, begin, unapply(end, pivot, p.x.xyz), thickness);
    if (!c.caught) {
        return;
    }
    let at = apply(end, pivot, c.at);
    let n = rotate(end.rotation, c.normal);
    var vs = velocity_at(end, pivot, at);
    if (deforming(o)) {
        vs = field_at(o, c.place, c.on_surface, 1u);
    }
    let v = p.v.xyz;
    p.x = vec4<f32>(at, p.x.w);
    p.v = vec4<f32>(touching(v, vs, n, ob.info.y, 1.0), p.v.w);
    state[i] = p;
    moved(i, p.v.xyz - v);
}

struct EdgeHit {
    along: f32,
    on_segment: vec3<f32>,
    on_edge: vec3<f32>,
    distance: f32,
}

fn between(a: vec3<f32>, b: vec3<f32>, p: vec3<f32>, q: vec3<f32>) -> EdgeHit {
    let st = segments_closest(a, b, p, q);
    let on_segment = a + (b - a) * st.x;
    let on_edge = p + (q - p) * st.y;
    return EdgeHit(st.x, on_segment, on_edge, distance(on_segment, on_edge));
}

fn edge_end(o: u32, place: u32, k: u32) -> vec3<f32> {
    return surface[starts(o).w + 2u * place + k].xyz;
}

fn boxes_meet(alo: vec3<f32>, ahi: vec3<f32>, blo: vec3<f32>, bhi: vec3<f32>) -> bool {
    return all(alo <= bhi) && all(blo <= ahi);
}

// The first time in 0..1 the segment moving from `b0`–`b1` to `a0`–`a1` meets the segment
// p–q, or -1 (the CPU's `sweep_meets`).
fn sweep_meets(b0: vec3<f32>, b1: vec3<f32>, a0: vec3<f32>, a1: vec3<f32>, p: vec3<f32>, q: vec3<f32>) -> f32 {
    let u = q - p;
    let a = b0 - p;
    let da = a0 - b0;
    let c = b1 - b0;
    let dc = (a1 - b1) - da;
    let k0 = dot(a, cross(c, u));
    let k1 = dot(a, cross(dc, u)) + dot(da, cross(c, u));
    let k2 = dot(da, cross(dc, u));
    let scale = (length(c) + length(dc) + length(da)) * length(u);
    var r0 = 2.0;
    var r1 = 2.0;
    if (abs(k2) > 1e-9 * scale * max(scale, 1e-12)) {
        let disc = k1 * k1 - 4.0 * k2 * k0;
        if (disc >= 0.0) {
            let s = sqrt(disc);
            let x = (-k1 - s) / (2.0 * k2);
            let y = (-k1 + s) / (2.0 * k2);
            r0 = min(x, y);
            r1 = max(x, y);
        }
    } else if (abs(k1) > 0.0) {
        r0 = -k0 / k1;
    }
    let touch = 1e-5 * (length(c) + length(u));
    for (var k = 0u; k < 2u; k++) {
        let t = select(r1, r0, k == 0u);
        if (t >= 0.0 && t <= 1.0) {
            let x = b0 + da * t;
            let y = b1 + (a1 - b1) * t;
            if (between(x, y, p, q).distance <= touch) {
                return t;
            }
        }
    }
    return -1.0;
}

// Obstacle `o`'s sharp edges whose boxes meet lo..hi, walked as the CPU's `overlapping`
// walks them: the nearest to segment a–b within `reach` (`nearest_one`), or the first the
// segment moving from b0–b1 to a–b passes through, with the side it came from.
struct EdgeFound {
    found: bool,
    hit: EdgeHit,
    p: vec3<f32>,
    q: vec3<f32>,
    side: vec3<f32>,
}

fn sharp_edges(o: u32, lo: vec3<f32>, hi: vec3<f32>, a: vec3<f32>, b: vec3<f32>, b0: vec3<f32>, b1: vec3<f32>, reach: f32, nearest_one: bool) -> EdgeFound {
    let base = starts(o).z;
    var out = EdgeFound(false, EdgeHit(0.0, vec3<f32>(0.0), vec3<f32>(0.0), 0.0), vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    var first_t = 2.0;
    var walk = box_walk(base, op.obstacles[o].counts.z, lo, hi);
    loop {
        let n = next_leaf(&walk, base, lo, hi);
        if (n.count == 0u) {
            break;
        }
        for (var place = n.first; place < n.first + n.count; place++) {
            let p = edge_end(o, place, 0u);
            let q = edge_end(o, place, 1u);
            if (!boxes_meet(min(p, q), max(p, q), lo, hi)) {
                continue;
            }
            if (nearest_one) {
                let h = between(a, b, p, q);
                if (h.distance <= reach && (!out.found || h.distance < out.hit.distance)) {
                    out = EdgeFound(true, h, p, q, vec3<f32>(0.0));
                }
            } else {
                let t = sweep_meets(b0, b1, a, b, p, q);
                if (t < 0.0 || (out.found && first_t <= t)) {
                    continue;
                }
                let s = between(b0, b1, p, q);
                if (s.distance > 0.0) {
                    first_t = t;
                    out = EdgeFound(true, s, p, q, (s.on_segment - s.on_edge) / s.distance);
                }
            }
        }
    }
    return out;
}

// A depth-first walk of a box tree (its nodes from `base`, `count` of them) for the
// leaves whose boxes meet lo..hi, the child after its node first (the CPU's order).
struct BoxWalk {
    stack: array<u32, 64>,
    top: u32,
}

fn box_walk(base: u32, count: u32, lo: vec3<f32>, hi: vec3<f32>) -> BoxWalk {
    var w: BoxWalk;
    w.top = 0u;
    if (count > 0u) {
        let root = node(base, 0u);
        if (boxes_meet(root.lo, root.hi, lo, hi)) {
            w.stack[0] = 0u;
            w.top = 1u;
        }
    }
    return w;
}

// The walk's next leaf whose box meets lo..hi (a count of 0 when none is left).
fn next_leaf(w: ptr<function, BoxWalk>, base: u32, lo: vec3<f32>, hi: vec3<f32>) -> Node {
    while ((*w).top > 0u) {
        (*w).top -= 1u;
        let at = (*w).stack[(*w).top];
        let n = node(base, at);
        if (n.count > 0u) {
            return n;
        }
        for (var k = 0u; k < 2u; k++) {
            let child = select(at + 1u, n.first, k == 0u);
            let c = node(base, child);
            if (boxes_meet(c.lo, c.hi, lo, hi) && (*w).top < STACK) {
                (*w).stack[(*w).top] = child;
                (*w).top += 1u;
            }
        }
    }
    return Node(vec3<f32>(0.0), vec3<f32>(0.0), 0u, 0u);
}

// Keeps each cloth edge of this dispatch's colour the thickness off this dispatch's
// obstacle's sharp edges where the substep ends (the CPU's `push_edges`): an edge it passed through puts
// it back on the side it came from, one it ends within the thickness of pushes it out;
// the two particles move in proportion to how near each is to the nearest point.
@compute @workgroup_size(64)
fn edges(@builtin(global_invocation_id) id: vec3<u32>) {
    // A sweep runs only after one that found a crossing (the first always).
    let sweep = colour.z >> 1u;
    if ((sweep > 0u && atomicLoad(&crossings[sweep - 1u]) == 0u) || not_again()) {
        return;
    }
    let stride = colour_stride(id.x);
    if (stride == 0u) {
        return;
    }
    for (var k = id.x; k < colour.y; k += stride) {
        let e = cloth_edges[colour.x + k];
        var pi = state[e.x];
        var pj = state[e.y];
        let free = vec2<f32>(select(0.0, 1.0, pi.x.w > 0.0), select(0.0, 1.0, pj.x.w > 0.0));
        if (free.x == 0.0 && free.y == 0.0) {
            continue;
        }
        let o = obstacle();
        let ob = op.obstacles[o];
        let pivot = ob.pivot.xyz;
        let thickness = ob.info.x;
        let begin = pose(false);
        let end = pose(true);
        let l0 = unapply(end, pivot, pi.x.xyz);
        let l1 = unapply(end, pivot, pj.x.xyz);
        let b0 = unapply(begin, pivot, start[e.x].x.xyz);
        let b1 = unapply(begin, pivot, start[e.y].x.xyz);
        let travel = max(length(l0 - b0), length(l1 - b1));
        let reach = max(thickness, travel);
        let pad = vec3<f32>(reach);
        let near = sharp_edges(o, min(l0, l1) - pad, max(l0, l1) + pad, l0, l1, b0, b1, reach, true);
        if (!near.found) {
            continue;
        }
        var hit = near.hit;
        var side = vec3<f32>(0.0);
        var crossed = EdgeFound(false, hit, vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
        if (near.hit.distance <= travel) {
            let lo = min(min(b0, b1), min(l0, l1));
            let hi = max(max(b0, b1), max(l0, l1));
            crossed = sharp_edges(o, lo, hi, l0, l1, b0, b1, 0.0, false);
        }
        if (crossed.found) {
            atomicAdd(&crossings[sweep], 1u);
            hit = between(l0, l1, crossed.p, crossed.q);
            side = crossed.side;
        } else {
            if (near.hit.distance <= thickness * 1e-3 || near.hit.distance >= thickness) {
                continue;
            }
            side = (near.hit.on_segment - near.hit.on_edge) / near.hit.distance;
        }
        let gap = rotate(end.rotation, side * thickness - (hit.on_segment - hit.on_edge));
        let n = rotate(end.rotation, side);
        let share = vec2<f32>(1.0 - hit.along, hit.along);
        let weight = share.x * share.x * free.x + share.y * share.y * free.y;
        if (weight <= 0.0) {
            continue;
        }
        let vs = velocity_near(o, hit.on_edge, thickness);
        let part = share * free;
        let before = array<vec3<f32>, 2>(pi.v.xyz, pj.v.xyz);
        if (part.x > 0.0) {
            pi.x = vec4<f32>(pi.x.xyz + gap * (part.x / weight), pi.x.w);
            pi.v = vec4<f32>(touching(pi.v.xyz, vs, n, ob.info.y, part.x), pi.v.w);
        }
        if (part.y > 0.0) {
            pj.x = vec4<f32>(pj.x.xyz + gap * (part.y / weight), pj.x.w);
            pj.v = vec4<f32>(touching(pj.v.xyz, vs, n, ob.info.y, part.y), pj.v.w);
        }
        state[e.x] = pi;
        state[e.y] = pj;
        if (part.x > 0.0) {
            moved(e.x, pi.v.xyz - before[0]);
        }
        if (part.y > 0.0) {
            moved(e.y, pj.v.xyz - before[1]);
        }
    }
}

// A ball of `curvature` rises this far under the triangle x0 x1 x2 above the circle its
// corners lie on (κρ²/2 over its least enclosing circle: the CPU's `sag`).
fn sag(x0: vec3<f32>, x1: vec3<f32>, x2: vec3<f32>, curvature: f32) -> f32 {
    let a = dot(x1 - x0, x1 - x0);
    let b = dot(x2 - x1, x2 - x1);
    let c = dot(x0 - x2, x0 - x2);
    let longest = max(a, max(b, c));
    // Right or obtuse: the longest edge is the circle's diameter; acute: the circumcircle.
    var r2 = 0.25 * longest;
    if (2.0 * longest < a + b + c) {
        let n = cross(x1 - x0, x2 - x0);
        r2 = a * b * c / max(4.0 * dot(n, n), 1.17549435e-38);
    }
    return 0.5 * curvature * r2;
}

// What a cloth triangle's nearest point to a tip must move by (`gap`, m; 0: nothing),
// which way, and its corners' weights in that point (the CPU's `Push`).
struct TipPush {
    gap: f32,
    away: vec3<f32>,
    w: vec3<f32>,
}

// How triangle x (its unit normal `normal`, zero when degenerate) must move to keep
// `thickness` off `tip` on the side of the plane it began the substep in (a corner
// `began_at`, a normal `began`) that the tip began on: the CPU's `Face::missing`.
fn tip_missing(x: array<vec3<f32>, 3>, normal: vec3<f32>, began_at: vec3<f32>, began: vec3<f32>, tip: vec3<f32>, thickness: f32) -> TipPush {
    let none = TipPush(0.0, vec3<f32>(0.0), vec3<f32>(0.0));
    if (all(normal == vec3<f32>(0.0))) {
        return none;
    }
    let over = dot(tip - began_at, began);
    let plane = dot(tip - x[0], normal);
    if (over * plane > 0.0 && abs(plane) >= thickness) {
        return none;
    }
    var side = select(-1.0, 1.0, plane >= 0.0);
    if (over != 0.0) {
        side = sign(over);
    }
    let w = closest_weights(tip, x[0], x[1], x[2]);
    let q = w.x * x[0] + w.y * x[1] + w.z * x[2];
    let height = side * dot(tip - q, normal);
    if (all(w > vec3<f32>(0.0))) {
        // Inside: the triangle goes to the far side of the tip.
        if (height < thickness) {
            return TipPush(thickness - height, -side * normal, w);
        }
        return none;
    }
    // Nearest an edge or a corner: kept a thickness off, where on its side.
    let distance = length(q - tip);
    if (distance > thickness * 1e-3 && height >= 0.0 && distance < thickness) {
        return TipPush(thickness - distance, (q - tip) / distance, w);
    }
    return none;
}

fn unit_or_zero(v: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    if (l > 0.0 && l < 3.4e38) {
        return v / l;
    }
    return vec3<f32>(0.0);
}

// A cloth triangle of the tip pass: its particles, their places in the obstacle's frame,
// which are free, and the plane it began the substep in.
struct TipFace {
    ids: vec3<u32>,
    p: array<Particle, 3>,
    x: array<vec3<f32>, 3>,
    free: vec3<f32>,
    normal: vec3<f32>,
    began_at: vec3<f32>,
    began: vec3<f32>,
    pushed: u32,
}

// Keeps face `f` the thickness off `tip` (in the frame), as the CPU's `push_tips` does:
// the nearest point moves by what is missing, the corners by their weights in it, and
// their velocity towards the tip is removed, with Coulomb friction.
fn push_off_tip(f: ptr<function, TipFace>, o: u32, tip: vec3<f32>) {
    let ob = op.obstacles[o];
    let thickness = ob.info.x;
    let push = tip_missing((*f).x, (*f).normal, (*f).began_at, (*f).began, tip, thickness);
    if (push.gap <= 0.0) {
        return;
    }
    let part = push.w * (*f).free;
    let weight = dot(push.w * push.w, (*f).free);
    if (weight <= 0.0) {
        return;
    }
    let pivot = ob.pivot.xyz;
    let end = pose(true);
    let n = rotate(end.rotation, push.away);
    let by = rotate(end.rotation, push.gap * push.away);
    let vs = velocity_near(o, tip, thickness);
    for (var k = 0u; k < 3u; k++) {
        if (part[k] <= 0.0) {
            continue;
        }
        var p = (*f).p[k];
        p.x = vec4<f32>(p.x.xyz + by * (part[k] / weight), p.x.w);
        p.v = vec4<f32>(touching(p.v.xyz, vs, n, ob.info.y, part[k]), p.v.w);
        (*f).p[k] = p;
        (*f).x[k] = unapply(end, pivot, p.x.xyz);
        (*f).pushed |= 1u << k;
    }
    (*f).normal = unit_or_zero(cross((*f).x[1] - (*f).x[0], (*f).x[2] - (*f).x[0]));
}

// Keeps each cloth triangle of this dispatch's colour the thickness off this dispatch's
// obstacle's tips within reach, and, where a ball of the smooth parts' largest curvature
// would rise a thickness under it, off each smooth vertex within reach whose own
// curvature would (the CPU's `push_tips`).
@compute @workgroup_size(64)
fn tips(@builtin(global_invocation_id) id: vec3<u32>) {
    if (not_again()) {
        return;
    }
    let stride = colour_stride(id.x);
    if (stride == 0u) {
        return;
    }
    let o = obstacle();
    let ob = op.obstacles[o];
    let tc = ob.tip_counts;
    if (tc.x == 0u && tc.y == 0u) {
        return;
    }
    let at = ob.tips + vec4<u32>(bitcast<u32>(poses[7].x));
    let curvature = bitcast<f32>(tc.z);
    let thickness = ob.info.x;
    let pivot = ob.pivot.xyz;
    let begin = pose(false);
    let end = pose(true);
    // How far the surface moved over the substep (a deforming obstacle's largest move).
    var moved_by = 0.0;
    if (deforming(o)) {
        moved_by = poses[7].y;
    }
    for (var k = id.x; k < colour.y; k += stride) {
        let entry = op.counts.y + 2u * (colour.x + k);
        let ab = cloth_edges[entry];
        var f: TipFace;
        f.ids = vec3<u32>(ab.x, ab.y, cloth_edges[entry + 1u].x);
        f.pushed = 0u;
        var s: array<vec3<f32>, 3>;
        var travel = 0.0;
        var scale = 0.0;
        for (var j = 0u; j < 3u; j++) {
            f.p[j] = state[f.ids[j]];
            f.x[j] = unapply(end, pivot, f.p[j].x.xyz);
            s[j] = unapply(begin, pivot, start[f.ids[j]].x.xyz);
            f.free[j] = select(0.0, 1.0, f.p[j].x.w > 0.0);
            travel = max(travel, length(f.x[j] - s[j]));
            let a = abs(f.x[j]);
            scale = max(scale, max(a.x, max(a.y, a.z)));
        }
        if (all(f.free == vec3<f32>(0.0))) {
            continue;
        }
        f.normal = unit_or_zero(cross(f.x[1] - f.x[0], f.x[2] - f.x[0]));
        f.began_at = s[0];
        f.began = cross(s[1] - s[0], s[2] - s[0]);
        // Its own corners' moves bound its points' (and the tips' own move).
        let rounding = 4.0 * 1.1920929e-7 * (1.0 + scale);
        let reach = vec3<f32>(thickness + travel + moved_by + rounding);
        let lo = min(f.x[0], min(f.x[1], f.x[2])) - reach;
        let hi = max(f.x[0], max(f.x[1], f.x[2])) + reach;
        // How far a ball of unit curvature rises under it.
        let wide = sag(f.x[0], f.x[1], f.x[2], 1.0);
        let risky = tc.y > 0u && curvature > 0.0 && wide * curvature >= thickness;
        // The tips' tree, then (where it is at risk) the smooth vertices'.
        for (var tree = 0u; tree < 2u; tree++) {
            if (tree == 1u && !risky) {
                break;
            }
            let base = select(at.x, at.z, tree == 1u);
            let points = select(at.y, at.w, tree == 1u);
            let count = select(tc.x, tc.y, tree == 1u);
            var walk = box_walk(base, count, lo, hi);
            loop {
                let n = next_leaf(&walk, base, lo, hi);
                if (n.count == 0u) {
                    break;
                }
                for (var place = n.first; place < n.first + n.count; place++) {
                    let e = surface[points + place];
                    if (any(e.xyz < lo) || any(e.xyz > hi)) {
                        continue;
                    }
                    // A smooth vertex where its own curvature could bulge that far.
                    if (tree == 1u && wide * e.w < thickness) {
                        continue;
                    }
                    push_off_tip(&f, o, e.xyz);
                }
            }
        }
        for (var j = 0u; j < 3u; j++) {
            if ((f.pushed & (1u << j)) != 0u) {
                let before = state[f.ids[j]].v.xyz;
                state[f.ids[j]] = f.p[j];
                moved(f.ids[j], f.p[j].v.xyz - before);
            }
        }
    }
}

// Copies the substep's start (bound as `start`) into `state` (bound to the kept copy), for
// an integrator that writes its end over its start.
@compute @workgroup_size(64)
fn keep_start(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x < op.counts.x) {
        state[id.x] = start[id.x];
    }
}
