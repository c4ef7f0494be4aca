//! The certificates: a corner they leave closed keeps every pair of its a thickness apart
//! along the whole motion, and a cloth that only turns and moves keeps its references.

use glam::{Quat, Vec3};

use super::*;
use crate::cloth::ClothModel;
use crate::mesh::{GridOrientation, GridSpec};
use crate::sim::self_contacts::primitives::distance;

const THICKNESS: f32 = 0.006;

/// An 8 × 8-quad cloth 16 cm wide (2 cm between particles), flat in the xz plane, its
/// owners, and its particles.
fn flat() -> (ClothModel, Owners, Vec<Vec3>) {
    let mesh = GridSpec::square(8, 0.16, GridOrientation::Horizontal, Vec3::ZERO)
        .build()
        .unwrap();
    let model = ClothModel::new(&mesh, 0.2, &[]);
    let owners = Owners::build(&model);
    (model, owners, mesh.positions)
}

/// The least distance between the sides of each pair of corner `c`, at 33 points along
/// the straight-line motion from `from` to `to`.
fn closest_along(
    owners: &Owners,
    triangles: &[[u32; 3]],
    c: usize,
    [from, to]: [&[Vec3]; 2],
) -> f64 {
    let mut least = f64::INFINITY;
    for p in owners.corner_pairs(c) {
        let pair = p.expand(triangles, &owners.edges);
        for k in 0..=32 {
            let t = f64::from(k) / 32.0;
            let x = pair
                .ids()
                .map(|i| from[i].as_dvec3().lerp(to[i].as_dvec3(), t));
            least = least.min(distance(&pair, x));
        }
    }
    least
}

/// The cloth's right half folded up over the line x = 0 by `fold` radians, every particle
/// wobbled by up to 1.5 mm in a pattern that changes with `step`, and the whole turned
/// and carried along with `step`.
fn folded(rest: &[Vec3], fold: f32, step: usize) -> Vec<Vec3> {
    let k = step as f32;
    let turn = Quat::from_axis_angle(Vec3::new(0.3, 1.0, 0.2).normalize(), k * 4f32.to_radians());
    let carry = k * Vec3::new(0.01, -0.03, 0.02);
    (rest.iter())
        .map(|&p| {
            let p = if p.x > 0.0 {
                Vec3::new(p.x * fold.cos(), p.x * fold.sin(), p.z)
            } else {
                p
            };
            let wobble = 0.0015
                * Vec3::new(
                    (0.7 * k + 90.0 * p.x).sin(),
                    (1.3 * k + 70.0 * p.z).sin(),
                    (0.9 * k + 60.0 * (p.x + p.z)).cos(),
                );
            turn * (p + wobble) + carry
        })
        .collect()
}

/// The right half of the cloth folds over onto the left, 5° a substep, from flat to 175°,
/// while every particle wobbles and the whole turns and moves: each substep, every pair of
/// every corner the certificates leave closed stays a thickness apart along the whole
/// motion. Near the fold they are used towards their limit (a closed corner's pairs come
/// within 1.7 thicknesses: 1.58 measured), and the fold opens corners (at 175° the halves
/// are 1.5 mm apart near the line).
#[test]
fn a_corner_left_closed_keeps_its_pairs_a_thickness_apart() {
    let (model, owners, rest) = flat();
    let triangles = &model.triangles;
    let mut certificates = Certificates::default();
    let (mut closest, mut closed, mut opened) = (f64::INFINITY, 0, 0);
    for step in 0..35 {
        let fold = |s: usize| (5.0 * s as f32).to_radians();
        let from = folded(&rest, fold(step), step);
        let to = folded(&rest, fold(step + 1), step + 1);
        certificates.decide(
            &owners,
            triangles,
            [&from, &to],
            THICKNESS,
            None,
            [&|_| false; 2],
        );
        for c in 0..rest.len() {
            if owners.corner_pairs(c).is_empty() {
                continue;
            }
            if certificates.open[c] {
                opened += 1;
                continue;
            }
            closed += 1;
            let least = closest_along(&owners, triangles, c, [&from, &to]);
            assert!(
                least >= f64::from(THICKNESS),
                "substep {step}: corner {c} closed, its pairs {least} m apart"
            );
            closest = closest.min(least);
        }
    }
    assert!(
        closed > 1000 && opened > 50,
        "{closed} closed, {opened} open"
    );
    assert!(closest < 1.7 * f64::from(THICKNESS), "closest {closest}");
}

/// A flat cloth turning 10° a substep about an upright axis and moving 5 cm: after the
/// first substep has taken every corner's reference, no corner's is taken again and none
/// is open (turned with each corner's frame, the references still fit; left unturned,
/// the ring's particles 2.8 cm from their corner would stray 4.9 mm a substep, more than
/// the 4 mm the corners' 1.4 cm leave over the thickness on each side).
#[test]
fn a_cloth_that_only_turns_keeps_its_references() {
    let (model, owners, rest) = flat();
    let with_pairs = (0..rest.len())
        .filter(|&c| !owners.corner_pairs(c).is_empty())
        .count();
    let moved = |s: usize| -> Vec<Vec3> {
        let turn = Quat::from_rotation_y((10.0 * s as f32).to_radians());
        let carry = s as f32 * Vec3::new(0.05, 0.0, -0.02);
        rest.iter().map(|&p| turn * p + carry).collect()
    };
    let mut certificates = Certificates::default();
    for step in 0..4 {
        let (from, to) = (moved(step), moved(step + 1));
        let retaken = certificates.decide(
            &owners,
            &model.triangles,
            [&from, &to],
            THICKNESS,
            None,
            [&|_| false; 2],
        );
        let expected = if step == 0 { with_pairs as u64 } else { 0 };
        assert_eq!(retaken, expected, "substep {step}");
        assert!(certificates.open.iter().all(|&o| !o), "substep {step}");
    }
}

/// Every corner starts from its rest shape: a cloth that only turns and moves from rest
/// takes no reference at all. One folded in two takes the references of the corners along
/// the fold; laid flat again and turning, where their rings keep near their rest shape (as
/// the patches tell), those corners go back to their rest shape, so that turning and
/// moving on takes none again.
#[test]
fn corners_start_from_their_rest_shape_and_go_back_to_it() {
    let (model, owners, rest) = flat();
    let triangles = &model.triangles;
    let moved = |s: usize| -> Vec<Vec3> {
        let turn = Quat::from_rotation_y((10.0 * s as f32).to_radians());
        let carry = s as f32 * Vec3::new(0.05, 0.0, -0.02);
        rest.iter().map(|&p| turn * p + carry).collect()
    };
    let mut certificates = Certificates::build(&owners, triangles, &rest);
    let mut decide = |motion: [&[Vec3]; 2], near_rest: bool| {
        let settled: [&(dyn Fn(usize) -> bool + Sync); 2] = [&|_| false, &|_| near_rest];
        let retaken = certificates.decide(&owners, triangles, motion, THICKNESS, None, settled);
        (retaken, certificates.open.iter().filter(|&&o| o).count())
    };
    assert_eq!(decide([&moved(0), &moved(1)], false), (0, 0));
    let fold = folded(&rest, 90f32.to_radians(), 0);
    let (retaken, _) = decide([&fold, &fold], false);
    assert!(retaken > 10, "{retaken} taken along the fold");
    assert_eq!(decide([&moved(0), &moved(1)], true), (0, 0));
    for step in 1..4 {
        let (from, to) = (moved(step), moved(step + 1));
        assert_eq!(decide([&from, &to], false), (0, 0), "substep {step}");
    }
}

/// A corner last closed by its ring is tried by its ring first, and decided by its
/// reference where the ring no longer holds: folded at a right angle, the corners along
/// the fold take references; laid flat, their rings close them; folded nearly flat, their
/// rings fail, their references are taken again, and some open: no corner left closed
/// has a pair within the thickness.
#[test]
fn a_corner_closed_by_its_ring_is_decided_again_where_its_ring_fails() {
    let (model, owners, rest) = flat();
    let triangles = &model.triangles;
    let mut certificates = Certificates::build(&owners, triangles, &rest);
    let mut decide = |motion: [&[Vec3]; 2], near_rest: bool| {
        let settled: [&(dyn Fn(usize) -> bool + Sync); 2] = [&|_| false, &|_| near_rest];
        let retaken = certificates.decide(&owners, triangles, motion, THICKNESS, None, settled);
        let open = certificates.open.clone();
        (retaken, open)
    };
    let fold = folded(&rest, 90f32.to_radians(), 0);
    let (retaken, _) = decide([&fold, &fold], false);
    assert!(retaken > 10, "{retaken} taken along the fold");
    let (retaken, open) = decide([&rest, &rest], true);
    assert_eq!((retaken, open.iter().filter(|&&o| o).count()), (0, 0));
    let sharp = folded(&rest, 175f32.to_radians(), 1);
    let (retaken, open) = decide([&sharp, &sharp], false);
    let opened = open.iter().filter(|&&o| o).count();
    assert!(retaken > 10 && opened > 0, "{retaken} taken, {opened} open");
    for c in (0..rest.len()).filter(|&c| !open[c]) {
        let least = closest_along(&owners, triangles, c, [&sharp, &sharp]);
        assert!(
            least >= f64::from(THICKNESS),
            "corner {c} closed at {least}"
        );
    }
}

/// Three triangles meeting only at corner 0, which is therefore their one corner with
/// pairs: a flat one pointing along −x (the corner's first triangle, whose frame turns
/// the references), a flat flap along +x, and above it a flap that rises to 6 mm over the
/// first's far edge. The flaps' nearest pairs (the upper flap's far edge and corners
/// against the lower flap, and the lower's corners against the upper) are 5.75–6 mm apart.
fn flaps() -> (ClothModel, Owners, Vec<Vec3>) {
    // r = 2 cm, h = 6 mm.
    let obj = "v 0 0 0\nv -0.02 0 -0.01\nv -0.02 0 0.01\nv 0.02 0.006 -0.01\n\
               v 0.02 0.006 0.01\nv 0.02 0 -0.01\nv 0.02 0 0.01\nf 1 2 3\nf 1 4 5\nf 1 6 7\n";
    let mesh = crate::mesh::obj_from_str(obj, "flaps.obj").unwrap().mesh;
    assert_eq!(mesh.triangles, [[0, 1, 2], [0, 3, 4], [0, 5, 6]]);
    let model = ClothModel::new(&mesh, 0.2, &[]);
    let owners = Owners::build(&model);
    (model, owners, mesh.positions)
}

/// The flaps pressed together, the upper down and the lower up by `s` each: their nearest
/// pairs close by nearly 2`s`, and the certificate, which allows for both sides straying
/// by `s`, keeps the corner closed only while they stay 2 mm apart (the thickness),
/// whether pressed over the substep or let go over it (nearest at its start); at its last
/// closed press they come within 1.2 thicknesses (1.16 measured); and in a still substep
/// after, on the reference taken where the first ended. The corner's first reference is
/// its rest shape, taken in a first, still substep.
#[test]
fn flaps_pressed_together_open_their_corner_before_they_come_within_the_thickness() {
    let (model, owners, rest) = flaps();
    let thickness = 0.002;
    assert_eq!(owners.neighbours.len(), owners.corner_pairs(0).len());
    let mut closest_closed = f64::INFINITY;
    let mut opened = 0;
    for k in 0..=40 {
        let s = 0.0025 * k as f32 / 40.0;
        let pressed: Vec<Vec3> = (rest.iter().enumerate())
            .map(|(i, &p)| match i {
                3 | 4 => p - Vec3::Y * s,
                5 | 6 => p + Vec3::Y * s,
                _ => p,
            })
            .collect();
        for motion in [[&rest, &pressed], [&pressed, &rest]] {
            let mut certificates = Certificates::default();
            let still = [&rest[..], &rest[..]];
            certificates.decide(
                &owners,
                &model.triangles,
                still,
                thickness,
                None,
                [&|_| false; 2],
            );
            assert!(!certificates.open[0]);
            // The substep, then one that stays where it ended (on the reference taken
            // there, if it was).
            for (n, motion) in [motion.map(|x| &x[..]), [motion[1], motion[1]]]
                .into_iter()
                .enumerate()
            {
                let retaken = certificates.decide(
                    &owners,
                    &model.triangles,
                    motion,
                    thickness,
                    None,
                    [&|_| false; 2],
                );
                let least = closest_along(&owners, &model.triangles, 0, motion);
                if certificates.open[0] {
                    assert!(
                        n == 1 || retaken == 1,
                        "a failed certificate takes its reference again"
                    );
                    opened += 1;
                } else {
                    assert!(
                        least >= f64::from(thickness),
                        "pressed {s}: closed, {least} m apart"
                    );
                    closest_closed = closest_closed.min(least);
                }
            }
        }
    }
    assert!(opened > 10, "{opened}");
    assert!(
        closest_closed < 1.2 * f64::from(thickness),
        "{closest_closed}"
    );
}
