use glam::Vec3;

use super::*;
use crate::mesh::{GridOrientation, GridSpec};
use crate::sim::SimParams;
use crate::sim::effects::rail;

/// How many sharp edges the stepper's first mesh obstacle keeps the cloth off.
fn kept_off(stepper: &CpuStepper) -> usize {
    let obstacle = stepper.effects.iter().find_map(|e| match e {
        Effect::Obstacle(o) => o.placed(),
        _ => None,
    });
    obstacle.map_or(0, |p| p.surface.sharp_edges().len())
}

/// A cloth of 10 cm quads (4 cm thickness) 2 m above a rail of 40 narrow faces: at rest it
/// cannot reach the rail's ridges, so the stepper keeps it off the 80 creases round the
/// rail's ends alone. Started at twice its rest size, the first frame ends with it grown
/// past what the rail was fitted to, and the stepper fits the rail again: its 40 ridges
/// are kept off too. (With the frame's end not asking, 80 still.)
#[test]
fn a_frame_that_ends_with_the_cloth_grown_fits_the_obstacles_again() {
    let at = Vec3::new(0.0, 2.0, 0.0);
    let mesh = GridSpec::square(10, 1.0, GridOrientation::Horizontal, at)
        .build()
        .unwrap();
    let model = ClothModel::new(&mesh, 0.2, &[]);
    let mut params = SimParams::default();
    params.contact.offset = 0.04;
    let mut stepper = CpuStepper::new(&model, &params, &[rail()]);
    assert_eq!(kept_off(&stepper), 80);
    let mut state = ClothState::at_rest(&model);
    for p in &mut state.pos {
        *p = at + (*p - at) * 2.0;
    }
    stepper.frame(&model, &mut state).unwrap();
    assert_eq!(kept_off(&stepper), 120);
}
