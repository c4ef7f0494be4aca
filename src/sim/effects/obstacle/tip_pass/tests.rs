//! Which way a triangle must move off a tip.

use glam::Vec3;

use super::*;

/// A triangle lying flat (normal up) around the origin, 2 cm across, at height `y`.
fn flat(y: f32) -> [Vec3; 3] {
    [
        Vec3::new(-0.01, y, -0.01),
        Vec3::new(0.0, y, 0.01),
        Vec3::new(0.01, y, -0.01),
    ]
}

/// How far and which way the triangle `x` (`start` where it began the substep) must move
/// off `tip`.
fn missing(tip: Vec3, x: [Vec3; 3], start: [Vec3; 3], thickness: f32) -> Option<(f32, Vec3)> {
    let push = Face::new(x, start).missing(tip, thickness)?;
    Some((push.gap, push.away))
}

const APEX: Vec3 = Vec3::ZERO;

/// A triangle that began the substep above an apex and ended less than the thickness above
/// it is lifted to the thickness; one that ended through it (the apex above the triangle)
/// is lifted back over it; one the thickness or more above is left.
#[test]
fn a_triangle_over_an_apex_is_lifted_to_the_thickness() {
    let t = 0.004;
    let (gap, away) = missing(APEX, flat(0.001), flat(0.01), t).expect("too near");
    assert!(
        (gap - 0.003).abs() < 1e-6 && away.abs_diff_eq(Vec3::Y, 1e-6),
        "{gap} {away}"
    );
    let (gap, away) = missing(APEX, flat(-0.002), flat(0.01), t).expect("through");
    assert!(
        (gap - 0.006).abs() < 1e-6 && away.abs_diff_eq(Vec3::Y, 1e-6),
        "{gap} {away}"
    );
    assert_eq!(missing(APEX, flat(0.004), flat(0.01), t), None);
    // Winding does not matter: the same triangle with its normal down.
    let turn = |[a, b, c]: [Vec3; 3]| [a, c, b];
    let (gap, away) = missing(APEX, turn(flat(-0.002)), turn(flat(0.01)), t).expect("through");
    assert!(
        (gap - 0.006).abs() < 1e-6 && away.abs_diff_eq(Vec3::Y, 1e-6),
        "{gap} {away}"
    );
}

/// The side a triangle began the substep on is kept, whichever it was: a triangle that
/// began below a tip and ended within the thickness above it is pushed back down through
/// it; one that began above, up.
#[test]
fn the_side_the_triangle_began_on_is_kept() {
    let corner = Vec3::ZERO;
    let t = 0.004;
    let (gap, away) = missing(corner, flat(0.001), flat(-0.01), t).expect("crossed");
    assert!(
        (gap - 0.005).abs() < 1e-6 && away.abs_diff_eq(Vec3::NEG_Y, 1e-6),
        "{gap} {away}"
    );
    let (gap, away) = missing(corner, flat(0.001), flat(0.01), t).expect("too near");
    assert!(
        (gap - 0.003).abs() < 1e-6 && away.abs_diff_eq(Vec3::Y, 1e-6),
        "{gap} {away}"
    );
}

/// Beside the triangle, the tip keeps a thickness from the nearest point of its edge,
/// along the line between them; a tip that has gone past the triangle's plane from the
/// side it began on is left to the edge pass.
#[test]
fn beside_a_triangle_the_tip_keeps_off_its_nearest_edge() {
    let t = 0.004;
    let x = flat(0.001).map(|p| p + Vec3::new(0.0, 0.0, 0.0115));
    let (gap, away) = missing(APEX, x, x, t).expect("near the edge");
    let off = Vec3::new(0.0, 0.001, 0.0015);
    assert!((gap - (t - off.length())).abs() < 1e-6, "{gap}");
    assert!(away.abs_diff_eq(off.normalize(), 1e-5), "{away}");
    let below = flat(-0.001).map(|p| p + Vec3::new(0.0, 0.0, 0.0115));
    assert_eq!(missing(APEX, below, x, t), None);
}

/// A ball's rise under a triangle is taken over its least enclosing circle: a right
/// triangle's has its hypotenuse for a diameter, an obtuse one's its longest edge, an
/// equilateral one's is its circumcircle (radius `L/√3`); `κρ²/2` for curvature `κ`.
#[test]
fn the_rise_under_a_triangle_is_over_its_least_enclosing_circle() {
    let h = 3f32.sqrt() / 2.0;
    let cases = [
        // Right: legs 0.3 and 0.4, radius 0.25.
        (
            [
                Vec3::ZERO,
                Vec3::new(0.3, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 0.4),
            ],
            0.0625,
        ),
        // Obtuse: longest edge 1, radius 0.5.
        ([Vec3::ZERO, Vec3::X, Vec3::new(0.5, 0.0, 0.1)], 0.25),
        // Equilateral of side 1: radius 1/√3.
        ([Vec3::ZERO, Vec3::X, Vec3::new(0.5, 0.0, h)], 1.0 / 3.0),
    ];
    for (x, rise) in cases {
        let got = sag(x, 2.0);
        assert!((got - rise).abs() < 1e-5, "{x:?}: {got} against {rise}");
    }
}

/// A cloth triangle collapsed to a segment has no plane and no side: it is not pushed off
/// an apex even where it passes within the thickness of it (its edges are the edge pass's).
#[test]
fn a_triangle_collapsed_to_a_segment_is_not_pushed() {
    let (a, b) = (Vec3::new(-0.01, 0.001, 0.0), Vec3::new(0.01, 0.001, 0.0));
    let segment = [a, b, (a + b) * 0.5];
    assert_eq!(missing(APEX, segment, segment, 0.004), None);
}
