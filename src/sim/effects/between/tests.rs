use glam::Vec3;

use super::*;
use crate::sim::effects::{Plane, Sphere};

const OFFSET: f32 = 0.01;

/// A sphere of radius 0.3 resting on the ground (y = 0), neither with friction.
fn sphere_on_ground() -> [Effect; 2] {
    [
        Effect::Sphere(Sphere {
            center: Vec3::new(0.0, 0.3, 0.0),
            radius: 0.3,
            spin: Vec3::ZERO,
            friction: 0.0,
        }),
        Effect::Plane(Plane {
            point: Vec3::ZERO,
            normal: Vec3::Y,
            friction: 0.0,
        }),
    ]
}

/// How far inside the offset of each of `effects` a point is (negative: clear).
fn depths(effects: &[Effect], x: Vec3) -> Vec<f32> {
    (effects.iter().filter_map(|e| e.surface(x, 0.0)))
        .map(|(d, _, _)| OFFSET - d)
        .collect()
}

/// Squeezed under the sphere, on the ground's offset and inside the sphere itself, a
/// particle is moved out along the wedge to where it keeps the offset of both, and no
/// longer moves towards either.
#[test]
fn a_particle_in_the_wedge_is_moved_out_to_where_both_offsets_hold() {
    let solids = sphere_on_ground();
    for rho in [0.02f32, 0.06, 0.09] {
        let x = Vec3::new(rho * 0.6, OFFSET, rho * 0.8);
        assert!(
            depths(&solids, x)[0] > 0.005,
            "{rho}: starts inside the sphere's offset"
        );
        let v = Vec3::new(-1.0, -1.0, 0.0);
        let (to, vel) = between(&solids, (x, v), 0.0, OFFSET).expect("moved");
        for depth in depths(&solids, to) {
            assert!(
                depth <= 2e-5,
                "{rho}: still {depth} m inside an offset at {to}"
            );
        }
        // Out along the wedge, where the two offsets meet: √(2rδ + ...) from the axis.
        let out = to.x.hypot(to.z);
        let room = ((0.3f32 + OFFSET).powi(2) - (0.3 - OFFSET).powi(2)).sqrt();
        assert!(
            (out - room).abs() < 1e-3,
            "{rho}: ends {out} m from the axis, not {room}"
        );
        for (_, n, _) in solids.iter().filter_map(|e| e.surface(to, 0.0)) {
            assert!(
                vel.dot(n) >= -1e-6,
                "{rho}: still moving into a surface: {vel}"
            );
        }
    }
}

/// A particle one solid alone keeps, or that touches two without being inside either, is
/// left as the solids left it.
#[test]
fn a_particle_near_one_solid_or_touching_two_is_left_alone() {
    let solids = sphere_on_ground();
    let v = Vec3::new(0.3, -0.2, 0.1);
    // On the ground, far from the sphere; and on top of the sphere, far from the ground.
    for x in [Vec3::new(0.5, 0.005, 0.0), Vec3::new(0.0, 0.605, 0.0)] {
        assert_eq!(between(&solids, (x, v), 0.0, OFFSET), None, "{x}");
    }
    // Just where the two offsets meet.
    let room = ((0.3f32 + OFFSET).powi(2) - (0.3 - OFFSET).powi(2)).sqrt();
    let x = Vec3::new(room + 1e-5, OFFSET, 0.0);
    assert_eq!(between(&solids, (x, v), 0.0, OFFSET), None);
}

fn near(depth: f32, normal: Vec3) -> Near {
    Near {
        depth,
        normal: normal.normalize(),
    }
}

/// The least move meets each depth along its normal: at a right angle each its own; where
/// one alone does for both, only it; facing each other with no room, halfway.
#[test]
fn the_least_move_meets_both_depths_or_splits_them() {
    let m = least_move([near(0.01, Vec3::X), near(0.02, Vec3::Y)]);
    assert!((m - Vec3::new(0.01, 0.02, 0.0)).length() < 1e-7, "{m}");
    // Tilted 45° from the first: pushing 0.02 along it lifts the second by 0.014 ≥ 0.01.
    let m = least_move([near(0.02, Vec3::X), near(0.01, Vec3::new(1.0, 1.0, 0.0))]);
    assert!((m - Vec3::new(0.02, 0.0, 0.0)).length() < 1e-7, "{m}");
    // A wedge of 30°: both exactly, and no less along either.
    let (a, b) = (
        near(0.004, Vec3::Y),
        near(0.0, Vec3::new(1.0, -3f32.sqrt(), 0.0)),
    );
    let m = least_move([a, b]);
    assert!(
        (m.dot(a.normal) - 0.004).abs() < 1e-7 && m.dot(b.normal).abs() < 1e-7,
        "{m}"
    );
    // Facing: a gap of 0.012 between two offsets of 0.01 leaves 0.004 each side.
    let m = least_move([near(0.006, Vec3::Y), near(0.002, -Vec3::Y)]);
    assert!((m - Vec3::new(0.0, 0.002, 0.0)).length() < 1e-7, "{m}");
}
