// Self-contact by one workgroup (appended to shaders/self_pushes.wgsl; src/gpu/self_contact.rs
// picks it for a small cloth): each phase of a substep in one dispatch (the search, the
// pushes' sweeps, the colliders' second pass, the cuts), where the wide path dispatches
// each step of each round over the whole device, about a hundred dispatches a substep.
// The steps are the wide path's own functions, in its order, with a barrier where it ends a
// dispatch; each result is a fixed-point sum, an atomic maximum or minimum, or the write of
// the one pair or particle that owns it, so both paths give the same bits. Where a round
// of pushes or cuts finds nothing to do, every later one would find the same, and the team
// stops there (the wide path dispatches them, and they return at once). On the software
// adapter a dispatch costs far more than a small cloth's work in it.

var<workgroup> team_count: u32;
var<workgroup> team_any: atomic<u32>;
var<workgroup> team_flag: u32;

// Whether any invocation of the team says `mine`, the same answer for every invocation.
fn any_in_team(l: u32, mine: bool) -> bool {
    if (mine) {
        atomicOr(&team_any, 1u);
    }
    workgroupBarrier();
    if (l == 0u) {
        team_flag = atomicExchange(&team_any, 0u);
    }
    return workgroupUniformLoad(&team_flag) != 0u;
}

// `count` as invocation 0 reads it, the same for every invocation of the team (a count
// the search kept: its pairs, or its pairs of triangles).
fn for_team(l: u32, count: u32) -> u32 {
    if (l == 0u) {
        team_count = count;
    }
    return workgroupUniformLoad(&team_count);
}

// The substep's pairs: the counters cleared, the particles' and triangles' boxes, the grid,
// the pairs of triangles, their pairs (the wide path's `clear`, `particle_boxes`, `insert`,
// `find` and `pairs_of_triangles`).
@compute @workgroup_size(WIDTH)
fn search_together(@builtin(local_invocation_index) l: u32) {
    for (var i = l; i < COUNTERS + sp.counts.z; i += WIDTH) {
        clear_one(i);
    }
    storageBarrier();
    for (var i = l; i < sp.counts.x; i += WIDTH) {
        particle_boxes_one(i);
    }
    storageBarrier();
    for (var t = l; t < sp.counts.y; t += WIDTH) {
        insert_one(t);
    }
    storageBarrier();
    for (var t = l; t < sp.counts.y; t += WIDTH) {
        find_one(t);
    }
    storageBarrier();
    let n = for_team(l, triangle_pairs_found());
    for (var q = l; q < n; q += WIDTH) {
        pairs_of_one(q);
    }
    storageBarrier();
    if (l == 0u) {
        _ = end_search();
    }
}

// Each particle takes `share` of the side-by-side pushes summed for it.
fn take_pushes_together(l: u32, share: f32) {
    for (var i = l; i < sp.counts.x; i += WIDTH) {
        take_pushes(i, share);
    }
}

// The sweeps of push rounds, each with what its rounds leave pushed side by side.
@compute @workgroup_size(WIDTH)
fn pushes_together(@builtin(local_invocation_index) l: u32) {
    let n = for_team(l, pairs_kept());
    for (var sweep = 0u; sweep < sp.passes.y; sweep++) {
        for (var r = 0u; r < sp.passes.z; r++) {
            let round = sweep * sp.passes.z + r;
            var mine = false;
            for (var p = l; p < n; p += WIDTH) {
                if (claim_one(p, round, sweep)) {
                    mine = true;
                }
            }
            storageBarrier();
            // A round in which no pair claims a particle finds every pair not yet pushed
            // this sweep apart: the rest of the sweep moves nothing, and if it is the
            // sweep's first round nor does any later sweep.
            if (!any_in_team(l, mine)) {
                if (r == 0u) {
                    return;
                }
                break;
            }
            for (var p = l; p < n; p += WIDTH) {
                push_alone_one(p, sweep);
            }
            storageBarrier();
        }
        for (var p = l; p < n; p += WIDTH) {
            push_one(p, sweep);
        }
        storageBarrier();
        take_pushes_together(l, LEFT_SHARE);
        storageBarrier();
    }
}

// The colliders again on what the pushes moved, and the triangles kept out of the spheres.
@compute @workgroup_size(WIDTH)
fn solids_together(@builtin(local_invocation_index) l: u32) {
    for (var i = l; i < sp.counts.x; i += WIDTH) {
        solids_one(i);
    }
    storageBarrier();
    for (var t = l; t < sp.counts.y; t += WIDTH) {
        faces_one(t, false);
    }
    storageBarrier();
    take_pushes_together(l, 0.0);
}

// The rounds of cuts on the motion as pushed, then each particle's end.
@compute @workgroup_size(WIDTH)
fn cuts_together(@builtin(local_invocation_index) l: u32) {
    let n = for_team(l, pairs_kept());
    for (var r = 0u; r < sp.more.w; r++) {
        // A round runs only after one that cut something (`cut_one`); the rounds not run
        // leave their counters cleared, as the wide path's rounds that return at once do.
        if (r > 0u && !any_in_team(l, l == 0u && cut_something(r - 1u))) {
            break;
        }
        for (var p = l; p < n; p += WIDTH) {
            cut_one(p, r);
        }
        storageBarrier();
        for (var i = l; i < sp.counts.x; i += WIDTH) {
            cut_apply_one(i);
        }
        storageBarrier();
    }
    for (var i = l; i < sp.counts.x; i += WIDTH) {
        finish_one(i);
    }
}
