// Self-contact's pushes on the GPU (appended to shaders/self_contact.wgsl, whose bindings,
// pairs and counters they use; src/gpu/self_contact.rs builds and dispatches them): the
// pairs closer than the thickness pushed apart, in rounds of pairs that share no particle
// and then side by side, and the triangles pushed out of the spheres after the colliders'
// second pass.

// How hard the pair is to move at its closest points' weights `w`, its particles' inverse
// masses `inv`.
fn pair_weight(w: array<f32, 4>, inv: array<f32, 4>) -> f32 {
    var weight = 0.0;
    for (var k = 0u; k < 4u; k++) {
        weight += w[k] * w[k] * inv[k];
    }
    return weight;
}

fn add_fixed(at: u32, x: f32, unit: f32) {
    let n = i32(clamp(x / unit, -1.0e9, 1.0e9));
    atomicAdd(&atomics[at], bitcast<u32>(n));
}

// A pair's push: each of its particles' move and change of velocity (`pushed` false where
// its sides are a thickness apart already).
struct Push {
    pushed: bool,
    // How far the sides are within the thickness (m).
    depth: f32,
    dx: array<vec3<f32>, 4>,
    dv: array<vec3<f32>, 4>,
}

// The push that keeps the pair's sides a thickness apart at the substep's end, on the side
// they started on (the CPU's `push_apart`, with Coulomb friction on their sliding): each
// particle moves by its share (its weight times its inverse mass), what rests on a
// collider only where nothing else in the pair can.
fn push_of(pair: Pair) -> Push {
    var none: Push;
    none.pushed = false;
    none.depth = 0.0;
    let edges = pair.edges;
    let ids = pair.ids;
    let thickness = sp.lengths.x;
    let origin = state[ids.x].x.xyz;
    let origin0 = start[ids.x].x.xyz;
    var x: array<vec3<f32>, 4>;
    var x0: array<vec3<f32>, 4>;
    var inv: array<f32, 4>;
    for (var k = 0u; k < 4u; k++) {
        let q = state[ids[k]].x;
        x[k] = q.xyz - origin;
        x0[k] = start[ids[k]].x.xyz - origin0;
        inv[k] = q.w;
    }
    var w: array<f32, 4>;
    if (edges) {
        let st = segments_closest(x[0], x[1], x[2], x[3]);
        w = array<f32, 4>(1.0 - st.x, st.x, 1.0 - st.y, st.y);
    } else {
        let b = closest_weights(x[0], x[1], x[2], x[3]);
        w = array<f32, 4>(1.0, b.x, b.y, b.z);
    }
    let first = select(1u, 2u, edges);
    var gap = vec3<f32>(0.0);
    var before = vec3<f32>(0.0);
    var sign: array<f32, 4>;
    for (var k = 0u; k < 4u; k++) {
        sign[k] = select(-1.0, 1.0, k < first);
        gap += sign[k] * w[k] * x[k];
        before += sign[k] * w[k] * x0[k];
    }
    let dist = length(gap);
    if (dist >= thickness) {
        return none;
    }
    var direction = vec3<f32>(0.0);
    if (dot(before, before) > 0.0 && dot(gap, before) > 0.0 && dist > 1e-9) {
        direction = gap / dist;
    } else if (dot(before, before) > 0.0) {
        direction = normalize(before);
    } else if (dist > 0.0) {
        direction = gap / dist;
    } else {
        return none;
    }
    let depth = thickness - dot(gap, direction);
    if (depth <= 0.0) {
        return none;
    }
    // What rests on a collider moves only where nothing else in the pair can.
    var unheld = inv;
    for (var k = 0u; k < 4u; k++) {
        if (held(ids[k])) {
            unheld[k] = 0.0;
        }
    }
    if (pair_weight(w, unheld) > 0.0) {
        inv = unheld;
    }
    let weight = pair_weight(w, inv);
    var most = 0.0;
    for (var k = 0u; k < 4u; k++) {
        most = max(most, w[k] * inv[k]);
    }
    if (weight <= 0.0) {
        return none;
    }
    let share = min(weight / most, 1.0);
    let lambda = share * depth / weight;
    var relative = vec3<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        relative += sign[k] * w[k] * state[ids[k]].v.xyz;
    }
    let approach = dot(relative, direction);
    var impulse = vec3<f32>(0.0);
    if (approach < 0.0) {
        let sliding = relative - approach * direction;
        let speed = length(sliding);
        var friction = 0.0;
        if (speed > 0.0) {
            friction = min(sp.contact.x * -approach / speed, 1.0);
        }
        impulse = share * (-approach * direction - friction * sliding) / weight;
    }
    var out: Push;
    out.pushed = true;
    out.depth = depth;
    for (var k = 0u; k < 4u; k++) {
        let part = sign[k] * w[k] * inv[k];
        out.dx[k] = (part * lambda) * direction;
        out.dv[k] = part * impulse;
    }
    return out;
}

// Pushes in a sweep come in rounds: in each, every pair still to push this sweep whose
// sides are nearer than the thickness claims its free particles with its key (the round,
// then how deep the pair is, the deepest first, then a hash of the pair, so that the claims
// depend on the pairs, not on where they were stored); a pair that holds all of its claims
// moves its particles itself, no other pair touching them (the CPU's sweep, one pair after
// another, taken as sets of pairs that share no particle). What is left after the rounds is
// pushed side by side (`push`). Deepest first: in a stack the pair that most needs its
// push gets it before those its push would undo: in the order of a 24-bit hash alone,
// `layers` at 6 quads under XPBD at 8 substeps came within 0.92 mm, against 4.8 mm (the
// CPU 4.9).

// The bits of a key below the round: the depth's, then the hash's. Two pairs of a round
// that share a particle and have the same key would both push it; with the depth in 4 bits
// the hash keeps 22, so that happens to one pair of pairs in 4 million alike in depth
// (resting pairs, at a rounding from the thickness, all are).
const KEY_DEPTH_BITS: u32 = 4u;
const KEY_HASH_BITS: u32 = 22u;

// The pair's key in push round `r`, its push `depth` deep: the round in the top bits,
// then the depth as a share of the thickness, then the hash.
fn key_of(pair: Pair, r: u32, depth: f32) -> u32 {
    var h = pair.ids.x * 747796405u + select(0u, 2891336453u, pair.edges);
    for (var k = 1u; k < 4u; k++) {
        h = (h ^ (h >> 16u)) * 2246822519u + pair.ids[k];
    }
    h = (h ^ (h >> 13u)) * 3266489917u;
    let most = f32((1u << KEY_DEPTH_BITS) - 1u);
    let d = u32(clamp(depth / sp.lengths.x, 0.0, 1.0) * most);
    let hash = (h ^ (h >> 16u)) & ((1u << KEY_HASH_BITS) - 1u);
    return ((r + 1u) << (KEY_DEPTH_BITS + KEY_HASH_BITS)) | (d << KEY_HASH_BITS) | hash;
}

fn owner_at(i: u32) -> u32 {
    return pushes_at() + PUSH_WORDS * sp.counts.x + i;
}

fn done_at(p: u32) -> u32 {
    return scales_at() + sp.counts.x + p;
}

// Where pair `p` keeps its key of the round it claimed in, 0 in a round it did not.
fn key_at(p: u32) -> u32 {
    return done_at(sp.more.x) + p;
}

// Whether pair `p` was pushed in sweep `sweep`.
fn pushed_in(p: u32, sweep: u32) -> bool {
    return lists[done_at(p)] == sweep + 1u;
}

// Pair `p` claims its free particles for push round `round` (counted through the
// substep's sweeps) of sweep `sweep`; returns whether it claimed any.
fn claim_one(p: u32, round: u32, sweep: u32) -> bool {
    if (p >= pairs_kept() || pushed_in(p, sweep)) {
        return false;
    }
    let pair = pair_at(p);
    let push = push_of(pair);
    if (!push.pushed) {
        lists[key_at(p)] = 0u;
        return false;
    }
    let key = key_of(pair, round, push.depth);
    lists[key_at(p)] = key;
    var claimed = false;
    for (var k = 0u; k < 4u; k++) {
        let i = pair.ids[k];
        if (start[i].x.w > 0.0) {
            atomicMax(&atomics[owner_at(i)], key);
            claimed = true;
        }
    }
    return claimed;
}

@compute @workgroup_size(64)
fn claim(@builtin(global_invocation_id) id: vec3<u32>) {
    _ = claim_one(id.x, this_round.x, this_round.y);
}

// Pair `p` pushes its particles where it holds all the claims it made this round (its
// push is worked out again only then: most pairs of a round lose a claim).
fn push_alone_one(p: u32, sweep: u32) {
    if (p >= pairs_kept() || pushed_in(p, sweep)) {
        return;
    }
    let key = lists[key_at(p)];
    if (key == 0u) {
        return;
    }
    let pair = pair_at(p);
    for (var k = 0u; k < 4u; k++) {
        let i = pair.ids[k];
        if (start[i].x.w > 0.0 && atomicLoad(&atomics[owner_at(i)]) != key) {
            return;
        }
    }
    lists[done_at(p)] = sweep + 1u;
    let push = push_of(pair);
    if (!push.pushed) {
        return;
    }
    for (var k = 0u; k < 4u; k++) {
        let i = pair.ids[k];
        if (start[i].x.w <= 0.0) {
            continue;
        }
        var q = state[i];
        q.x = vec4<f32>(q.x.xyz + push.dx[k], q.x.w);
        q.v = vec4<f32>(q.v.xyz + push.dv[k], q.v.w);
        state[i] = q;
        tell_solver(i, push.dv[k]);
        atomicStore(&atomics[PUSHES_MOVED], 1u);
    }
}

@compute @workgroup_size(64)
fn push_alone(@builtin(global_invocation_id) id: vec3<u32>) {
    push_alone_one(id.x, this_round.y);
}

// The pairs the rounds left, side by side: each particle moves by half the sum of their
// pushes (`push_apply`), summed in fixed point so that the sum is the same in any order.
// Half, not the average: these are the pairs of a crowded contact, a stack pressed
// together, and the average of a particle's pushes, one from each layer, barely moves it
// (measured: `layers` at 8 quads pressed to 3 µm apart, where it should be 6 mm); the
// whole sum overshoots there (it blew `layers` up). Its velocity changes by the average of
// theirs: each pair takes away the whole of its sides' approach, so a particle landing on
// several triangles at once lost it several times over in half the sum (a cloth landing
// flat on another on the ground flung a corner up at ten times its landing speed).
const LEFT_SHARE: f32 = 0.5;

// Pair `p`, left by sweep `sweep`'s rounds, adds its pushes to its particles' sums.
fn push_one(p: u32, sweep: u32) {
    if (p >= pairs_kept() || pushed_in(p, sweep)) {
        return;
    }
    let pair = pair_at(p);
    let push = push_of(pair);
    if (!push.pushed) {
        return;
    }
    for (var k = 0u; k < 4u; k++) {
        if (all(push.dx[k] == vec3<f32>(0.0)) && all(push.dv[k] == vec3<f32>(0.0))) {
            continue;
        }
        let slot = pushes_at() + PUSH_WORDS * pair.ids[k];
        for (var c = 0u; c < 3u; c++) {
            add_fixed(slot + c, push.dx[k][c], MOVE_UNIT);
            add_fixed(slot + 4u + c, push.dv[k][c], SPEED_UNIT);
        }
        atomicAdd(&atomics[slot + 3u], 1u);
        atomicMax(&atomics[slot + LONGEST], bitcast<u32>(length(push.dx[k])));
    }
}

@compute @workgroup_size(64)
fn push(@builtin(global_invocation_id) id: vec3<u32>) {
    push_one(id.x, this_round.y);
}

// Particle `i` takes the side-by-side pushes summed for it: `share` of their moves' sum,
// or their average where `share` is 0, and the average of their changes of velocity.
fn take_pushes(i: u32, share: f32) {
    if (i >= sp.counts.x) {
        return;
    }
    let slot = pushes_at() + PUSH_WORDS * i;
    let count = atomicLoad(&atomics[slot + 3u]);
    if (count == 0u) {
        return;
    }
    var dx = vec3<f32>(0.0);
    var dv = vec3<f32>(0.0);
    for (var c = 0u; c < 3u; c++) {
        dx[c] = f32(bitcast<i32>(atomicLoad(&atomics[slot + c]))) * MOVE_UNIT;
        dv[c] = f32(bitcast<i32>(atomicLoad(&atomics[slot + 4u + c]))) * SPEED_UNIT;
    }
    let longest = bitcast<f32>(atomicLoad(&atomics[slot + LONGEST]));
    for (var k = 0u; k < HELD; k++) {
        atomicStore(&atomics[slot + k], 0u);
    }
    atomicStore(&atomics[slot + LONGEST], 0u);
    let average = 1.0 / f32(count);
    var shift = dx * select(share, average, share == 0.0);
    // A share of the sum moves a particle no further than its longest push: where many
    // pairs push it the same way (one landing within the thickness of a dozen of the
    // other cloth's), each alone would have moved it clear, as the CPU's sweep does with
    // the first; half their sum flung it by many thicknesses.
    let far = length(shift);
    if (share > 0.0 && far > longest) {
        shift *= longest / far;
    }
    var q = state[i];
    q.x = vec4<f32>(q.x.xyz + shift, q.x.w);
    q.v = vec4<f32>(q.v.xyz + dv * average, q.v.w);
    state[i] = q;
    tell_solver(i, dv * average);
    // The pairs' pushes (not the spheres' on the triangles, a solid's own).
    if (share > 0.0) {
        atomicStore(&atomics[PUSHES_MOVED], 1u);
    }
}

// Each particle takes its share of the side-by-side pushes.
@compute @workgroup_size(64)
fn push_apply(@builtin(global_invocation_id) id: vec3<u32>) {
    take_pushes(id.x, LEFT_SHARE);
}

// A face whose nearest point lies within this share of the offset inside the reach
// touches it and is left as it is (the CPU's `FACE_TOUCHING`).
const FACE_TOUCHING: f32 = 1e-4;

// Each triangle's interior is kept out of the spheres too, not only its corners (the
// CPU's `keep_faces_out`: the guarantee covers the surface, and a triangle over a small
// sphere dips in between its corners however far out they are): a triangle whose point
// nearest a centre is within the sphere and the offset is pushed out along the line from
// the centre, its corners by their weights and inverse masses, and that point's velocity
// loses what points in, its sliding slowed by the sphere's friction (the push lifts a
// draped face's corners past the offset, where the colliders' pass no longer touches
// them), the change shared among the corners as the push is; side by side, each corner
// taking the average.
fn faces_one(t: u32, alone: bool) {
    if (t >= sp.counts.y) {
        return;
    }
    let tri = triangles[t];
    for (var c = 0u; c < sp.passes.x; c++) {
        let col = sp.colliders[c];
        if (col.info.x != 1.0) {
            continue;
        }
        // Where the last sphere left the corners (the same where they are summed).
        var x: array<vec3<f32>, 3>;
        var inv: array<f32, 3>;
        for (var k = 0u; k < 3u; k++) {
            let q = state[tri[k]].x;
            x[k] = q.xyz;
            inv[k] = q.w;
        }
        let longest = max(distance(x[0], x[1]), max(distance(x[1], x[2]), distance(x[2], x[0])));
        let centre = col.a.xyz;
        let reach = col.info.y + sp.contact.y;
        let near = min(distance(x[0], centre), min(distance(x[1], centre), distance(x[2], centre)));
        if (near > reach + longest) {
            continue;
        }
        let w = closest_weights(centre, x[0], x[1], x[2]);
        let gap = w.x * x[0] + w.y * x[1] + w.z * x[2] - centre;
        let d = length(gap);
        let weight = w.x * w.x * inv[0] + w.y * w.y * inv[1] + w.z * w.z * inv[2];
        if (d >= reach - FACE_TOUCHING * sp.contact.y || d < 1e-9 || weight <= 0.0) {
            continue;
        }
        let n = gap / d;
        let lambda = (reach - d) / weight;
        // The surface there, spinning or not: the face's nearest point slides on it as a
        // particle resting on it would (Coulomb, the sphere's friction), the change of its
        // velocity shared among the corners as the push is.
        let v_surface = cross(col.b.xyz, n * col.info.y);
        let v = w.x * state[tri[0]].v.xyz + w.y * state[tri[1]].v.xyz + w.z * state[tri[2]].v.xyz;
        let change = (touching(v, v_surface, n, col.info.z, 1.0) - v) / weight;
        for (var k = 0u; k < 3u; k++) {
            let share = w[k] * inv[k];
            if (share <= 0.0) {
                continue;
            }
            let slot = pushes_at() + PUSH_WORDS * tri[k];
            let dx = (share * lambda) * n;
            let dv = share * change;
            if (alone) {
                // Its colour's only triangle at this corner: moved at once, and marked.
                var q = state[tri[k]];
                q.x = vec4<f32>(q.x.xyz + dx, q.x.w);
                q.v = vec4<f32>(q.v.xyz + dv, q.v.w);
                state[tri[k]] = q;
                tell_solver(tri[k], dv);
            } else {
                for (var e = 0u; e < 3u; e++) {
                    add_fixed(slot + e, dx[e], MOVE_UNIT);
                    add_fixed(slot + 4u + e, dv[e], SPEED_UNIT);
                }
            }
            atomicAdd(&atomics[slot + 3u], 1u);
        }
    }
}

@compute @workgroup_size(64)
fn faces(@builtin(global_invocation_id) id: vec3<u32>) {
    faces_one(id.x, false);
}

// Each corner takes the average of its triangles' pushes out of the spheres.
@compute @workgroup_size(64)
fn faces_apply(@builtin(global_invocation_id) id: vec3<u32>) {
    take_pushes(id.x, 0.0);
}

// Without self-contact (src/gpu/self_contact/faces.rs), after the step's colliders: the
// triangles of one colour, which share no particle (`this_round`, a colour's record as the
// coloured solvers read theirs: the first in the pass's triangles, which are in colour
// order, how many, 1 where they may share one and one invocation takes them in turn, and
// how many invocations take them, each every so many), each pushed out of the spheres at
// once, a colour after another, as the CPU's pass takes them one after another in the
// same order.
@compute @workgroup_size(64)
fn faces_coloured(@builtin(global_invocation_id) id: vec3<u32>) {
    if (this_round.z == 1u) {
        if (id.x == 0u) {
            for (var k = 0u; k < this_round.y; k++) {
                faces_one(this_round.x + k, true);
            }
        }
        return;
    }
    for (var k = id.x; k < this_round.y; k += this_round.w) {
        faces_one(this_round.x + k, true);
    }
}

// Then the planes act again on a corner the pass moved, from where it was pushed to (no
// path: it was pushed, not carried), and what lies within two offsets is settled, as the
// CPU's ground after a sphere acts on what the sphere's face pass moved: a corner pushed
// off a sphere into the ground's offset, in the wedge under it, goes back out. (Not the
// spheres: a corner the particles' pass left a rounding inside one would take its
// friction twice.)
@compute @workgroup_size(64)
fn faces_settle(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= sp.counts.x) {
        return;
    }
    let count = pushes_at() + PUSH_WORDS * i + 3u;
    if (atomicLoad(&atomics[count]) == 0u) {
        return;
    }
    atomicStore(&atomics[count], 0u);
    var q = state[i];
    var m = Motion(q.x.xyz, q.v.xyz);
    let offset = sp.contact.y;
    for (var c = 0u; c < sp.passes.x; c++) {
        if (sp.colliders[c].info.x == 2.0) {
            m = onto_plane(sp.colliders[c], offset, m);
        }
    }
    m = settle_between(sp.colliders, sp.passes.x, offset, m);
    q.x = vec4<f32>(m.x, q.x.w);
    q.v = vec4<f32>(m.v, q.v.w);
    state[i] = q;
}

// The same before the pushes, and what it moved rests on a sphere (the pushes move it only
// where nothing else in a pair can: the CPU holds what its solids moved).
@compute @workgroup_size(64)
fn faces_lift(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= sp.counts.x) {
        return;
    }
    let slot = pushes_at() + PUSH_WORDS * i;
    if (atomicLoad(&atomics[slot + 3u]) != 0u) {
        atomicOr(&atomics[slot + HELD], MOVED);
    }
    take_pushes(i, 0.0);
}

// Each particle's position before the mesh obstacles act, kept where the search will put
// its box.
@compute @workgroup_size(64)
fn before_obstacles(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i < sp.counts.x) {
        boxes[2u * i] = vec4<f32>(state[i].x.xyz, 0.0);
    }
}

// What the mesh obstacles moved rests on them, as on the CPU.
@compute @workgroup_size(64)
fn obstacles_moved(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i == 0u) {
        atomicStore(&atomics[PUSHES_MOVED], 0u);
    }
    if (i < sp.counts.x && any(boxes[2u * i].xyz != state[i].x.xyz)) {
        atomicOr(&atomics[pushes_at() + PUSH_WORDS * i + HELD], MOVED);
    }
}

