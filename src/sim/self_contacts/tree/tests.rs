//! The tree's walks: every two triangles that share no corner and whose boxes overlap,
//! once; by the motion, no two passed by that come within the reach anywhere along it; a
//! search of some triangles finds what the whole walk finds of theirs; a fit of some
//! triangles leaves the tree as a whole fit does; and a fit by the motion tells the widest
//! triangle.

use glam::{DVec3, Quat, Vec3};

use super::*;
use crate::mesh::{GridOrientation, GridSpec};
use crate::sim::self_contacts::primitives::{Pair, distance};
use crate::sim::self_contacts::search::in_lanes;

/// A 15 × 15-quad cloth 1 m wide (450 triangles: several pieces of a walk, and leaves of
/// three triangles as well as of four), its particles jittered by up to 2 cm about the
/// plane: its triangles and rest and jittered positions.
fn cloth() -> (Vec<[u32; 3]>, Vec<Vec3>, Vec<Vec3>) {
    let mesh = GridSpec::square(15, 1.0, GridOrientation::Horizontal, Vec3::ZERO)
        .build()
        .unwrap();
    let mut rnd = crate::test_rng::uniform(11);
    let mut jitter = || Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 0.04;
    let pos = mesh.positions.iter().map(|&p| p + jitter()).collect();
    (mesh.triangles.clone(), mesh.positions.clone(), pos)
}

/// Fills the lanes past each leaf's triangles with boxes that meet everything, by boxes
/// and by motion: a walk or a search must never take them (they hold no triangle).
fn poison_empty_lanes(tree: &mut TriangleTree) {
    let everywhere = One {
        lo: Vec3A::NEG_INFINITY,
        hi: Vec3A::INFINITY,
        end_lo: Vec3A::NEG_INFINITY,
        end_hi: Vec3A::INFINITY,
    };
    for (lanes, &node) in tree.lanes.iter_mut().zip(&tree.leaves) {
        for lane in tree.nodes[node as usize].count as usize..LEAF {
            lanes.set(lane, everywhere);
        }
    }
}

/// Whether two triangles share a corner.
fn share_a_corner(a: [u32; 3], b: [u32; 3]) -> bool {
    a.iter().any(|i| b.contains(i))
}

/// The pairs of every piece's walk, each as (lower, higher), sorted; and whether any came
/// twice.
fn walked(tree: &TriangleTree) -> (Vec<(u32, u32)>, bool) {
    let mut pairs = Vec::new();
    for piece in 0..tree.pieces() {
        tree.piece_pairs(piece, |a, b| pairs.push((a.min(b), a.max(b))));
    }
    sorted(pairs)
}

/// The pairs, sorted without repeats; and whether any came twice.
fn sorted(mut pairs: Vec<(u32, u32)>) -> (Vec<(u32, u32)>, bool) {
    pairs.sort_unstable();
    let n = pairs.len();
    pairs.dedup();
    let twice = pairs.len() != n;
    (pairs, twice)
}

/// Fitted to boxes, the walk finds exactly the two triangles that share no corner and whose
/// boxes overlap, each once, over pieces of several hundred triangles and leaves short of
/// four (whose empty lanes hold no triangle).
#[test]
fn a_walk_finds_every_two_triangles_whose_boxes_overlap_once() {
    let (triangles, rest, pos) = cloth();
    let mut tree = TriangleTree::build(&triangles, &rest);
    assert!(tree.pieces() >= 3, "{} pieces", tree.pieces());
    let short = |n: &Split| TriangleTree::is_leaf(*n) && (n.count as usize) < LEAF;
    assert!(
        tree.nodes().iter().any(short),
        "no leaf short of four triangles"
    );
    // Each triangle's box, grown by 2 cm.
    let grow = Vec3::splat(0.02);
    let boxed = |t: [u32; 3]| {
        let [a, b, c] = t.map(|i| pos[i as usize]);
        (a.min(b).min(c) - grow, a.max(b).max(c) + grow)
    };
    let (lo, hi): (Vec<Vec3>, Vec<Vec3>) = triangles.iter().map(|&t| boxed(t)).unzip();
    tree.fit_boxes(&lo, &hi);
    poison_empty_lanes(&mut tree);
    let (found, twice) = walked(&tree);
    assert!(!twice, "a pair found twice");
    let mut every = Vec::new();
    for a in 0..triangles.len() {
        for b in a + 1..triangles.len() {
            let overlap = lo[a].cmple(hi[b]).all() && lo[b].cmple(hi[a]).all();
            if overlap && !share_a_corner(triangles[a], triangles[b]) {
                every.push((a as u32, b as u32));
            }
        }
    }
    assert!(every.len() > 3 * triangles.len(), "{}", every.len());
    assert_eq!(found, every);
}

/// The least distance between triangles `s` and `t`, their particles at `x`.
fn apart(s: [u32; 3], t: [u32; 3], x: &[DVec3]) -> f64 {
    let mut least = f64::INFINITY;
    let mut pair = |p: Pair| {
        least = least.min(distance(&p, p.ids().map(|i| x[i])));
    };
    for (v, other) in [(s, t), (t, s)] {
        for &i in &v {
            pair(Pair::vertex_triangle(i, other));
        }
    }
    for k in 0..3 {
        for j in 0..3 {
            pair(Pair::edge_edge(
                [s[k], s[(k + 1) % 3]],
                [t[j], t[(j + 1) % 3]],
            ));
        }
    }
    least
}

/// The particles at 33 points evenly along their straight motion from `from` to `to`.
fn along(from: &[Vec3], to: &[Vec3]) -> Vec<Vec<DVec3>> {
    (0..=32)
        .map(|k| {
            let s = f64::from(k) / 32.0;
            (from.iter().zip(to))
                .map(|(a, b)| a.as_dvec3() + s * (b.as_dvec3() - a.as_dvec3()))
                .collect()
        })
        .collect()
}

/// The least distance between triangles `s` and `t` over the particles' `samples`.
fn least_apart(s: [u32; 3], t: [u32; 3], samples: &[Vec<DVec3>]) -> f64 {
    (samples.iter())
        .map(|x| apart(s, t, x))
        .fold(f64::INFINITY, f64::min)
}

/// Fitted to the motion, the cloth folded in two, its upper half falling 8 cm through the
/// lower while turning 20° and sliding 5 cm, the lower rising 2 cm (each half as a whole):
/// no two triangles the walk passes by come within the reach at any of 33 points along the
/// motion (1 848 pairs do), while more than 91 % of all two are passed by.
#[test]
fn a_walk_by_the_motion_passes_by_nothing_that_comes_within_reach() {
    let (triangles, rest, jittered) = cloth();
    let mut tree = TriangleTree::build(&triangles, &rest);
    // Folded over x = 0: the half that was at x < 0 lies 3 cm above the other.
    let upper: Vec<bool> = rest.iter().map(|p| p.x < 0.0).collect();
    let from: Vec<Vec3> = (jittered.iter().zip(&upper))
        .map(|(&p, &up)| {
            if up {
                Vec3::new(-p.x, p.y + 0.03, p.z)
            } else {
                p
            }
        })
        .collect();
    let to: Vec<Vec3> = (from.iter().zip(&upper))
        .map(|(&p, &up)| {
            if up {
                Quat::from_rotation_y(0.35) * p + Vec3::new(0.05, -0.08, 0.0)
            } else {
                p + Vec3::new(0.0, 0.02, 0.0)
            }
        })
        .collect();
    let reach = 0.01;
    tree.fit_motion([&in_lanes(&from), &in_lanes(&to)], reach);
    poison_empty_lanes(&mut tree);
    let (found, twice) = walked(&tree);
    assert!(!twice, "a pair found twice");
    let samples = along(&from, &to);
    let (mut passed, mut near) = (0, 0);
    for a in 0..triangles.len() {
        for b in a + 1..triangles.len() {
            let (s, t) = (triangles[a], triangles[b]);
            if s.iter().any(|i| t.contains(i)) {
                continue;
            }
            let least = least_apart(s, t, &samples);
            let kept = found.binary_search(&(a as u32, b as u32)).is_ok();
            if least < f64::from(reach) {
                near += 1;
                assert!(kept, "{a} and {b} come within {least} m, passed by");
            } else if !kept {
                passed += 1;
            }
        }
    }
    let pairs = triangles.len() * (triangles.len() - 1) / 2;
    assert!(near > 100, "{near} pairs come near");
    assert!(passed > pairs * 91 / 100, "{passed} of {pairs} passed by");
}

/// A search of some triangles finds, once each, the pairs with one of them that the whole
/// walk finds: exactly by the boxes; by the motion (half the cloth falling, or all of it
/// sheared, so that each leaf moves otherwise), none more, and those fewer each keep the
/// reach apart all along the motion (the search tells a triangle apart from the nodes by
/// its own boxes, where the whole walk tells two nodes apart, and the leaves' rows in
/// their own frame are no test of two nodes: 33 points along it).
#[test]
fn a_search_of_some_triangles_finds_what_the_whole_walk_finds_of_theirs() {
    let (triangles, rest, from) = cloth();
    let mut tree = TriangleTree::build(&triangles, &rest);
    // Half the cloth falling 5 cm; and the whole sheared, each leaf moving otherwise (so
    // that two leaves' frame, wherever it is taken from, differs from either's motion).
    let moved =
        |by: &dyn Fn(Vec3) -> Vec3| -> Vec<Vec3> { from.iter().map(|&p| p + by(p)).collect() };
    let falling = moved(&|p| Vec3::new(0.0, if p.x < 0.0 { -0.05 } else { 0.0 }, 0.0));
    let sheared = moved(&|p| Vec3::new(0.4 * p.z, -0.3 * p.x, 0.2 * p.x * p.z));
    let mut rnd = crate::test_rng::uniform(3);
    let dirty: Vec<bool> = triangles.iter().map(|_| rnd() < 0.2).collect();
    let marked = |p: &(u32, u32)| dirty[p.0 as usize] || dirty[p.1 as usize];
    for motion in [None, Some(&falling), Some(&sheared)] {
        if let Some(to) = motion {
            tree.fit_motion([&in_lanes(&from), &in_lanes(to)], 0.01);
        } else {
            let (lo, hi): (Vec<Vec3>, Vec<Vec3>) = (triangles.iter())
                .map(|t| {
                    let [a, b, c] = t.map(|i| from[i as usize]);
                    (a.min(b).min(c), a.max(b).max(c))
                })
                .unzip();
            tree.fit_boxes(&lo, &hi);
        }
        poison_empty_lanes(&mut tree);
        let (whole, _) = walked(&tree);
        let mut pairs = Vec::new();
        for t in (0..triangles.len() as u32).filter(|&t| dirty[t as usize]) {
            tree.triangle_pairs(t, &dirty, |a, b| pairs.push((a.min(b), a.max(b))));
        }
        let (only, twice) = sorted(pairs);
        assert!(!twice);
        let theirs: Vec<_> = whole.iter().copied().filter(marked).collect();
        assert!(theirs.len() > 100, "{}", theirs.len());
        assert!(
            only.len() < whole.len() / 2,
            "{} of {}",
            only.len(),
            whole.len()
        );
        let Some(to) = motion else {
            assert_eq!(only, theirs, "by the boxes");
            continue;
        };
        let extra = (only.iter()).filter(|p| theirs.binary_search(p).is_err());
        assert_eq!(
            extra.count(),
            0,
            "found by the search of some, not by the whole walk"
        );
        let samples = along(&from, to);
        for &(a, b) in theirs.iter().filter(|p| only.binary_search(p).is_err()) {
            let (s, t) = (triangles[a as usize], triangles[b as usize]);
            let least = least_apart(s, t, &samples);
            assert!(
                least >= 0.01,
                "{a} and {b} come within {least} m, passed by"
            );
        }
        assert!(
            only.len() * 100 > theirs.len() * 99,
            "{} of {}",
            only.len(),
            theirs.len()
        );
    }
}

/// Fitting again only the triangles whose particles moved (a refresh) leaves every node as
/// a fit of the whole tree does, by boxes and by the motion: a moved particle's triangles
/// sit in leaves far apart in the tree, so the fit must carry each change up to the root;
/// and after a fit of the other kind, the whole tree is fitted. Each node's box is its
/// triangles' boxes together, whatever the lanes past a leaf's triangles hold.
#[test]
fn fitting_the_moved_triangles_again_leaves_the_tree_as_a_whole_fit_does() {
    let (triangles, rest, pos) = cloth();
    // A corner of the cloth and a particle in its middle move 5 cm up.
    let moved = |i: usize| i < 20 || i == 150;
    let lifted: Vec<Vec3> = (pos.iter().enumerate())
        .map(|(i, &p)| if moved(i) { p + 0.05 * Vec3::Y } else { p })
        .collect();
    let changed: Vec<u32> = (0..triangles.len() as u32)
        .filter(|&t| triangles[t as usize].iter().any(|&i| moved(i as usize)))
        .collect();
    let boxes_of = |x: &[Vec3]| -> (Vec<Vec3>, Vec<Vec3>) {
        (triangles.iter())
            .map(|t| {
                let [a, b, c] = t.map(|i| x[i as usize]);
                (a.min(b).min(c), a.max(b).max(c))
            })
            .unzip()
    };
    let whole = |fit: &dyn Fn(&mut TriangleTree)| {
        let mut tree = TriangleTree::build(&triangles, &rest);
        fit(&mut tree);
        tree
    };
    let same = |a: &TriangleTree, b: &TriangleTree, moving: bool| {
        assert!(a.boxes == b.boxes, "the nodes' boxes differ");
        assert!(!moving || a.motion == b.motion, "the nodes' motion differs");
        assert_eq!(walked(a), walked(b));
    };
    // Each node's box is its triangles' boxes together: the lanes past a leaf's
    // triangles (filled with boxes that meet everything) are left out.
    let united = |tree: &TriangleTree, lo: &[Vec3], hi: &[Vec3]| {
        for i in 0..tree.nodes().len() {
            let (l, h) = (tree.held(i).iter())
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), &t| {
                    (l.min(lo[t as usize]), h.max(hi[t as usize]))
                });
            assert_eq!(tree.boxes[i], [l.into(), h.into()], "node {i}");
        }
    };
    let ((lo, hi), (lo2, hi2)) = (boxes_of(&pos), boxes_of(&lifted));
    let mut tree = whole(&|t| t.fit_boxes(&lo, &hi));
    poison_empty_lanes(&mut tree);
    tree.fit_boxes(&lo, &hi);
    united(&tree, &lo, &hi);
    tree.refit_boxes(&changed, &lo2, &hi2);
    united(&tree, &lo2, &hi2);
    same(&tree, &whole(&|t| t.fit_boxes(&lo2, &hi2)), false);
    // By the motion: first rest → pos, then rest → lifted for the moved triangles.
    let reach = 0.01;
    let mut tree = whole(&|t| {
        t.fit_motion([&in_lanes(&rest), &in_lanes(&pos)], reach);
    });
    let widest = tree.refit_motion(&changed, [&in_lanes(&rest), &in_lanes(&lifted)], reach);
    let mut fresh = whole(&|t| {
        t.fit_motion([&in_lanes(&rest), &in_lanes(&lifted)], reach);
    });
    same(&tree, &fresh, true);
    // The moved triangles are the widest over the motion: 5 cm up and more.
    assert!(widest > 0.05, "{widest}");
    // Fitted by boxes last, a fit by the motion of some triangles fits them all.
    fresh.fit_boxes(&lo, &hi);
    fresh.refit_motion(&changed, [&in_lanes(&rest), &in_lanes(&lifted)], reach);
    same(&fresh, &tree, true);
    // Refitted again, back: the nodes fitted by the first refit are fitted by the second.
    tree.refit_motion(&changed, [&in_lanes(&rest), &in_lanes(&pos)], reach);
    let back = whole(&|t| {
        t.fit_motion([&in_lanes(&rest), &in_lanes(&pos)], reach);
    });
    same(&tree, &back, true);
}

/// A fit by the motion tells the widest any triangle's particles span along an axis over
/// the motion, wherever in the tree that triangle lies: in the first subtree fitted, the
/// last, or one between (the fit runs subtree by subtree).
#[test]
fn a_fit_by_the_motion_tells_the_widest_triangle_wherever_it_lies() {
    let (triangles, rest, pos) = cloth();
    let mut tree = TriangleTree::build(&triangles, &rest);
    assert!(tree.subtrees.len() >= 2, "{} subtrees", tree.subtrees.len());
    let widest = |to: &[Vec3]| {
        (triangles.iter())
            .map(|t| {
                let (s, e) = (t.map(|i| rest[i as usize]), t.map(|i| to[i as usize]));
                let lo = s.iter().chain(&e).fold(Vec3::INFINITY, |m, &p| m.min(p));
                let hi = s
                    .iter()
                    .chain(&e)
                    .fold(Vec3::NEG_INFINITY, |m, &p| m.max(p));
                (hi - lo).max_element()
            })
            .fold(0.0f32, f32::max)
    };
    let places = [0, tree.order.len() / 2, tree.order.len() - 1];
    for place in places {
        // A corner of the triangle at that place in the tree's order flung 3 m.
        let flung = triangles[tree.order[place] as usize][0] as usize;
        let mut to = pos.clone();
        to[flung] += Vec3::new(3.0, 0.0, 0.0);
        let told = tree.fit_motion([&in_lanes(&rest), &in_lanes(&to)], 0.01);
        assert!(told >= 3.0, "place {place}: {told}");
        assert_eq!(told, widest(&to), "place {place}");
    }
}
