use glam::Vec3;

use super::*;
use crate::mesh::{GridOrientation, GridSpec};

/// Two squares of 10 cm (two triangles each), the second 5 cm above the first, moving
/// straight down by `drop` in the motion the boxes were made for: the pairs of the upper
/// square's triangles with the lower's that [`Search::keep`] keeps, judged by the motion,
/// with a thickness of 1 cm.
fn kept_when_dropped(drop: f32) -> usize {
    let square = GridSpec::square(1, 0.1, GridOrientation::Horizontal, Vec3::ZERO)
        .build()
        .expect("a grid");
    let model = ClothModel::new(&square.stacked(2, Vec3::Y * 0.05), 0.2, &[]);
    let owners = Owners::build(&model);
    let from = model.rest_positions.clone();
    let to: Vec<Vec3> = (from.iter())
        .map(|&p| if p.y > 0.01 { p - Vec3::Y * drop } else { p })
        .collect();
    let boxes = Boxes {
        swept: true,
        from,
        to,
        ..Boxes::default()
    };
    let search = Search {
        owners: &owners,
        triangles: &model.triangles,
        boxes: &boxes,
        thickness: 0.01,
        open: &[],
    };
    let mut out = Vec::new();
    for (a, b) in [(2, 0), (2, 1), (3, 0), (3, 1)] {
        owners.each_pair(&model.triangles, a, b, |pair, stored| {
            search.keep(pair, stored, &mut out);
        });
    }
    out.len()
}

/// Judged by the motion, the upper square dropped 10 cm passes through the lower one:
/// its pairs with it are kept, though at the start and at the end the squares lie 5 cm
/// apart (on either side); dropped 3 cm, it stops 2 cm short, and none is.
#[test]
fn a_side_that_passes_through_another_is_kept_one_that_stops_short_is_not() {
    let through = kept_when_dropped(0.1);
    assert!(through >= 4, "{through} pairs kept");
    assert_eq!(kept_when_dropped(0.03), 0);
}

/// A triangle within `size` and a copy of it `d` along its normal (one corner of each, at
/// random, brought `dip·d/2` nearer the other), both turned at random and carried along one
/// straight motion of up to 2 cm (with `through`, the copy ends as far on the other side
/// instead): the boxes of that motion.
fn stacked(rnd: &mut impl FnMut() -> f32, size: f32, d: f32, through: bool, dip: f32) -> Boxes {
    let mut point = |scale: f32| Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * scale;
    let turn = glam::Quat::from_scaled_axis(point(6.0));
    let (shift, motion) = (point(0.1), point(0.04));
    let flat = [0, 1, 2].map(|_| point(size) * Vec3::new(1.0, 1.0, 0.0));
    let place = |p: Vec3| turn * p + shift;
    // One corner of each, at random, half the dip towards the other.
    let dipped = [0, 1].map(|_| (3.0 * rnd()) as usize);
    let lift = |copy: usize, k: usize| match (copy, k == dipped[copy]) {
        (0, true) => 0.5 * dip,
        (0, false) => 0.0,
        (_, true) => 1.0 - 0.5 * dip,
        (_, false) => 1.0,
    };
    let from: Vec<Vec3> = (0..6)
        .map(|i| place(flat[i % 3] + Vec3::Z * (d * lift(i / 3, i % 3))))
        .collect();
    let to: Vec<Vec3> = (from.iter().enumerate())
        .map(|(i, &p)| match i >= 3 && through {
            true => p + motion - turn * Vec3::Z * (2.0 * d),
            false => p + motion,
        })
        .collect();
    let mut boxes = Boxes {
        swept: true,
        ..Boxes::default()
    };
    boxes.set_motion(&from, &to, 1);
    boxes
}

/// Whether [`Search::apart_in_lanes`] and [`Search::apart_in_f64`] tell the two triangles
/// of `boxes` a `thickness` apart.
fn told_apart(boxes: &Boxes, thickness: f32) -> [bool; 2] {
    let owners = Owners::default();
    let search = Search {
        owners: &owners,
        triangles: &[[0, 1, 2], [3, 4, 5]],
        boxes,
        thickness,
        open: &[],
    };
    [search.apart_in_lanes(0, 1), search.apart_in_f64(0, 1)]
}

/// The thickness at which the f64 test stops telling the two triangles of `boxes` apart
/// (the least it does not, to the float).
fn f64_border(boxes: &Boxes, d: f32) -> f32 {
    let (mut apart, mut not) = (1e-3 * d.abs(), 2.0 * d.abs());
    for _ in 0..32 {
        let mid = 0.5 * (apart + not);
        if told_apart(boxes, mid)[1] {
            apart = mid;
        } else {
            not = mid;
        }
    }
    not
}

/// Where the lanes tell two triangles apart, so does the f64 test (the same pairs are
/// kept): at thicknesses just past where the f64 test stops telling them apart, where the
/// lanes' rounding could tip some (without their room, 343 of these 4 000; without its
/// share of the farthest coordinate, 107); a hundredth short of that border the lanes tell the
/// pair apart themselves, and a hundredth past it, or where the copy passes through,
/// they do not.
#[test]
fn what_the_lanes_tell_apart_the_f64_test_does() {
    let mut rnd = crate::test_rng::uniform(23);
    let side = |rnd: &mut dyn FnMut() -> f32| {
        let d = 0.001 + 0.005 * rnd();
        if rnd() < 0.5 { -d } else { d }
    };
    let mut tipped = 0;
    for _ in 0..4000 {
        let (size, d, dip) = (0.01 + 0.1 * rnd(), side(&mut rnd), 0.5 * rnd());
        let boxes = stacked(&mut rnd, size, d, false, dip);
        let past = f64_border(&boxes, d) * (1.0 + 1e-5 * rnd());
        let [lanes, f64_test] = told_apart(&boxes, past);
        assert!(!f64_test);
        tipped += usize::from(lanes);
    }
    assert_eq!(tipped, 0, "pairs the lanes told apart and f64 did not");
    for _ in 0..1000 {
        let (size, d, dip) = (0.005 + 0.02 * rnd(), side(&mut rnd), 0.5 * rnd());
        let boxes = stacked(&mut rnd, size, d, false, dip);
        let border = f64_border(&boxes, d);
        assert_eq!(told_apart(&boxes, 0.99 * border), [true, true]);
        assert_eq!(told_apart(&boxes, 1.01 * border), [false, false]);
        let through = stacked(&mut rnd, size, d, true, dip);
        assert_eq!(told_apart(&through, 0.1 * d.abs()), [false, false]);
    }
}
