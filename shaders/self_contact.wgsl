// Self-contact on the GPU (prepended with shaders/cloth_layout.wgsl, shaders/contact.wgsl
// and shaders/geometry.wgsl, followed by shaders/self_pushes.wgsl and
// shaders/self_together.wgsl; src/gpu/self_contact.rs builds and dispatches it): the cloth
// kept off itself after each substep. Each kernel's work is a function of one particle,
// triangle or pair (`…_one`), which the wide path dispatches over the device and the small
// cloth's one workgroup loops over.
// Each particle's motion over the substep, grown by half the thickness, is its box; each
// triangle's box (its corners' together) goes into a hashed grid of cells (a list per
// bucket, linked through an atomic exchange); each triangle then walks the cells its box
// covers and keeps every other triangle whose box overlaps its own in the first cell both
// cover; then each such pair of triangles keeps its vertex–triangle and edge–edge pairs
// (each vertex and edge owned by one triangle, as on the CPU) whose sides' boxes overlap.
// A triangle whose box covers too many cells is checked against every triangle instead.
// The pairs closer than the thickness at the substep's end are pushed a thickness apart
// (shaders/self_pushes.wgsl), a particle resting on a sphere or plane moving only where
// nothing else in its pair can (the CPU's `held`); the colliders then act again on what
// the pushes moved into them, triangles kept out of the spheres too.
// The search runs again on the motion as pushed, and its pairs go through rounds of
// conservative continuous collision detection (additive CCD, as the CPU's, in f32 on
// coordinates taken from the pair's first particle, with a floor f32 resolves): a pair
// whose sides could come within a tenth of the thickness along the motion has its free
// particles' motion cut short where they are still apart (each particle keeps the
// smallest cut, an atomic minimum of its bits); after four rounds the cut is to the
// substep's start. Where the rounds recorded do not end it, or the grid's or the pairs'
// room ran out, every free particle goes back to its start.

struct SelfParams {
    // x: particles; y: triangles; z: buckets (a power of two); w: room for grid entries.
    counts: vec4<u32>,
    // x: room for pairs; y: what the contacts tell the solver (0 nothing, 1 implicit
    // Euler's flag, 2 VBD's memory); z: the solver's word for it; w: rounds recorded.
    more: vec4<u32>,
    // x: thickness (m); y: the separation the check keeps (m); z: the grid's cell (m);
    // w: the substep (s).
    lengths: vec4<f32>,
    // x: Coulomb friction between layers; y: the colliders' offset (m).
    contact: vec4<f32>,
    // x: how many colliders; y: sweeps of the pushes a substep; z: push rounds a sweep.
    passes: vec4<u32>,
    // The sphere and plane colliders (the step's).
    colliders: array<Collider, 4>,
}

@group(0) @binding(0) var<uniform> sp: SelfParams;
// The substep's start, and its end, which the cuts move.
@group(0) @binding(1) var<storage, read> start: array<Particle>;
@group(0) @binding(2) var<storage, read_write> state: array<Particle>;
// Each triangle's corners, and which of its corners (bits 0–2) and edges (bits 3–5, edge
// k from corner k to the next) it owns.
@group(0) @binding(3) var<storage, read> triangles: array<vec4<u32>>;
// Each particle's box (lo, hi; lo.w 1 where it is held, see `held`), then each triangle's
// (lo, hi; lo.w 1 where it is checked against every triangle).
@group(0) @binding(4) var<storage, read_write> boxes: array<vec4<f32>>;
// Counters (see below), then each bucket's first entry, then each particle's cut (the
// bits of its share of the motion).
@group(0) @binding(5) var<storage, read_write> atomics: array<atomic<u32>>;
// Each grid entry's next in its bucket, then the entries (triangle and cell, four words),
// then the triangles checked against all, then the pairs (four words), then each
// particle's share of its motion as the last round left it, each pair's marks in the push
// rounds (two words), and the pairs of triangles whose boxes overlap (two words).
@group(0) @binding(6) var<storage, read_write> lists: array<u32>;
// The solver's words the contacts tell of what they moved (see the obstacles' shader).
@group(0) @binding(7) var<storage, read_write> solver: array<u32>;
// The round this dispatch takes (x).
@group(1) @binding(0) var<uniform> this_round: vec4<u32>;
// The pair kernels' workgroup counts (x, y, z), then `pairs_of_triangles`', read by their
// indirect dispatches (bound to `size_pairs` and `size_triangle_pairs` alone).
@group(2) @binding(0) var<storage, read_write> pair_groups: array<u32>;

// Counters in `atomics`: grid entries, pairs, triangles checked against all, pairs of
// triangles whose boxes overlap, and per round the pairs it found could meet and those of
// them it could not cut.
const ENTRIES: u32 = 0u;
const PAIRS: u32 = 1u;
const BIG: u32 = 2u;
const TRIANGLE_PAIRS: u32 = 3u;
const IMPACTS: u32 = 4u;
const STUCK: u32 = 20u;
// The most grid entries and pairs any substep of the submission asked for, the pairs its
// substeps forced, and the fastest particle (an `f32`'s bits, m/s) its substeps' searches
// found, before their cuts, for the guard (zeroed by the host before each, not by
// `clear`).
const MOST_ENTRIES: u32 = 34u;
const MOST_PAIRS: u32 = 35u;
const FORCED: u32 = 36u;
const FASTEST: u32 = 37u;
// 1 where the substep's pushes moved anything (`obstacles_moved` zeroes it): the mesh
// obstacles act again after them only then, as the CPU's solids do.
const PUSHES_MOVED: u32 = 38u;
const COUNTERS: u32 = 39u;
// Rounds of cuts by the safe fraction; later rounds cut to the start (the CPU's).
const SCALED_ROUNDS: u32 = 4u;
// Cells a triangle's box may cover and still go into the grid.
const MOST_CELLS: i32 = 64;
const EMPTY: u32 = 0xffffffffu;
// The least separation the check keeps, as a share of the thickness (or four times what
// f32 resolves at the pair's coordinates, where that is more).
const FLOOR: f32 = 5e-4;
const EDGES: u32 = 0x80000000u;

fn heads_at() -> u32 {
    return COUNTERS;
}

fn cuts_at() -> u32 {
    return COUNTERS + sp.counts.z;
}

// Each particle's pushes in a sweep, in fixed point (9 words: its move, how many pushed
// it, its change of velocity, 1 where it rests on a collider, and its longest push), after
// the cuts.
fn pushes_at() -> u32 {
    return COUNTERS + sp.counts.z + sp.counts.x;
}

// Fixed point of the pushes: metres and metres a second per unit (a sum is the same in
// any order).
const MOVE_UNIT: f32 = 9.313226e-10;
const SPEED_UNIT: f32 = 5.9604645e-8;

fn next_at() -> u32 {
    return 0u;
}

fn entries_at() -> u32 {
    return sp.counts.w;
}

fn big_at() -> u32 {
    return 5u * sp.counts.w;
}

fn pairs_at() -> u32 {
    return 5u * sp.counts.w + sp.counts.y;
}

fn scales_at() -> u32 {
    return pairs_at() + 4u * sp.more.x;
}

// The pairs of triangles (room for as many as for pairs: a substep that finds more has
// run out of room, as one that keeps more pairs has).
fn triangle_pairs_at() -> u32 {
    return scales_at() + sp.counts.x + 2u * sp.more.x;
}

fn cell_of(p: vec3<f32>) -> vec3<i32> {
    return vec3<i32>(floor(p / sp.lengths.z));
}

fn bucket(c: vec3<i32>) -> u32 {
    let h = (c.x * 73856093) ^ (c.y * 19349663) ^ (c.z * 83492791);
    return bitcast<u32>(h) & (sp.counts.z - 1u);
}

// Zeroes the counters and empties the buckets.
fn clear_one(i: u32) {
    if (i < MOST_ENTRIES) {
        atomicStore(&atomics[i], 0u);
    } else if (i >= COUNTERS && i < COUNTERS + sp.counts.z) {
        atomicStore(&atomics[i], EMPTY);
    }
}

@compute @workgroup_size(64)
fn clear(@builtin(global_invocation_id) id: vec3<u32>) {
    clear_one(id.x);
}

// Each particle's box: its motion over the substep grown by half the thickness; its whole
// motion kept so far.
fn particle_boxes_one(i: u32) {
    if (i >= sp.counts.x) {
        return;
    }
    let a = start[i].x.xyz;
    let b = state[i].x.xyz;
    // Non-negative floats order as their bits do, and a NaN's bits above infinity's; a
    // load first spares most particles the atomic.
    let speed = bitcast<u32>(length(state[i].v.xyz));
    if (speed > atomicLoad(&atomics[FASTEST])) {
        atomicMax(&atomics[FASTEST], speed);
    }
    let g = vec3<f32>(0.5 * sp.lengths.x);
    let word = pushes_at() + PUSH_WORDS * i + HELD;
    let moved = atomicLoad(&atomics[word]) & MOVED;
    let now_held = moved | select(0u, 1u, on_solid(b));
    boxes[2u * i] = vec4<f32>(min(a, b) - g, select(0.0, 1.0, now_held != 0u));
    boxes[2u * i + 1u] = vec4<f32>(max(a, b) + g, 0.0);
    lists[scales_at() + i] = bitcast<u32>(1.0);
    atomicStore(&atomics[cuts_at() + i], bitcast<u32>(1.0));
    for (var k = 0u; k < HELD; k++) {
        atomicStore(&atomics[pushes_at() + PUSH_WORDS * i + k], 0u);
    }
    // Held: on a sphere or plane, or moved by a solid this substep (`MOVED`); the box
    // keeps a copy (`held`).
    atomicStore(&atomics[word], now_held);
    atomicStore(&atomics[pushes_at() + PUSH_WORDS * i + LONGEST], 0u);
    atomicStore(&atomics[owner_at(i)], 0u);
}

@compute @workgroup_size(64)
fn particle_boxes(@builtin(global_invocation_id) id: vec3<u32>) {
    particle_boxes_one(id.x);
}

// The word of a particle's nine where it rests on a collider, and the one that holds the
// longest move a pair pushed side by side gave it in the sweep (an `f32`'s bits).
const HELD: u32 = 7u;
// The bit of the held word that says a solid moved the particle this substep, before the
// pushes: a mesh obstacle (`obstacles_moved`) or the triangles' pass (`faces_lift`).
const MOVED: u32 = 2u;
const LONGEST: u32 = 8u;
const PUSH_WORDS: u32 = 9u;

// Whether a particle at `x` rests on a sphere or plane (within a hair of where the
// colliders put what they catch).
fn on_solid(x: vec3<f32>) -> bool {
    let offset = sp.contact.y;
    for (var c = 0u; c < sp.passes.x; c++) {
        let col = sp.colliders[c];
        let hair = 1e-5 * (col.info.y + offset) + 1e-6;
        if (col.info.x == 1.0 && length(x - col.a.xyz) <= col.info.y + offset + hair) {
            return true;
        }
        if (col.info.x == 2.0 && dot(x - col.a.xyz, col.b.xyz) <= offset + hair) {
            return true;
        }
    }
    return false;
}

// Whether particle `i` is held (its held word not 0), as the search copied the word into
// its box: the word changes only before a search (`obstacles_moved`, `faces_lift`), in it
// and after the cuts (`finish`), so the copy is the word wherever the pushes and cuts read
// it; read so, not by an atomic load, which some backends make a read-modify-write (GL's
// `atomicOr(x, 0)`), and every pair's push reads four of them.
fn held(i: u32) -> bool {
    return boxes[2u * i].w != 0.0;
}

// The colliders act again on the substep's end, as pushed (a stack pressed its lowest
// layer into one).
fn solids_one(i: u32) {
    if (i >= sp.counts.x || start[i].x.w <= 0.0) {
        return;
    }
    var q = state[i];
    let out = collide_among(sp.colliders, sp.passes.x, sp.contact.y, start[i].x.xyz, Motion(q.x.xyz, q.v.xyz));
    q.x = vec4<f32>(out.x, q.x.w);
    q.v = vec4<f32>(out.v, q.v.w);
    state[i] = q;
}

@compute @workgroup_size(64)
fn solids(@builtin(global_invocation_id) id: vec3<u32>) {
    solids_one(id.x);
}

fn triangle_box_at(t: u32) -> u32 {
    return 2u * sp.counts.x + 2u * t;
}

// Each triangle's box goes into the grid, in every cell it covers, or where it covers too
// many, onto the list of those checked against every triangle.
fn insert_one(t: u32) {
    if (t >= sp.counts.y) {
        return;
    }
    let tri = triangles[t];
    var lo = boxes[2u * tri.x].xyz;
    var hi = boxes[2u * tri.x + 1u].xyz;
    for (var k = 1u; k < 3u; k++) {
        let v = tri[k];
        lo = min(lo, boxes[2u * v].xyz);
        hi = max(hi, boxes[2u * v + 1u].xyz);
    }
    let c0 = cell_of(lo);
    let c1 = cell_of(hi);
    let span = c1 - c0 + vec3<i32>(1);
    let big = any(span > vec3<i32>(MOST_CELLS)) || span.x * span.y * span.z > MOST_CELLS;
    boxes[triangle_box_at(t)] = vec4<f32>(lo, select(0.0, 1.0, big));
    boxes[triangle_box_at(t) + 1u] = vec4<f32>(hi, 0.0);
    if (big) {
        let at = atomicAdd(&atomics[BIG], 1u);
        lists[big_at() + at] = t;
        return;
    }
    for (var z = c0.z; z <= c1.z; z++) {
        for (var y = c0.y; y <= c1.y; y++) {
            for (var x = c0.x; x <= c1.x; x++) {
                let e = atomicAdd(&atomics[ENTRIES], 1u);
                if (e >= sp.counts.w) {
                    return;
                }
                let at = entries_at() + 4u * e;
                lists[at] = t;
                lists[at + 1u] = bitcast<u32>(x);
                lists[at + 2u] = bitcast<u32>(y);
                lists[at + 3u] = bitcast<u32>(z);
                lists[next_at() + e] = atomicExchange(&atomics[heads_at() + bucket(vec3<i32>(x, y, z))], e);
            }
        }
    }
}

@compute @workgroup_size(64)
fn insert(@builtin(global_invocation_id) id: vec3<u32>) {
    insert_one(id.x);
}

fn boxes_meet(alo: vec3<f32>, ahi: vec3<f32>, blo: vec3<f32>, bhi: vec3<f32>) -> bool {
    return all(alo <= bhi) && all(blo <= ahi);
}

fn particle_lo(i: u32) -> vec3<f32> {
    return boxes[2u * i].xyz;
}

fn particle_hi(i: u32) -> vec3<f32> {
    return boxes[2u * i + 1u].xyz;
}

// A pair kept: an edge–edge pair or a vertex–triangle one, and its four particles.
struct Pair {
    edges: bool,
    ids: vec4<u32>,
}

// The pairs the search kept (those that had room), counted as it adds them.
fn pairs_found() -> u32 {
    return min(atomicLoad(&atomics[PAIRS]), sp.more.x);
}

// Where a search's counts are written once the step that counts them is done, for the
// kernels after to read plainly (see `held`: every invocation of theirs reads one): its
// pairs of triangles, then its pairs.
fn triangle_pairs_kept_at() -> u32 {
    return triangle_pairs_at() + 2u * sp.more.x;
}

fn kept_at() -> u32 {
    return triangle_pairs_kept_at() + 1u;
}

// The pairs kept this substep, as the search's end wrote them.
fn pairs_kept() -> u32 {
    return lists[kept_at()];
}

// Pair `p` (stored with EDGES set in its first particle for an edge–edge pair).
fn pair_at(p: u32) -> Pair {
    let at = pairs_at() + 4u * p;
    let first = lists[at];
    return Pair((first & EDGES) != 0u, vec4<u32>(first & ~EDGES, lists[at + 1u], lists[at + 2u], lists[at + 3u]));
}

fn keep_pair(pair: vec4<u32>) {
    let at = atomicAdd(&atomics[PAIRS], 1u);
    if (at < sp.more.x) {
        let p = pairs_at() + 4u * at;
        lists[p] = pair.x;
        lists[p + 1u] = pair.y;
        lists[p + 2u] = pair.z;
        lists[p + 3u] = pair.w;
        lists[done_at(at)] = 0u;
    }
}

// Keeps the vertex–triangle and edge–edge pairs triangles `a` and `b` own whose sides'
// boxes overlap (the CPU's `each_pair` and `sides_meet`).
fn pairs_of(a: u32, b: u32) {
    let ta = triangles[a];
    let tb = triangles[b];
    for (var side = 0u; side < 2u; side++) {
        let own = select(ta, tb, side == 1u);
        let other = select(tb, ta, side == 1u);
        let other_t = select(b, a, side == 1u);
        let olo = boxes[triangle_box_at(other_t)].xyz;
        let ohi = boxes[triangle_box_at(other_t) + 1u].xyz;
        for (var k = 0u; k < 3u; k++) {
            let v = own[k];
            if ((own.w & (1u << k)) == 0u || v == other.x || v == other.y || v == other.z) {
                continue;
            }
            if (boxes_meet(particle_lo(v), particle_hi(v), olo, ohi)) {
                keep_pair(vec4<u32>(v, other.x, other.y, other.z));
            }
        }
    }
    for (var j = 0u; j < 3u; j++) {
        if ((ta.w & (8u << j)) == 0u) {
            continue;
        }
        let e0 = ta[j];
        let e1 = ta[(j + 1u) % 3u];
        let elo = min(particle_lo(e0), particle_lo(e1));
        let ehi = max(particle_hi(e0), particle_hi(e1));
        for (var k = 0u; k < 3u; k++) {
            if ((tb.w & (8u << k)) == 0u) {
                continue;
            }
            let f0 = tb[k];
            let f1 = tb[(k + 1u) % 3u];
            if (e0 == f0 || e0 == f1 || e1 == f0 || e1 == f1) {
                continue;
            }
            let flo = min(particle_lo(f0), particle_lo(f1));
            let fhi = max(particle_hi(f0), particle_hi(f1));
            if (boxes_meet(elo, ehi, flo, fhi)) {
                keep_pair(vec4<u32>(e0 | EDGES, e1, f0, f1));
            }
        }
    }
}

// Keeps triangles `a` and `b`, whose boxes overlap, for `pairs_of_triangles`.
fn keep_triangles(a: u32, b: u32) {
    let at = atomicAdd(&atomics[TRIANGLE_PAIRS], 1u);
    if (at < sp.more.x) {
        lists[triangle_pairs_at() + 2u * at] = a;
        lists[triangle_pairs_at() + 2u * at + 1u] = b;
    }
}

// The pairs of triangles the search kept (those that had room), counted as it adds them.
fn triangle_pairs_found() -> u32 {
    return min(atomicLoad(&atomics[TRIANGLE_PAIRS]), sp.more.x);
}

// The pairs of triangles kept this substep, as `size_triangle_pairs` wrote them.
fn triangle_pairs_kept() -> u32 {
    return lists[triangle_pairs_kept_at()];
}

// Each triangle keeps every triangle whose box meets its own: from the grid, each two
// once (from the lower-numbered, in the first cell both cover); a triangle on the list of
// those checked against all, with every triangle. Their vertex–triangle and edge–edge
// pairs are kept in a dispatch of their own (`pairs_of_triangles`), one pair of triangles
// an invocation: tested here as each walk met them, each invocation's walk of a different
// length, the invocations run side by side waited on each other, and on the software
// adapter the search took twice as long (`layers` at 6 quads: 6.7 ms against 3).
fn find_one(a: u32) {
    if (a >= sp.counts.y) {
        return;
    }
    let box_a = boxes[triangle_box_at(a)];
    let lo = box_a.xyz;
    let hi = boxes[triangle_box_at(a) + 1u].xyz;
    if (box_a.w > 0.5) {
        for (var b = 0u; b < sp.counts.y; b++) {
            let box_b = boxes[triangle_box_at(b)];
            if (b == a || (box_b.w > 0.5 && b < a)) {
                continue;
            }
            if (boxes_meet(lo, hi, box_b.xyz, boxes[triangle_box_at(b) + 1u].xyz)) {
                keep_triangles(a, b);
            }
        }
        return;
    }
    let c0 = cell_of(lo);
    let c1 = cell_of(hi);
    for (var z = c0.z; z <= c1.z; z++) {
        for (var y = c0.y; y <= c1.y; y++) {
            for (var x = c0.x; x <= c1.x; x++) {
                let c = vec3<i32>(x, y, z);
                var e = atomicLoad(&atomics[heads_at() + bucket(c)]);
                while (e != EMPTY && e < sp.counts.w) {
                    let at = entries_at() + 4u * e;
                    let b = lists[at];
                    let cb = vec3<i32>(bitcast<i32>(lists[at + 1u]), bitcast<i32>(lists[at + 2u]), bitcast<i32>(lists[at + 3u]));
                    e = lists[next_at() + e];
                    if (b <= a || any(cb != c)) {
                        continue;
                    }
                    let blo = boxes[triangle_box_at(b)].xyz;
                    let bhi = boxes[triangle_box_at(b) + 1u].xyz;
                    // The first cell both cover: where their boxes' overlap starts.
                    if (!boxes_meet(lo, hi, blo, bhi) || any(cell_of(max(lo, blo)) != c)) {
                        continue;
                    }
                    keep_triangles(a, b);
                }
            }
        }
    }
}

@compute @workgroup_size(64)
fn find(@builtin(global_invocation_id) id: vec3<u32>) {
    find_one(id.x);
}

// The pairs of the `q`th pair of triangles kept.
fn pairs_of_one(q: u32) {
    let at = triangle_pairs_at() + 2u * q;
    pairs_of(lists[at], lists[at + 1u]);
}

@compute @workgroup_size(64)
fn pairs_of_triangles(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x < triangle_pairs_kept()) {
        pairs_of_one(id.x);
    }
}

// Invocations a workgroup has (the host's `WORKGROUP`, every `@workgroup_size` here).
const WIDTH: u32 = 64u;

// The grid entries and the room for pairs the search just made asked for (a pair of
// triangles takes as much room as a pair).
fn room_asked() -> vec2<u32> {
    let pairs = max(atomicLoad(&atomics[PAIRS]), atomicLoad(&atomics[TRIANGLE_PAIRS]));
    return vec2<u32>(atomicLoad(&atomics[ENTRIES]), pairs);
}

// Records what the search asked for among the most of the submission, after each search:
// the pushes' as well as the cuts', so that a frame whose pushes' search ran out of room
// (and dropped pairs from its pushes) is redone with more, as one whose cuts' did.
fn record_room_asked() {
    let asked = room_asked();
    atomicMax(&atomics[MOST_ENTRIES], asked.x);
    atomicMax(&atomics[MOST_PAIRS], asked.y);
}

// What ends a search: what it asked for recorded, and the count of the pairs it kept
// written (and returned).
fn end_search() -> u32 {
    record_room_asked();
    let kept = pairs_found();
    lists[kept_at()] = kept;
    return kept;
}

// The indirect dispatch at word `at` of `pair_groups` runs as many workgroups as `count`
// invocations need (the room is far more, and a workgroup past them would do nothing).
fn dispatch_for(at: u32, count: u32) {
    pair_groups[at] = (count + WIDTH - 1u) / WIDTH;
    pair_groups[at + 1u] = 1u;
    pair_groups[at + 2u] = 1u;
}

// The workgroups the pair kernels dispatch, at the search's end.
@compute @workgroup_size(1)
fn size_pairs() {
    dispatch_for(0u, end_search());
}

// The same for `pairs_of_triangles`, after `find` (the next four words), its count written.
@compute @workgroup_size(1)
fn size_triangle_pairs() {
    let kept = triangle_pairs_found();
    lists[triangle_pairs_kept_at()] = kept;
    dispatch_for(4u, kept);
}

// Where particle i is with `share` of its motion over the substep (the one expression both
// the check and the cut take).
fn moved_to(i: u32, share: f32) -> vec3<f32> {
    let a = start[i].x.xyz;
    return a + share * (state[i].x.xyz - a);
}

// The distance between segments p0–p1 and q0–q1.
fn segments_distance(p0: vec3<f32>, p1: vec3<f32>, q0: vec3<f32>, q1: vec3<f32>) -> f32 {
    let st = segments_closest(p0, p1, q0, q1);
    return length((p0 + st.x * (p1 - p0)) - (q0 + st.y * (q1 - q0)));
}

// The distance between the pair's sides with its particles at x (relative to one point).
fn pair_distance(edges: bool, x: array<vec3<f32>, 4>) -> f32 {
    if (edges) {
        return segments_distance(x[0], x[1], x[2], x[3]);
    }
    return length(x[0] - closest_on_triangle(x[0], x[1], x[2], x[3]));
}

// The least change of a pair's distance that counts as one, for a pair whose coordinates
// are at most `scale` (m) from the origin: eight units in the last place of f32 there, more
// than the rounding of its positions and of the distance itself.
fn resolved(scale: f32) -> f32 {
    return 8.0 * 1.1920929e-7 * scale;
}

// The largest share in [0, 1] of the motion `moves` from `x0` (relative to one point; the
// pair's coordinates at most `scale` from the origin) over which the pair's sides stay
// more than `keep_at_most` apart, or half the distance they start at where that is less
// (the CPU's `safe_fraction`): additive CCD, each advance a share of the gap over the most
// the sides can close on each other. A floor, a little above what f32 resolves, is kept
// as well: a pair that starts above it stops above it, one within it stops at half of it,
// and one below that (by rounding) moves only where it ends farther apart than it started
// (else 0): a pair pressed substep after substep never creeps closer.
fn safe_fraction(edges: bool, x0_in: array<vec3<f32>, 4>, moves_in: array<vec3<f32>, 4>, keep_at_most: f32, scale: f32) -> f32 {
    var x0 = x0_in;
    var moves = moves_in;
    let k = select(1u, 2u, edges);
    var alo = vec3<f32>(3.4e38);
    var ahi = vec3<f32>(-3.4e38);
    var blo = vec3<f32>(3.4e38);
    var bhi = vec3<f32>(-3.4e38);
    var mean = vec3<f32>(0.0);
    var x1: array<vec3<f32>, 4>;
    for (var i = 0u; i < 4u; i++) {
        x1[i] = x0[i] + moves[i];
        if (i < k) {
            alo = min(alo, min(x0[i], x1[i]));
            ahi = max(ahi, max(x0[i], x1[i]));
        } else {
            blo = min(blo, min(x0[i], x1[i]));
            bhi = max(bhi, max(x0[i], x1[i]));
        }
        mean += 0.25 * moves[i];
    }
    let apart = max(blo - ahi, alo - bhi);
    if (max(apart.x, max(apart.y, apart.z)) > keep_at_most) {
        return 1.0;
    }
    var reach_a = 0.0;
    var reach_b = 0.0;
    for (var i = 0u; i < 4u; i++) {
        let r = length(moves[i] - mean);
        if (i < k) {
            reach_a = max(reach_a, r);
        } else {
            reach_b = max(reach_b, r);
        }
    }
    // A little more than the bound, for rounding.
    let speed = (reach_a + reach_b) * (1.0 + 1e-5);
    if (speed == 0.0) {
        return 1.0;
    }
    let d0 = pair_distance(edges, x0);
    if (d0 <= 0.0) {
        return 1.0;
    }
    // Above the floor, the pair stops above it; within it, at half the floor, so that it may
    // still slide; below that (only rounding takes it there) it moves only where it ends
    // farther apart than it started, so that it never creeps closer.
    let margin = resolved(scale);
    let floor = max(FLOOR * sp.lengths.x, 4.0 * margin);
    let stuck = d0 <= 0.5 * floor;
    if (stuck && pair_distance(edges, x1) < d0 + margin) {
        return 0.0;
    }
    var keep = min(keep_at_most, 0.5 * d0);
    if (!stuck) {
        keep = max(keep, select(0.5 * floor, floor, d0 > floor));
    }
    if (d0 - speed > keep) {
        return 1.0;
    }
    let stop = keep + 0.1 * (d0 - keep);
    var t = 0.0;
    var d = d0;
    for (var n = 0u; n < 64u; n++) {
        let step = 0.9 * (d - keep) / speed;
        if (t + step >= 1.0) {
            return 1.0;
        }
        t += step;
        var x: array<vec3<f32>, 4>;
        for (var i = 0u; i < 4u; i++) {
            x[i] = x0[i] + t * moves[i];
        }
        d = pair_distance(edges, x);
        if (d <= stop) {
            break;
        }
    }
    return select(t, 0.0, stuck);
}

fn share_of(i: u32) -> f32 {
    return bitcast<f32>(lists[scales_at() + i]);
}

// Whether round `r` of cuts cut some particle's motion.
fn cut_something(r: u32) -> bool {
    return atomicLoad(&atomics[IMPACTS + r]) != atomicLoad(&atomics[STUCK + r]);
}

// One round of cuts: each pair whose sides could come within what is kept along the
// motion as the last round left it cuts its free particles' motion short (a scaled round:
// to where the pair is still apart; later ones: to the start).
fn cut_one(p: u32, r: u32) {
    // A round runs only after one that cut something.
    if (r > 0u && !cut_something(r - 1u)) {
        return;
    }
    if (p >= pairs_kept()) {
        return;
    }
    let pair = pair_at(p);
    let edges = pair.edges;
    let ids = pair.ids;
    let origin = start[ids.x].x.xyz;
    var x0: array<vec3<f32>, 4>;
    var moves: array<vec3<f32>, 4>;
    var scale = 0.0;
    for (var k = 0u; k < 4u; k++) {
        let i = ids[k];
        let to = moved_to(i, share_of(i));
        x0[k] = start[i].x.xyz - origin;
        moves[k] = (to - origin) - x0[k];
        let far = max(abs(start[i].x.xyz), abs(to));
        scale = max(scale, max(far.x, max(far.y, far.z)));
    }
    let t = safe_fraction(edges, x0, moves, sp.lengths.y, scale);
    if (t >= 1.0) {
        return;
    }
    atomicAdd(&atomics[IMPACTS + r], 1u);
    // What rests on a collider is cut only where nothing else in the pair can be (the
    // CPU's `fixed`).
    var only_held = true;
    for (var k = 0u; k < 4u; k++) {
        let i = ids[k];
        only_held = only_held && !(start[i].x.w > 0.0 && share_of(i) > 0.0 && !held(i));
    }
    var cut_any = false;
    for (var k = 0u; k < 4u; k++) {
        let i = ids[k];
        let s = share_of(i);
        if (start[i].x.w > 0.0 && s > 0.0 && (only_held || !held(i))) {
            let to = select(0.0, s * t, r < SCALED_ROUNDS);
            atomicMin(&atomics[cuts_at() + i], bitcast<u32>(to));
            cut_any = true;
        }
    }
    if (!cut_any) {
        atomicAdd(&atomics[STUCK + r], 1u);
    }
}

@compute @workgroup_size(64)
fn cut(@builtin(global_invocation_id) id: vec3<u32>) {
    cut_one(id.x, this_round.x);
}

// Each particle takes the round's cut.
fn cut_apply_one(i: u32) {
    if (i < sp.counts.x) {
        lists[scales_at() + i] = atomicLoad(&atomics[cuts_at() + i]);
    }
}

@compute @workgroup_size(64)
fn cut_apply(@builtin(global_invocation_id) id: vec3<u32>) {
    cut_apply_one(id.x);
}

// Each particle ends at its share of its motion, keeping that share of its velocity (its
// motion may hold the pushes' moves, which are no velocity). Every free particle goes back
// to its start where the last round recorded still cut something, or the grid's or the
// pairs' room ran out.
fn finish_one(i: u32) {
    if (i == 0u) {
        count_forced();
    }
    if (i >= sp.counts.x) {
        return;
    }
    let last = sp.more.w - 1u;
    let unfinished = cut_something(last);
    let asked = room_asked();
    let overflow = asked.x > sp.counts.w || asked.y > sp.more.x;
    atomicAnd(&atomics[pushes_at() + PUSH_WORDS * i + HELD], ~MOVED);
    var s = share_of(i);
    if ((unfinished || overflow) && start[i].x.w > 0.0) {
        s = 0.0;
    }
    if (s >= 1.0) {
        return;
    }
    var p = state[i];
    let v = p.v.xyz;
    let to = moved_to(i, s);
    p.v = vec4<f32>(v * s, p.v.w);
    p.x = vec4<f32>(to, p.x.w);
    state[i] = p;
    tell_solver(i, p.v.xyz - v);
}

// Adds the substep's forced pairs to the submission's: those the last round that ran found
// could meet and could not cut. Each round checks every pair again and a forced pair's
// particles are never cut, so a pair forced in one round is forced in every later one and
// is counted once.
fn count_forced() {
    var r = 0u;
    while (r + 1u < sp.more.w && cut_something(r)) {
        r++;
    }
    atomicAdd(&atomics[FORCED], atomicLoad(&atomics[STUCK + r]));
}

@compute @workgroup_size(64)
fn finish(@builtin(global_invocation_id) id: vec3<u32>) {
    finish_one(id.x);
}

// Tells the solver that particle `i`'s velocity changed by `dv` after its step (see the
// obstacles' shader): VBD's last acceleration takes it, implicit Euler's first guess keeps
// no history.
fn tell_solver(i: u32, dv: vec3<f32>) {
    if (sp.more.y == 2u) {
        let word = sp.more.z + 4u * i;
        for (var k = 0u; k < 3u; k++) {
            solver[word + k] = bitcast<u32>(bitcast<f32>(solver[word + k]) + dv[k] / sp.lengths.w);
        }
    } else if (sp.more.y == 1u) {
        solver[sp.more.z] = bitcast<u32>(1.0);
    }
}

// Copies the substep's start (bound as `start`) into `state` (bound to the kept copy), for
// an integrator that writes its end over its start.
@compute @workgroup_size(64)
fn keep_start(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x < sp.counts.x) {
        state[id.x] = start[id.x];
    }
}
