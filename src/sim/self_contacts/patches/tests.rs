//! The patches: a covered node keeps every pair of two of its triangles the reach apart
//! along the whole motion, a covered corner's ring lies in one, and the rest gap is the
//! least distance at rest.

use glam::{Quat, Vec3};

use super::*;
use crate::cloth::ClothModel;
use crate::mesh::{GridOrientation, GridSpec};
use crate::sim::self_contacts::certify::Certificates;
use crate::sim::self_contacts::primitives::distance;
use crate::sim::self_contacts::search::in_lanes;

const REACH: f32 = 0.004;

/// A `quads`² cloth 2 cm between particles, flat in the xz plane (rest gap 1.41 cm,
/// half the diagonal), with its particles moved by `shape` from rest; its triangles,
/// owners, tree and patches, and those particles.
struct Cloth {
    model: ClothModel,
    owners: Owners,
    tree: TriangleTree,
    patches: Patches,
    rest: Vec<Vec3>,
}

fn cloth(quads: u32, mut shape: impl FnMut(Vec3) -> Vec3) -> Cloth {
    let size = 0.02 * quads as f32;
    let mesh = GridSpec::square(quads, size, GridOrientation::Horizontal, Vec3::ZERO)
        .build()
        .unwrap();
    let mut mesh = mesh;
    for p in &mut mesh.positions {
        *p = shape(*p);
    }
    cloth_of(&mesh)
}

/// The cloth of `mesh`, with its owners, tree and patches.
fn cloth_of(mesh: &crate::mesh::ClothMesh) -> Cloth {
    let model = ClothModel::new(mesh, 0.2, &[]);
    let owners = Owners::build(&model);
    let rest = model.rest_positions.clone();
    let mut tree = TriangleTree::build(&model.triangles, &rest);
    let corners = Certificates::build(&owners, &model.triangles, &rest).least_at_rest();
    let patches = Patches::build(&mut tree, &model.triangles, &rest, (&owners, corners));
    Cloth {
        model,
        owners,
        tree,
        patches,
        rest,
    }
}

/// Calls `visit` with every pair of triangles `s` and `t`: each vertex of one against the
/// other, if not its corner; each edge of one against each of the other sharing no
/// particle.
fn each_pair(s: [u32; 3], t: [u32; 3], mut visit: impl FnMut(Pair)) {
    for (v, other) in [(s, t), (t, s)] {
        for &i in v.iter().filter(|i| !other.contains(i)) {
            visit(Pair::vertex_triangle(i, other));
        }
    }
    for k in 0..3 {
        for j in 0..3 {
            let (e, f) = ([s[k], s[(k + 1) % 3]], [t[j], t[(j + 1) % 3]]);
            if !e.iter().any(|i| f.contains(i)) {
                visit(Pair::edge_edge(e, f));
            }
        }
    }
}

/// The least distance, at 17 points along the motion from `from` to `to`, between the
/// sides of any pair of two triangles (or one) in `held` (pairs whose sides' boxes over
/// the motion lie `REACH` apart are passed by: they keep that far apart).
fn closest_within(triangles: &[[u32; 3]], held: &[u32], [from, to]: [&[Vec3]; 2]) -> f64 {
    let mut least = f64::INFINITY;
    for (k, &a) in held.iter().enumerate() {
        for &b in &held[k + 1..] {
            each_pair(triangles[a as usize], triangles[b as usize], |pair| {
                let ids = pair.ids();
                let side = |r: std::ops::Range<usize>| {
                    (ids[r].iter()).fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &i| {
                        (lo.min(from[i]).min(to[i]), hi.max(from[i]).max(to[i]))
                    })
                };
                let s = pair.first_side();
                let ((alo, ahi), (blo, bhi)) = (side(0..s), side(s..4));
                if (blo - ahi).max(alo - bhi).max_element() >= REACH {
                    return;
                }
                for step in 0..=16 {
                    let t = f64::from(step) / 16.0;
                    let x = ids.map(|i| from[i].as_dvec3().lerp(to[i].as_dvec3(), t));
                    least = least.min(distance(&pair, x));
                }
            });
        }
    }
    least
}

/// Decides the motion and checks every node covered below an uncovered one (the others
/// are held by those), every corner flagged and every corner whose ring holds: no pair of
/// theirs comes within the reach. Returns the triangles covered, the least distance of a
/// covered pair, and the corners whose ring holds.
fn decide_and_check(c: &mut Cloth, motion: [&[Vec3]; 2], what: &str) -> (usize, f64, usize) {
    let triangles = &c.model.triangles;
    let lanes = motion.map(in_lanes);
    let lanes = [&lanes[0][..], &lanes[1][..]];
    c.patches
        .decide(&mut c.tree, triangles, lanes, REACH, &mut Vec::new());
    let (mut covered, mut least) = (0, f64::INFINITY);
    for (i, _) in c.tree.nodes().iter().enumerate() {
        let parent = c.patches.parent[i] as usize;
        if c.tree.covered[i] && (i == 0 || !c.tree.covered[parent]) {
            let held = c.tree.held(i);
            covered += held.len();
            least = least.min(closest_within(triangles, held, motion));
        }
    }
    assert!(
        least >= f64::from(REACH),
        "{what}: a covered pair at {least}"
    );
    // Corners covered by a node, or whose ring keeps near its rest shape.
    let (start, around) = crate::mesh::triangles_around(c.rest.len(), triangles);
    let mut rings = 0;
    for corner in 0..c.rest.len() {
        let ring = &around[start[corner] as usize..start[corner + 1] as usize];
        let held = c
            .patches
            .ring_holds(corner, (triangles, ring), lanes, REACH);
        if c.patches.covers(&c.tree, corner) || held {
            let near = closest_within(triangles, ring, motion);
            assert!(
                near >= f64::from(REACH),
                "{what}: corner {corner}'s pair at {near}"
            );
            least = least.min(near);
            rings += usize::from(held);
        }
    }
    (covered, least, rings)
}

/// The cloth folds over the line x = 0, then over x = 3 cm (through the middle of a row
/// of its nodes), as the corners' test folds it (5° a substep, to 175°), wobbling by up to 3 mm and
/// turned and carried as a whole; then it is squeezed along x, then along z instead of
/// x as it moves, and jittered, more the farther along x: each time, no covered pair
/// comes within the reach, while most of the cloth is covered where it stays near its
/// rest shape and the covered pairs come near the reach where it does not; and four
/// particles are pushed along the plane towards their neighbours by the motion's end
/// alone.
#[test]
fn a_covered_patch_keeps_its_pairs_the_reach_apart() {
    let mut c = cloth(12, |p| p);
    assert!(
        (c.patches.gap - 0.01 * 2f32.sqrt()).abs() < 1e-6,
        "{}",
        c.patches.gap
    );
    let rest = c.rest.clone();
    let folded = |line: f32, fold: f32, step: usize| -> Vec<Vec3> {
        let k = step as f32;
        let turn = Quat::from_axis_angle(Vec3::new(0.3, 1.0, 0.2).normalize(), 0.07 * k);
        (rest.iter())
            .map(|&p| {
                let x = p.x - line;
                let p = if x > 0.0 {
                    Vec3::new(line + x * fold.cos(), x * fold.sin(), p.z)
                } else {
                    p
                };
                let wobble = 0.003
                    * Vec3::new(
                        (0.7 * k + 90.0 * p.x).sin(),
                        (1.3 * k + 70.0 * p.z).sin(),
                        (0.9 * k + 60.0 * (p.x + p.z)).cos(),
                    );
                turn * (p + wobble) + k * Vec3::new(0.01, -0.03, 0.02)
            })
            .collect()
    };
    let triangles = c.model.triangles.len();
    let mut least = f64::INFINITY;
    let (mut most, mut fewest) = (0, usize::MAX);
    let (mut rings_most, mut rings_fewest) = (0, usize::MAX);
    // Over the line between the two halves the tree's root splits the cloth into, where
    // the corners on the line have a ring no covered node holds; then over one through
    // a row of nodes.
    for line in [0.0, 0.03] {
        for step in 0..35 {
            let fold = |s: usize| (s as f32 * 5.0).to_radians();
            let from = folded(line, fold(step), step);
            let to = folded(line, fold(step + 1), step + 1);
            let (covered, near, held) = decide_and_check(&mut c, [&from, &to], "fold");
            least = least.min(near);
            if line > 0.0 {
                (most, fewest) = (most.max(covered), fewest.min(covered));
                (rings_most, rings_fewest) = (rings_most.max(held), rings_fewest.min(held));
            }
        }
    }
    // Flat, nearly all of it; folded, the nodes across the fold are not.
    assert!(most * 10 >= triangles * 9, "{most} of {triangles}");
    assert!(fewest * 10 <= triangles * 8, "{fewest} of {triangles}");
    // And most corners' rings, fewer folded.
    let corners = c.rest.len();
    assert!(
        rings_most * 10 >= corners * 7 && rings_fewest < rings_most,
        "{rings_fewest}–{rings_most} of {corners}"
    );
    // Squeezed along x and falling: a patch squeezed less than its rest gap allows over
    // the reach is covered (by the least it stretches any direction), one squeezed more
    // is not.
    for squeeze in [0.6, 0.3, 0.2, 0.1] {
        let from: Vec<Vec3> = rest
            .iter()
            .map(|p| Vec3::new(squeeze * p.x, p.y, p.z))
            .collect();
        let to: Vec<Vec3> = from
            .iter()
            .map(|&p| p + Vec3::new(0.0, -0.02, 0.01))
            .collect();
        let (covered, near, _) = decide_and_check(&mut c, [&from, &to], "squeezed");
        let allowed = squeeze * 0.01 * 2f32.sqrt() >= REACH * (1.0 + MARGIN);
        assert_eq!(covered > 0, allowed, "squeezed to {squeeze}: {covered}");
        least = least.min(near);
    }
    // Squeezed to 0.15 along x at the start and along z at the end: in the middle the
    // map shrinks nothing by more than 0.575, but at the ends the pairs are within the
    // reach.
    let from: Vec<Vec3> = rest
        .iter()
        .map(|p| Vec3::new(0.15 * p.x, p.y, p.z))
        .collect();
    let to: Vec<Vec3> = rest
        .iter()
        .map(|p| Vec3::new(p.x, p.y, 0.15 * p.z))
        .collect();
    let (covered, _, _) = decide_and_check(&mut c, [&from, &to], "squeezed across");
    assert_eq!(covered, 0);
    // Jittered by up to 0 mm at x = −12 cm and 12 mm at 12 cm, at the start and end.
    let mut rnd = crate::test_rng::uniform(9);
    let mut jitter = |p: Vec3| {
        let amount = 0.05 * (p.x + 0.12);
        p + amount * Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5)
    };
    let from: Vec<Vec3> = rest.iter().map(|&p| jitter(p)).collect();
    let to: Vec<Vec3> = rest.iter().map(|&p| jitter(p)).collect();
    let (covered, near, _) = decide_and_check(&mut c, [&from, &to], "jittered");
    assert!(covered > 0 && covered < triangles, "{covered}");
    least = least.min(near);
    // Four particles, far apart, pushed 11 mm along the plane by the motion's end, each
    // along another diagonal (one at least towards an edge of a triangle it is not a
    // corner of, 14 mm away at rest): the start is the rest shape, which the nodes around
    // them fit at the start but not at the end.
    let pushed = [
        (40, Vec3::new(1.0, 0.0, 1.0)),
        (46, Vec3::new(1.0, 0.0, -1.0)),
    ]
    .into_iter()
    .chain([
        (118, Vec3::new(-1.0, 0.0, 1.0)),
        (124, Vec3::new(-1.0, 0.0, -1.0)),
    ]);
    let mut to = rest.clone();
    for (i, along) in pushed {
        to[i] += 0.011 * along.normalize();
    }
    let (covered, near, _) = decide_and_check(&mut c, [&rest, &to], "pushed");
    assert!(covered > triangles / 2, "{covered}");
    least = least.min(near);
    // The certificates are used towards their limit.
    assert!(least < 2.0 * f64::from(REACH), "{least}");
}

/// A node whose certificate failed is left uncovered, untested, for the next search; after
/// two failures in a row for the next three, after three or more for the next seven; and
/// tested again after. The cloth folded at a right angle (the nodes across the fold fail),
/// then laid flat: the next search leaves those nodes uncovered, the one after covers what
/// a search with no backoff covers. Folded at every search where they are tested again,
/// three times in a row, they stay uncovered for seven flat searches and are covered at
/// the eighth.
#[test]
fn a_node_that_failed_is_tried_again_after_a_few_searches() {
    let mut c = cloth(12, |p| p);
    let rest = c.rest.clone();
    let fold: Vec<Vec3> = (rest.iter())
        .map(|&p| {
            let a = 90f32.to_radians();
            if p.x > 0.0 {
                Vec3::new(p.x * a.cos(), p.x * a.sin(), p.z)
            } else {
                p
            }
        })
        .collect();
    let mut covered = |motion: &[Vec3], backoff: &mut Vec<u8>| {
        let motion = &in_lanes(motion)[..];
        c.patches.decide(
            &mut c.tree,
            &c.model.triangles,
            [motion, motion],
            REACH,
            backoff,
        );
        c.tree.covered.clone()
    };
    let (folded, flat) = (
        covered(&fold, &mut Vec::new()),
        covered(&rest, &mut Vec::new()),
    );
    let fewer = |some: &[bool]| {
        let n = |v: &[bool]| v.iter().filter(|&&c| c).count();
        // Only nodes that the fold leaves uncovered are left out.
        let subset = (some.iter().zip(&flat).zip(&folded)).all(|((&s, &f), &o)| s == f || !s && !o);
        subset && n(some) < n(&flat)
    };
    assert!(fewer(&folded), "the fold uncovers some nodes");
    let mut backoff = Vec::new();
    assert_eq!(covered(&fold, &mut backoff), folded);
    assert!(fewer(&covered(&rest, &mut backoff)));
    assert_eq!(covered(&rest, &mut backoff), flat);
    // Failures at the searches where they are tested again: the 1st, 3rd and 7th.
    for search in 1..=7 {
        assert!(fewer(&covered(&fold, &mut backoff)), "search {search}");
    }
    for search in 1..=7 {
        assert!(fewer(&covered(&rest, &mut backoff)), "flat search {search}");
    }
    assert_eq!(covered(&rest, &mut backoff), flat);
}

/// A cloth rolled onto a cylinder of radius 10 cm across x (the normals turn 2.4 rad
/// over its 24 cm), then drifting as it unrolls to a radius of 12 cm: far from any
/// linear map of its rest shape where a node spans 12 cm, yet its triangles turn little
/// from one to the next. No covered pair comes within the reach; the triangles' turns
/// cover it in larger patches than the particles' places alone (the same cloth taken as
/// not flat).
#[test]
fn a_patch_bent_evenly_is_certified_by_its_triangles_turns() {
    let mut c = cloth(12, |p| p);
    assert!(c.patches.flat.is_some() && c.patches.convex.iter().filter(|&&x| x).count() > 8);
    // Every corner's ring that has pairs (the pairs of two triangles are taken at the
    // first corner they share).
    let with_pairs = |k: &usize| !c.owners.corner_pairs(*k).is_empty();
    assert!(
        (0..c.rest.len())
            .filter(with_pairs)
            .all(|k| c.patches.ring_convex[k])
    );
    let rolled = |rest: &[Vec3], radius: f32, drift: f32| -> Vec<Vec3> {
        (rest.iter())
            .map(|&p| {
                let a = p.x / radius;
                Vec3::new(
                    radius * a.sin() + drift,
                    radius * (1.0 - a.cos()),
                    p.z - drift,
                )
            })
            .collect()
    };
    // The covered nodes no covered node holds (the patches a walk passes by whole), and
    // the corners whose rings hold, each certificate taken alone: with the cloth's plane
    // and without it.
    let decide = |c: &mut Cloth, [from, to]: [&[Vec3]; 2], flat: &Option<Flat>| {
        c.patches.flat = flat.clone();
        let (covered, near, rings) = decide_and_check(c, [from, to], "rolled");
        let tops: Vec<u32> = (c.tree.nodes().iter().enumerate())
            .filter(|&(i, _)| {
                let parent = c.patches.parent[i] as usize;
                c.tree.covered[i] && (i == 0 || !c.tree.covered[parent])
            })
            .map(|(_, n)| n.count)
            .collect();
        (covered, near, rings, tops)
    };
    let flat = c.patches.flat.clone();
    let rest = c.rest.clone();
    let (from, to) = (rolled(&rest, 0.10, 0.0), rolled(&rest, 0.12, 0.004));
    let (turns, near, _, by_turns) = decide(&mut c, [&from, &to], &flat);
    let (places, _, _, by_places) = decide(&mut c, [&from, &to], &None);
    let triangles = c.model.triangles.len();
    // All of it either way, by the turns in a third as many patches, twice as large.
    assert!(
        turns == triangles && places == triangles,
        "{turns}, {places}"
    );
    let largest = |tops: &[u32]| tops.iter().copied().max().unwrap_or(0);
    assert!(
        largest(&by_turns) >= 2 * largest(&by_places) && by_turns.len() * 3 <= by_places.len(),
        "{by_turns:?} against {by_places:?}"
    );
    assert!(near < 4.0 * f64::from(REACH), "{near}");
}

/// An island of 2 × 2 quads in the hole of a cloth of 8 × 8 with the middle 4 × 4 cut
/// out, sliding 18 mm towards the hole's edge (2 mm from it at the end: within the
/// reach). Every triangle keeps its rest shape and the patch holding both keeps its
/// linear map (the island lies in its middle), so only that its rest shape is no convex
/// region tells that the island may meet the rest: no covered pair comes within the
/// reach. A cloth that does not lie flat at rest gets no certificate by its turns.
#[test]
fn a_patch_with_a_hole_or_off_its_plane_is_not_certified_by_turns() {
    let mut obj = String::new();
    let at = |i: i32, j: i32| (i + 4) * 9 + (j + 4) + 1;
    for i in -4..=4 {
        for j in -4..=4 {
            obj += &format!("v {} 0 {}\n", 0.02 * i as f32, 0.02 * j as f32);
        }
    }
    for i in -4..4 {
        for j in -4..4 {
            let (x, z) = (i as f32 + 0.5, j as f32 + 0.5);
            let (hole, island) = (
                x.abs() < 2.0 && z.abs() < 2.0,
                x.abs() < 1.0 && z.abs() < 1.0,
            );
            if island || !hole {
                let [a, b, c, d] = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                obj += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
            }
        }
    }
    let built = crate::mesh::obj_from_str(&obj, "island.obj").unwrap();
    let mut c = cloth_of(&built.mesh);
    assert_eq!(c.model.triangles.len(), 2 * (64 - 16 + 4));
    assert!(c.patches.flat.is_some());
    let island = |p: Vec3| p.x.abs() < 0.03 && p.z.abs() < 0.03;
    let to: Vec<Vec3> = (c.rest.iter())
        .map(|&p| {
            if island(p) {
                p + Vec3::new(0.018, 0.0, 0.0)
            } else {
                p
            }
        })
        .collect();
    let rest = c.rest.clone();
    let (covered, _, _) = decide_and_check(&mut c, [&rest, &to], "island");
    // The parts of the cloth around the hole are covered; the whole is no convex patch.
    assert!(covered > 0 && !c.patches.convex[0], "{covered}");
    // Bent at rest by a tenth of a millimetre: not flat.
    let c = cloth(12, |p| p + Vec3::new(0.0, 0.001 * (10.0 * p.x).sin(), 0.0));
    assert!(c.patches.flat.is_none() && !c.patches.convex.contains(&true));
}

/// The rest gap is the least distance between the sides of any pair at rest, found by
/// testing every two triangles: the cloth jittered at rest (so that it is not the grid's),
/// and with its four corner particles moved 12 mm inwards along the diagonal, towards
/// triangles of their ring (pairs the walk leaves to the corners' own).
#[test]
fn the_rest_gap_is_the_least_distance_at_rest() {
    let mut rnd = crate::test_rng::uniform(4);
    let jittered = cloth(8, |p| {
        p + 0.008 * Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5)
    });
    let moves = [
        (0, [1.0, 1.0]),
        (8, [-1.0, 1.0]),
        (72, [1.0, -1.0]),
        (80, [-1.0, -1.0]),
    ];
    let mut i = 0;
    let moved = cloth(8, |p| {
        let along = moves.iter().find(|m| m.0 == i).map_or(Vec3::ZERO, |m| {
            Vec3::new(m.1[0], 0.0, m.1[1]).normalize() * 0.012
        });
        i += 1;
        p + along
    });
    for c in [jittered, moved] {
        let (triangles, x) = (&c.model.triangles, &c.rest);
        let mut least = f64::from(c.owners.longest);
        for a in 0..triangles.len() {
            for b in a..triangles.len() {
                each_pair(triangles[a], triangles[b], |pair| {
                    let at = pair.ids().map(|i| x[i].as_dvec3());
                    least = least.min(distance(&pair, at));
                });
            }
        }
        assert!(least < 0.01, "{least}");
        let gap = f64::from(c.patches.gap);
        assert!(gap <= least && gap > least - 1e-9, "{gap} against {least}");
    }
}

/// Judged by the boxes, each node is certified for the rooms of its own particles: on a
/// 16 × 16-quad cloth at rest (rest gap 1.41 cm), every particle free to go 45 % of what
/// the rest gap leaves past the 4 mm thickness (4.6 mm) from its place but one corner 1 cm
/// (its reach, the thickness and twice its room, past the rest gap), the nodes that hold
/// that corner are not covered and all the others are — where a reach taken from the
/// widest room alone covered none. Every pair of two triangles of a covered node stays
/// the thickness apart with each particle its whole room off its place, in any of 40
/// random directions (so the rest gap the rooms are measured against is no more than the
/// cloth's).
#[test]
fn each_node_is_certified_for_its_own_particles_rooms() {
    let mut c = cloth(16, |p| p);
    // The particle at the cloth's least x and z.
    let corner = (0..c.rest.len())
        .min_by(|&a, &b| (c.rest[a].x + c.rest[a].z).total_cmp(&(c.rest[b].x + c.rest[b].z)))
        .unwrap();
    let mut rooms = vec![0.45 * (c.patches.gap - REACH); c.rest.len()];
    rooms[corner] = 0.01;
    let places = in_lanes(&c.rest);
    let triangles = &c.model.triangles;
    (c.patches).decide_in_rooms(
        &mut c.tree,
        triangles,
        &places,
        (REACH, &rooms),
        &mut Vec::new(),
    );
    let holds_corner = |i: usize| {
        c.tree
            .held(i)
            .iter()
            .any(|&t| triangles[t as usize].contains(&(corner as u32)))
    };
    let mut tops = Vec::new();
    for (i, _) in c.tree.nodes().iter().enumerate() {
        let parent = c.patches.parent[i] as usize;
        let certifiable = c.patches.start[i + 1] > c.patches.start[i];
        if !certifiable {
            continue;
        }
        assert_eq!(c.tree.covered[i], !holds_corner(i), "node {i}");
        if c.tree.covered[i] && (i == 0 || !c.tree.covered[parent]) {
            tops.push(i);
        }
    }
    assert!(tops.len() > 4, "{} nodes covered", tops.len());
    let mut rnd = crate::test_rng::uniform(11);
    for _ in 0..40 {
        let off: Vec<Vec3> = (c.rest.iter().zip(&rooms))
            .map(|(&p, &room)| {
                let d = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize_or_zero();
                p + d * room
            })
            .collect();
        for &i in &tops {
            let least = closest_within(triangles, c.tree.held(i), [&off, &off]);
            assert!(least >= f64::from(REACH), "node {i}: {least}");
        }
    }
    // The reach of the widest room alone: past the rest gap, nothing to certify.
    assert!(REACH + 2.0 * 0.01 >= c.patches.gap);
}
