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
