//! The refresh: searching again only the triangles whose particles left their boxes gives
//! the pairs a search of the whole tree gives with the same boxes, in an order that does
//! not depend on the team's size.

use glam::Vec3;

use super::*;
use crate::mesh::{GridOrientation, GridSpec};
use crate::sim::self_contacts::primitives::{Pair, distance, push_apart};
use crate::sim::self_contacts::search::meet;
use crate::sim::self_contacts::search::pairs;
use crate::sim::self_contacts::sweeps::Sweeps;

const THICKNESS: f32 = 0.01;

thread_local! {
    /// Whether [`SelfContacts::settle`] on this thread checks every pair, as before it
    /// was narrowed to the particles the solids moved.
    pub(super) static RECHECK_EVERY_PAIR: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// How many of its calls on this thread were narrowed so.
    pub(super) static NARROWED: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// A 48 × 48-quad cloth (4 608 triangles, so the search is shared out) 1 m wide, crumpled
/// by random offsets of up to 1.5 cm, so that its particles have many pairs.
fn crumpled() -> (ClothModel, Vec<Vec3>) {
    crumpled_of(48)
}

/// [`crumpled`] with `quads`² quads.
fn crumpled_of(quads: u32) -> (ClothModel, Vec<Vec3>) {
    let (model, flat) = grid(quads, 1.0);
    let mut rnd = crate::test_rng::uniform(5);
    let mut jitter = || Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 0.03;
    let pos = flat.iter().map(|&p| p + jitter()).collect();
    (model, pos)
}

/// A flat `quads`² cloth `size` m wide in the xz plane, and its particles.
fn grid(quads: u32, size: f32) -> (ClothModel, Vec<Vec3>) {
    let mesh = GridSpec::square(quads, size, GridOrientation::Horizontal, Vec3::ZERO)
        .build()
        .unwrap();
    (ClothModel::new(&mesh, 0.2, &[]), mesh.positions)
}

/// Two 4 × 4-quad sheets 20 cm wide, one `apart` above the other (particles 0–24 below,
/// 25–49 above), all pinned or none, and their positions.
fn two_sheets(apart: f32, pinned: bool) -> (ClothModel, Vec<Vec3>) {
    let sheet = GridSpec::square(4, 0.2, GridOrientation::Horizontal, Vec3::ZERO)
        .build()
        .unwrap();
    let mesh = sheet.stacked(2, apart * Vec3::Y);
    let all: Vec<u32> = (0..mesh.positions.len() as u32).collect();
    let model = ClothModel::new(&mesh, 0.2, if pinned { &all } else { &[] });
    (model, mesh.positions)
}

/// A solver for `model` with the pairs found for every particle moving by `motion` from
/// `start`.
fn searched(model: &ClothModel, start: &[Vec3], motion: Vec3) -> SelfContacts {
    searched_to(
        model,
        start,
        &start.iter().map(|&p| p + motion).collect::<Vec<_>>(),
    )
}

/// A solver for `model` with the pairs found for the particles moving from `start` to
/// `end`.
fn searched_to(model: &ClothModel, start: &[Vec3], end: &[Vec3]) -> SelfContacts {
    let mut contacts = SelfContacts::default();
    contacts.prepare(model).unwrap();
    let moved = Moved::plain(start, end);
    contacts
        .update_pairs(model, THICKNESS, THICKNESS, Some(moved))
        .unwrap();
    contacts
}

/// Calls `visit` with each vertex–triangle and edge–edge pair of every two triangles whose
/// boxes (their particles' boxes, as `search` has them) overlap, whose sides' boxes
/// overlap too: by testing every two triangles.
fn each_overlapping_pair(search: &Search, mut visit: impl FnMut(Pair, StoredPair)) {
    let (lo, hi, triangles) = (
        &search.boxes.vertex_lo,
        &search.boxes.vertex_hi,
        search.triangles,
    );
    let boxed = |t: usize| {
        let [a, b, c] = triangles[t].map(|i| i as usize);
        (lo[a].min(lo[b]).min(lo[c]), hi[a].max(hi[b]).max(hi[c]))
    };
    for a in 0..triangles.len() {
        for b in a + 1..triangles.len() {
            if meet(boxed(a), boxed(b)) {
                (search.owners).each_pair(triangles, a, b, |pair, stored| {
                    if search.sides_meet(&pair) {
                        visit(pair, stored);
                    }
                });
            }
        }
    }
}

/// Pairs found for every particle moving by `motion` (none: the boxes get room, and the
/// pairs are judged by them alone; a fast one: by the motion too), then the particles in
/// the band `x < band` moved by `shift` more, which takes them out of their boxes, and the
/// pairs brought up to date for what `within` needs. Returns the solver and the pairs
/// before and after.
fn refreshed(
    motion: Vec3,
    (band, shift): (f32, Vec3),
    within: f32,
) -> (SelfContacts, Vec<StoredPair>, Vec<StoredPair>) {
    let (model, start) = crumpled();
    let mut contacts = searched(&model, &start, motion);
    assert_eq!(contacts.work.searches, 1);
    assert_eq!(contacts.boxes.swept, motion != Vec3::ZERO);
    let before: Vec<StoredPair> = contacts.found.stored().copied().collect();
    let end: Vec<Vec3> = (start.iter())
        .map(|&s| s + motion + if s.x < band { shift } else { Vec3::ZERO })
        .collect();
    let moved = Moved::plain(&start, &end);
    contacts
        .update_pairs(&model, THICKNESS, within, Some(moved))
        .unwrap();
    let after = contacts.found.stored().copied().collect();
    (contacts, before, after)
}

/// A fast motion for [`refreshed`]: more than half the thickness a substep.
const FAST: Vec3 = Vec3::new(0.0, 0.0, 0.6 * THICKNESS);

/// The band [`refreshed`] moves: a fifth of the cloth, 4 cm sideways.
const BAND: (f32, Vec3) = (-0.3, Vec3::new(0.0, 0.0, 0.04));

/// `f`'s result on a pool of `threads` threads (and the team of as many).
fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build();
    pool.unwrap().install(f)
}

/// The pairs as a set: sorted, each edge–edge pair's edges in order.
fn sorted(pairs: Vec<StoredPair>) -> Vec<StoredPair> {
    let mut pairs: Vec<StoredPair> = pairs.into_iter().map(StoredPair::canonical).collect();
    pairs.sort_unstable();
    pairs
}

/// A search finds exactly the pairs that testing every two triangles whose boxes overlap
/// finds — those of triangles sharing a corner from the owners' list, the others from the
/// tree — with the cloth still; and moving fast (half the cloth towards the other), less
/// the pairs of the corners the certificates closed (16 895 of the 45 886 pairs of
/// triangles sharing a corner) and a few that the tree and the line between two
/// triangles tell apart while the pairs' own tests do not (each stays a thickness apart
/// all along the motion); and many of them are of triangles that share a corner (the
/// crumpled cloth folds its neighbours close).
#[test]
fn a_search_finds_what_testing_every_two_triangles_finds() {
    let (model, start) = crumpled();
    let triangles = &model.triangles;
    // Still, and moving fast: the half x < 0 also 0.8 of the thickness a substep towards
    // the other.
    let towards = |p: Vec3| {
        if p.x < 0.0 {
            Vec3::new(0.8 * THICKNESS, 0.0, 0.0)
        } else {
            Vec3::ZERO
        }
    };
    for motion in [Vec3::ZERO, FAST] {
        let end: Vec<Vec3> = (start.iter())
            .map(|&p| {
                p + motion
                    + if motion == FAST {
                        towards(p)
                    } else {
                        Vec3::ZERO
                    }
            })
            .collect();
        let contacts = searched_to(&model, &start, &end);
        let found = sorted(contacts.found.stored().copied().collect());
        let search = contacts.search(triangles, THICKNESS);
        let mut every = Vec::new();
        each_overlapping_pair(&search, |pair, stored| {
            search.keep(pair, stored, &mut every)
        });
        // Moving fast, the pairs of the corners the certificates closed are left out.
        let mut closed = Vec::new();
        if contacts.boxes.swept {
            let open = &contacts.certificates.open;
            for c in (0..start.len()).filter(|&c| !open[c]) {
                closed.extend_from_slice(contacts.owners.corner_pairs(c));
            }
        }
        let closed = sorted(closed);
        eprintln!(
            "closed {} of {}",
            closed.len(),
            contacts.owners.neighbours.len()
        );
        every.retain(|p| closed.binary_search(&p.canonical()).is_err());
        let every = sorted(every);
        let owner = &contacts.owners.vertex_owner;
        let neighbours = (every.iter())
            .filter(|p| {
                let [a, b] = p.triangles(owner).map(|t| triangles[t as usize]);
                a.iter().any(|i| b.contains(i))
            })
            .count();
        assert!(neighbours > 1000, "{neighbours} of {}", every.len());
        if !contacts.boxes.swept {
            assert!(
                found == every,
                "{} found, {} by testing every two",
                found.len(),
                every.len()
            );
            continue;
        }
        // Judged by the motion, the tree and the line between two triangles pass by some
        // pairs that the pairs' own tests, looser, would keep: each such pair stays a
        // thickness apart at every one of 33 points along the motion.
        let extra: Vec<_> = (found.iter())
            .filter(|p| every.binary_search(p).is_err())
            .collect();
        assert!(
            extra.is_empty(),
            "{} found that testing every two does not keep",
            extra.len()
        );
        let passed: Vec<_> = (every.iter())
            .filter(|p| found.binary_search(p).is_err())
            .collect();
        for stored in &passed {
            let pair = stored.expand(triangles, &contacts.owners.edges);
            let least = (0..=32)
                .map(|k| {
                    let t = f64::from(k) / 32.0;
                    let x = pair.ids().map(|i| {
                        let (a, b) = (start[i].as_dvec3(), end[i].as_dvec3());
                        a + t * (b - a)
                    });
                    distance(&pair, x)
                })
                .fold(f64::INFINITY, f64::min);
            assert!(
                least >= f64::from(THICKNESS),
                "{pair:?} passed by at {least} m"
            );
        }
        assert!(
            passed.len() < found.len() / 100,
            "{} of {} passed by",
            passed.len(),
            found.len()
        );
    }
}

/// Judged by the boxes (the cloth still), the pairs hold wherever each particle lies in its
/// box less half the thickness: with the crumpled cloth's particles at the corners of
/// that room, and at random points in it, every vertex–triangle and edge–edge pair that
/// comes within the thickness is among the pairs found.
#[test]
fn pairs_judged_by_the_boxes_hold_anywhere_in_them() {
    let (model, start) = crumpled();
    let contacts = searched(&model, &start, Vec3::ZERO);
    assert!(!contacts.boxes.swept);
    let found = pairs(&contacts.found, &model.triangles, &contacts.owners);
    let held: std::collections::HashSet<[u32; 5]> = found.map(|p| pair_key(&p)).collect();
    let (lo, hi) = (&contacts.boxes.vertex_lo, &contacts.boxes.vertex_hi);
    let room = Vec3::splat(0.5 * THICKNESS);
    let mut rnd = crate::test_rng::uniform(9);
    for corners in [true, false] {
        let pos: Vec<Vec3> = (lo.iter().zip(hi))
            .map(|(&l, &h)| {
                let u = Vec3::new(rnd(), rnd(), rnd());
                l + room + (h - l - 2.0 * room) * if corners { u.round() } else { u }
            })
            .collect();
        let close =
            |p: &Pair| distance(p, p.ids().map(|i| pos[i].as_dvec3())) < f64::from(THICKNESS);
        let near = pairs_near(&model.triangles, [&pos, &pos], THICKNESS, close);
        let missed = near.iter().filter(|k| !held.contains(*k)).count();
        assert!(near.len() > 1000, "{} near", near.len());
        assert_eq!(missed, 0, "of {} near", near.len());
    }
}

/// Every vertex–triangle and edge–edge pair of `triangles` for which `close` holds, by
/// [`pair_key`], of those whose particles' boxes over the motion from `start` to `end`
/// come within `within` of each other (by brute force over the triangles, swept along x):
/// the pairs the checks hold the solver's against.
fn pairs_near(
    triangles: &[[u32; 3]],
    [start, end]: [&[Vec3]; 2],
    within: f32,
    close: impl Fn(&Pair) -> bool,
) -> Vec<[u32; 5]> {
    let boxes: Vec<(Vec3, Vec3)> = (triangles.iter())
        .map(|t| {
            let (lo, hi) = (t.iter()).fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &i| {
                let (s, e) = (start[i as usize], end[i as usize]);
                (lo.min(s).min(e), hi.max(s).max(e))
            });
            (lo, hi + within)
        })
        .collect();
    let mut by_x: Vec<usize> = (0..triangles.len()).collect();
    by_x.sort_by(|&a, &b| boxes[a].0.x.total_cmp(&boxes[b].0.x));
    let mut near = Vec::new();
    for (k, &a) in by_x.iter().enumerate() {
        for &b in by_x[k + 1..]
            .iter()
            .take_while(|&&b| boxes[b].0.x <= boxes[a].1.x)
        {
            if !meet(boxes[a], boxes[b]) {
                continue;
            }
            let (ta, tb) = (triangles[a], triangles[b]);
            let mut each = vec![];
            for (s, t) in [(ta, tb), (tb, ta)] {
                each.extend(
                    s.iter()
                        .filter(|v| !t.contains(v))
                        .map(|&v| Pair::vertex_triangle(v, t)),
                );
            }
            for j in 0..3 {
                for k in 0..3 {
                    let (e, f) = ([ta[j], ta[(j + 1) % 3]], [tb[k], tb[(k + 1) % 3]]);
                    if !e.iter().any(|i| f.contains(i)) {
                        each.push(Pair::edge_edge(e, f));
                    }
                }
            }
            near.extend(each.iter().filter(|p| close(p)).map(pair_key));
        }
    }
    near.sort_unstable();
    near.dedup();
    near
}

/// A band of a fifth of the cloth moved 4 cm sideways: only its triangles are searched
/// again (one refresh, no second search of the whole tree), and the pairs are those a
/// search of the whole tree finds with the boxes as they now are — the band's new pairs
/// found, its old ones gone, the rest kept: exactly, where the pairs were judged by their
/// boxes (the cloth still); less a few pairs that stay apart, where by the motion too
/// (the cloth moving fast).
#[test]
fn a_refresh_finds_what_a_whole_search_finds() {
    let model = crumpled().0;
    for (motion, within, least) in [
        (Vec3::ZERO, THICKNESS, 10_000),
        (FAST, CHECKED * THICKNESS, 1000),
    ] {
        let (mut contacts, before, after) = refreshed(motion, BAND, within);
        assert_eq!((contacts.work.searches, contacts.work.refreshes), (1, 1));
        let refreshed = contacts.work.refreshed as usize;
        assert!(
            refreshed > 500 && refreshed < model.triangles.len() / 3,
            "{refreshed}"
        );
        assert_ne!(
            sorted(before.clone()),
            sorted(after.clone()),
            "the band moved"
        );
        let kept = before.iter().filter(|p| after.contains(p)).count();
        assert!(kept > before.len() / 2, "{kept} of {}", before.len());
        contacts.search_all(&model, THICKNESS).unwrap();
        let whole: Vec<StoredPair> = contacts.found.stored().copied().collect();
        assert!(whole.len() > least, "{}", whole.len());
        let (after, whole) = (sorted(after), sorted(whole));
        let extra: Vec<_> = (after.iter())
            .filter(|p| whole.binary_search(p).is_err())
            .collect();
        let missing: Vec<_> = (whole.iter())
            .filter(|p| after.binary_search(p).is_err())
            .collect();
        // By the motion, a refresh tells its triangles apart from the whole tree's nodes,
        // not from those the whole walk pairs them with: it may pass by a few pairs more,
        // each of which stays the reach apart along the motion (at every one of 33
        // points); by the boxes, the tests are the same.
        let ([from, to], reach) = (contacts.boxes.paths(), contacts.reach(THICKNESS));
        let passed = |stored: &&StoredPair| {
            let pair = stored.expand(&model.triangles, &contacts.owners.edges);
            (0..=32).all(|k| {
                let t = f64::from(k) / 32.0;
                let x = (pair.ids()).map(|i| (from[i] + (to[i] - from[i]) * t as f32).as_dvec3());
                distance(&pair, x) >= f64::from(reach)
            })
        };
        let unexplained = missing
            .iter()
            .filter(|p| motion == Vec3::ZERO || !passed(p));
        assert!(
            extra.is_empty() && unexplained.count() == 0 && missing.len() < whole.len() / 100,
            "{} pairs not in the whole search's {}, {} of its missing: {:?} {:?}",
            extra.len(),
            whole.len(),
            missing.len(),
            &extra[..extra.len().min(5)],
            &missing[..missing.len().min(5)]
        );
    }
}

/// Where the cloth moves fast the pairs are judged by the motion too, and then hold only
/// while every particle ends within the slack of where it did (half of what `within`
/// leaves of the thickness): a particle moved 0.45 of the thickness (0.26 along each axis,
/// inside its box) is searched again for the checks (0.2 × thickness), one moved 0.35 is
/// not. Judged by the boxes alone, the pairs hold while each particle lies in its box less
/// half the thickness (a room of a quarter of it each way, whatever the checks need): the
/// particle moved 0.45 is searched again, one moved 0.4 (0.23 along each axis) is not.
/// Checked next for the pushes (the whole thickness: no slack), with no particle moved
/// since, the particle moved 0.35 is searched again: a check that asks more checks every
/// particle.
#[test]
fn pairs_judged_by_the_motion_hold_within_the_slack() {
    let nudge = |by: f32| (-0.49, Vec3::splat(by * THICKNESS / 3f32.sqrt()));
    let cases = [
        (FAST, 0.45, 1),
        (FAST, 0.35, 0),
        (Vec3::ZERO, 0.45, 1),
        (Vec3::ZERO, 0.4, 0),
    ];
    for (motion, by, searched) in cases {
        let (mut contacts, _, _) = refreshed(motion, nudge(by), CHECKED * THICKNESS);
        let work = contacts.work;
        assert_eq!(
            work.searches + work.refreshes,
            1 + searched,
            "{motion} {by}"
        );
        if motion == FAST && searched == 0 {
            let model = crumpled().0;
            contacts
                .update_pairs(&model, THICKNESS, THICKNESS, None)
                .unwrap();
            assert_eq!(contacts.work.searches + contacts.work.refreshes, 2);
        }
    }
}

/// Where a quarter or more of the particles left their boxes, the whole tree is searched.
#[test]
fn many_particles_out_of_their_boxes_search_the_whole_tree() {
    let (contacts, _, _) = refreshed(Vec3::ZERO, (0.1, BAND.1), THICKNESS);
    assert_eq!((contacts.work.searches, contacts.work.refreshes), (2, 0));
}

/// A refresh shared out between two threads stores its pairs in the same order as on one.
#[test]
fn a_refresh_stores_the_same_order_on_two_threads_as_on_one() {
    let run = |threads: usize| on_threads(threads, || refreshed(Vec3::ZERO, BAND, THICKNESS));
    let ((one, _, a), (two, _, b)) = (run(1), run(2));
    assert!(one.work.refreshed as usize >= PARALLEL_REFRESHED);
    assert_eq!(two.work.refreshes, 1);
    assert_eq!(a, b);
}

/// The continuous check's rounds, shared out between two threads, cut the motion to the
/// same bits as on one: each particle keeps its smallest cut, whichever thread found it.
#[test]
fn the_checks_cut_the_same_bits_on_two_threads_as_on_one() {
    let run = |threads: usize| {
        on_threads(threads, || {
            let (_, _, state, contacts) = resolved_once(9, Vec3::ZERO, 0.04);
            (state, contacts.work)
        })
    };
    let ((one, work), (two, _)) = (run(1), run(2));
    assert!(work.candidates as usize >= PARALLEL_PAIRS, "{work:?}");
    assert!(work.impacts > 500, "{work:?}");
    assert!(one.pos == two.pos && one.vel == two.vel);
}

/// The per-particle loops shared out between two threads (the moving frame, the
/// particles' checks against their boxes and paths, a whole search's boxes) on a cloth
/// large enough to share them: three substeps of a crumpled 64 × 64-quad cloth falling and
/// rippling (its pairs judged by the motion, found for windows and checked along them)
/// end in the same bits, with the same pairs, as on one thread.
#[test]
fn a_cloth_large_enough_to_share_its_particles_resolves_the_same_on_two_threads() {
    let run = |threads: usize| {
        on_threads(threads, || {
            let (model, start) = crumpled_of(64);
            assert!(start.len() >= crate::parallel::PARALLEL_ELEMENTS);
            let mut contacts = SelfContacts::default();
            let (mut from, mut ends) = (start, Vec::new());
            for k in 0..3 {
                let mut state = ClothState::at_rest(&model);
                let ripple = |p: Vec3| 0.006 * (10.0 * p.x + 7.0 * p.z + k as f32).sin();
                state.pos = (from.iter())
                    .map(|&p| p + Vec3::new(0.0, -0.02 + ripple(p), 0.0))
                    .collect();
                (contacts.resolve([THICKNESS, 0.3], &model, &from, &mut state)).unwrap();
                from.clone_from(&state.pos);
                ends.push(state.pos);
            }
            assert!(contacts.boxes.swept && contacts.work.searches + contacts.work.refreshes > 0);
            (ends, sorted(contacts.found.stored().copied().collect()))
        })
    };
    let ((one, found), (two, found_two)) = (run(1), run(2));
    assert!(found.len() > 1000, "{} pairs", found.len());
    assert!(one == two && found == found_two);
}

/// A solver that served one cloth and is handed another with as many particles and
/// triangles rebuilds what it derived from the triangles and drops its pairs and its
/// corners' references. The same triangles in reverse order (each pair's stored triangle
/// numbers now name others), the cloth still: it resolves the new cloth to the same bits
/// as a fresh solver. Each triangle's corners turned round (the same rings and frames,
/// but other owners, so other pairs at each corner), its halves moving apart fast (where
/// the corners are decided): it takes every corner's reference afresh, as a fresh solver
/// does (its frame has moved with the first cloth, so the bits may differ).
#[test]
fn a_solver_handed_another_cloth_forgets_the_first() {
    let (model, start) = crumpled();
    let mut reversed = model.clone();
    reversed.triangles.reverse();
    let mut turned = model.clone();
    turned.triangles.iter_mut().for_each(|t| t.rotate_left(1));
    for (motion, other) in [(Vec3::ZERO, reversed), (FAST, turned)] {
        let step = |solver: &mut SelfContacts, model: &ClothModel| {
            let mut state = ClothState::at_rest(model);
            // The halves moving apart: in the frame of the mean motion too.
            let side = |p: Vec3| if p.x < 0.0 { -1.0 } else { 1.0 };
            state.pos = start.iter().map(|&p| p + side(p) * motion).collect();
            solver
                .resolve([THICKNESS, 0.3], model, &start, &mut state)
                .unwrap();
            (state, solver.work)
        };
        let mut reused = SelfContacts::default();
        step(&mut reused, &model);
        let (again, again_work) = step(&mut reused, &other);
        let (fresh, fresh_work) = step(&mut SelfContacts::default(), &other);
        assert!(fresh.pos != start, "the pushes moved something");
        if motion == Vec3::ZERO {
            assert!(again.pos == fresh.pos && again.vel == fresh.vel);
        }
        assert_eq!(again_work.retaken, fresh_work.retaken, "{motion}");
        if motion == FAST {
            assert!(fresh_work.retaken > 1000, "{fresh_work:?}");
        }
    }
}

/// Each pair of the cloth's particles that could be a contact — a vertex and a triangle it
/// is not a corner of, two edges that share no particle — keyed by its particles (a
/// triangle's and each edge's in order).
fn pair_key(pair: &Pair) -> [u32; 5] {
    let [i, j, k, l] = pair.ids().map(|i| i as u32);
    if pair.edges() {
        let (e, f) = ([i.min(j), i.max(j)], [k.min(l), k.max(l)]);
        let (e, f) = (e.min(f), e.max(f));
        [1, e[0], e[1], f[0], f[1]]
    } else {
        let mut t = [j, k, l];
        t.sort_unstable();
        [0, i, t[0], t[1], t[2]]
    }
}

/// The pushes' sweeps pass a pair by only where its test would leave it: on the crumpled
/// cloth squeezed to a third of its height, moving, the sweeps (in the slabs' groups, as
/// that many pairs go) end at the same positions and velocities, to the bit, as sweeps in
/// the same order that test every pair left in every time (the first sweep leaving out
/// those twice the thickness apart), with as many pushes.
#[test]
fn the_sweeps_pass_by_only_pairs_their_test_would_leave() {
    let (model, start) = crumpled();
    let end: Vec<Vec3> = (start.iter())
        .map(|p| Vec3::new(p.x, 0.3 * p.y, p.z))
        .collect();
    let contacts = searched_to(&model, &start, &end);
    let mut state = ClothState::at_rest(&model);
    state.pos.clone_from(&end);
    let mut rnd = crate::test_rng::uniform(8);
    (state.vel.iter_mut()).for_each(|v| *v = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5));
    let at = [THICKNESS, 0.3, 2.0 * THICKNESS];
    let mut swept = state.clone();
    let owners = &contacts.owners;
    let found = (&contacts.found, owners);
    let pushes = Sweeps::default().push(4, found, at, &model, &start, &mut swept, &[]);
    let mut every = state.clone();
    let mut left_out = vec![false; contacts.found.len()];
    let mut every_pushes = 0;
    let (order, grouped) = Sweeps::default().order(found, &model, &end);
    assert!(grouped, "{} pairs go through in groups", order.len());
    for sweep in 0..4 {
        for (pair, out) in order.iter().zip(&mut left_out) {
            if *out {
                continue;
            }
            let within = if sweep == 0 { at[2] } else { THICKNESS };
            let pair_at = [THICKNESS, 0.3, within];
            match push_apart(pair, pair_at, &model, &start, &mut every, &[]) {
                Err(apart) => *out = sweep == 0 && apart >= within,
                Ok(pushed) => every_pushes += usize::from(pushed),
            }
        }
    }
    assert!(pushes > 1000, "{pushes} pushes");
    assert_eq!(pushes, every_pushes);
    assert!(swept.pos == every.pos && swept.vel == every.vel);
}

/// Judged by the boxes, a pair is kept exactly where the smallest balls around its
/// particles' boxes less half the thickness come within the thickness (the distance
/// between the boxes' centres less the largest radius of each side), however near two
/// of its particles' centres are.
#[test]
fn pairs_judged_by_the_boxes_are_kept_exactly_where_their_balls_come_near() {
    let (model, start) = crumpled();
    let contacts = searched_to(&model, &start, &start);
    assert!(!contacts.boxes.swept);
    let search = contacts.search(&model.triangles, THICKNESS);
    let (lo, hi) = (&contacts.boxes.vertex_lo, &contacts.boxes.vertex_hi);
    let centre = |i: usize| (0.5 * (lo[i] + hi[i])).as_dvec3();
    let radius = |i: usize| 0.5 * f64::from((hi[i] - lo[i] - THICKNESS).max(Vec3::ZERO).length());
    let (mut kept, mut passed) = (0, 0);
    each_overlapping_pair(&search, |pair, stored| {
        let (ids, k) = (pair.ids(), pair.first_side());
        let most = |r: std::ops::Range<usize>| r.map(|j| radius(ids[j])).fold(0.0, f64::max);
        let apart = distance(&pair, ids.map(centre)) - most(0..k) - most(k..4);
        let mut out = Vec::new();
        search.keep(pair, stored, &mut out);
        assert_eq!(!out.is_empty(), apart < f64::from(THICKNESS), "{apart}");
        (kept, passed) = (kept + out.len(), passed + 1 - out.len());
    });
    assert!(
        kept > 1000 && passed > 1000,
        "{kept} kept, {passed} passed by"
    );
}

mod boxes;
mod cuts;
mod refusals;
mod settle;
mod trickle;
mod windows;

impl<'a> Moved<'a> {
    /// The motion from `start` to `end` in a frame that has not moved.
    fn plain(start: &'a [Vec3], end: &'a [Vec3]) -> Self {
        Moved {
            start,
            end,
            shift: Vec3::ZERO,
            mean: Vec3::ZERO,
        }
    }
}

/// The substeps (counted from 1) at which the particles of `start`'s left half, creeping
/// along x at `v` a substep while the rest stays, leave their boxes the first and the
/// second time, and the pairs per particle the first time (whose count the new boxes are
/// made by; judged by the boxes: the creep is slow).
fn creeping(model: &ClothModel, start: &[Vec3], v: f32) -> ([usize; 2], f32) {
    let at = |k: usize| -> Vec<Vec3> {
        let shift = Vec3::X * v * k as f32;
        (start.iter())
            .map(|&p| if p.x < 0.0 { p + shift } else { p })
            .collect()
    };
    let mut contacts = searched_to(model, &at(0), &at(1));
    assert!(!contacts.boxes.swept);
    let (mut out, mut per_particle) = (Vec::new(), 0.0);
    for k in 1..100 {
        let found = contacts.found.len() as f32 / start.len() as f32;
        let (from, to) = (at(k), at(k + 1));
        let moved = Moved::plain(&from, &to);
        contacts
            .update_pairs(model, THICKNESS, THICKNESS, Some(moved))
            .unwrap();
        if contacts.work.searches + contacts.work.refreshes > 1 + out.len() as u64 {
            if out.is_empty() {
                per_particle = found;
            }
            out.push(k);
        }
        if out.len() == 2 {
            break;
        }
    }
    ([out[0], out[1]], per_particle)
}

/// Judged by the boxes, particles creeping at 0.045 of the thickness a substep keep
/// their boxes for their motion carried on 24 substeps, up to a whole thickness, where the
/// pairs are few (a flat cloth: a third of a pair a particle), and leave them after 12
/// where they are many (the crumpled cloth: boxes carried on 12 substeps, up to a quarter
/// of the thickness, so that a stack of cloths pushed about does not keep long boxes and
/// more pairs). A box holds its particle while it lies ¼ of the thickness inside, past the
/// room carried on. The first boxes, found with no pairs before, are all carried on as
/// where they are few.
#[test]
fn a_creeping_particle_keeps_its_box_longer_where_the_pairs_are_few() {
    let v = 0.045 * THICKNESS;
    let (crumpled, start) = crumpled();
    let ([first, second], per_particle) = creeping(&crumpled, &start, v);
    assert!(per_particle >= 1.0, "{per_particle} pairs a particle");
    // Out once crept past ¼ + 1 thickness (1.25 / 0.045 = 27.8 substeps), then past
    // ¼ + ¼ from where it was out (11.1).
    assert_eq!([first, second - first], [28, 12]);
    let (flat, start) = grid(24, 1.0);
    let ([first, second], per_particle) = creeping(&flat, &start, v);
    assert!(per_particle < 1.0, "{per_particle} pairs a particle");
    assert_eq!([first, second - first], [28, 28]);
}

/// A [`crumpled`] cloth's start, and a solver and the state after it resolved one substep
/// that moved every particle by `motion` and up to half of `jitter` more along each axis
/// (at random from `seed`).
fn resolved_once(
    seed: u64,
    motion: Vec3,
    jitter: f32,
) -> (ClothModel, Vec<Vec3>, ClothState, SelfContacts) {
    let (model, start) = crumpled();
    let mut rnd = crate::test_rng::uniform(seed);
    let mut state = ClothState::at_rest(&model);
    for (p, s) in state.pos.iter_mut().zip(&start) {
        *p = *s + motion + Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * jitter;
    }
    let mut contacts = SelfContacts::default();
    (contacts.resolve([THICKNESS, 0.3], &model, &start, &mut state)).unwrap();
    (model, start, state, contacts)
}

/// After a substep whose pushes moved many particles (a crumpled cloth, still or moving
/// fast, each particle jittered by up to 2 or 4 mm more along each axis), every
/// particle's motion as pushed and cut still lies in its box less what the continuous
/// check needs and, judged by the motion, near its path: a check of every particle again
/// finds none out, so the pairs the check went through hold for that motion. (Only the
/// pushed particles are checked after the pushes: the others' motion is as checked before
/// them.)
#[test]
fn the_pairs_hold_for_the_motion_as_pushed_and_cut() {
    for (motion, jitter) in [(Vec3::ZERO, 0.004), (FAST, 0.008)] {
        let (model, start, state, mut contacts) = resolved_once(11, motion, jitter);
        let work = contacts.work;
        assert!(work.contacts > 100, "{work:?}");
        // Every particle checked again for the motion as it ended, in the frame it was
        // resolved in.
        let moved = Moved {
            start: &start,
            end: &state.pos,
            shift: Vec3::ZERO,
            mean: contacts.mean,
        };
        (contacts.update_pairs(&model, THICKNESS, CHECKED * THICKNESS, Some(moved))).unwrap();
        let again = contacts.work;
        assert_eq!(
            (again.searches, again.refreshes),
            (work.searches, work.refreshes),
            "{motion}"
        );
    }
}
