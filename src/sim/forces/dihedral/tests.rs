//! The hinges eight at a time against one at a time.

use glam::Vec3;

use super::{DihedralBending, angle_difference, hinge_angle, wing_limit};
use crate::cloth::ClothModel;
use crate::mesh::{GridOrientation, GridSpec};

/// A crumpled 7 × 5-quad cloth (130 hinges: the last chunk holds two), bent from a
/// crumpled rest shape so that some hinges turn past ±π from their rest angle, with one
/// wing laid on its hinge (degenerate) and one nearly so (a sliver, its force limited):
/// eight hinges at a time pull every particle as one at a time does, but for the
/// arctangent's last places (9.4e-8 of the largest force apart, where a wing limit,
/// a wrap or a gradient's sign left out is 10⁻² or more).
#[test]
fn eight_hinges_at_a_time_pull_as_one_at_a_time() {
    let mesh = GridSpec {
        quads_x: 7,
        quads_y: 5,
        size_x: 0.7,
        size_y: 0.5,
        orientation: GridOrientation::Horizontal,
        center: Vec3::ZERO,
    }
    .build()
    .unwrap();
    let mut model = ClothModel::new(&mesh, 0.2, &[]);
    let mut jitter = crate::test_rng::jitter(7);
    for p in &mut model.rest_positions {
        *p += jitter(0.05);
    }
    let bending = DihedralBending::new(&model, 0.03);
    let mut pos: Vec<Vec3> = (model.rest_positions.iter())
        .map(|&p| p + jitter(0.08))
        .collect();
    let [x0, _, a, _] = model.hinges[17].map(|i| i as usize);
    pos[a] = pos[x0];
    let [x0, x1, _, b] = model.hinges[40].map(|i| i as usize);
    pos[b] = pos[x0].lerp(pos[x1], 0.6) + Vec3::Y * 1e-4;
    // The paths the test is for, each taken at least once.
    let (rest, _) = bending.rest_and_weight();
    let (mut degenerate, mut wrapped, mut limited) = (0, 0, 0);
    for (h, &r) in model.hinges.iter().zip(rest) {
        let [x0, x1, a, b] = h.map(|i| pos[i as usize]);
        match hinge_angle::<f32>(x0, x1, a, b) {
            None => degenerate += 1,
            Some((theta, grad)) => {
                wrapped += usize::from(angle_difference::<f32>(theta, r) != theta - r);
                limited += usize::from(wing_limit::<f32>(x1 - x0, &grad) < 1.0);
            }
        }
    }
    assert!(degenerate >= 1 && wrapped >= 1 && limited >= 1);
    assert!(!model.hinges.len().is_multiple_of(8));
    let (mut lanes, mut one) = (vec![Vec3::ZERO; pos.len()], vec![Vec3::ZERO; pos.len()]);
    bending.add_forces::<f32>(&model, &pos, &mut lanes);
    bending.add_forces_one_by_one::<f32>(&model, &pos, &mut one);
    let largest = one.iter().map(|f| f.length()).fold(0.0, f32::max);
    for (i, (l, o)) in lanes.iter().zip(&one).enumerate() {
        assert!(
            (*l - *o).length() <= 2e-7 * largest,
            "particle {i}: {l} against {o} (largest {largest})"
        );
    }
}
