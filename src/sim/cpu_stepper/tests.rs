use glam::Vec3;

use super::*;
use crate::mesh::{GridOrientation, GridSpec};
use crate::sim::effects::rail;
use crate::sim::{Obstacle, SimParams};

/// How many sharp edges the stepper's first mesh obstacle keeps the cloth off.
fn kept_off(stepper: &CpuStepper) -> usize {
    let obstacle = stepper.effects.iter().find_map(|e| match e {
        Effect::Obstacle(o) => o.placed(),
        _ => None,
    });
    obstacle.map_or(0, |p| p.surface.sharp_edges().len())
}

/// How many sharp edges a stepper keeps a cloth of 10 cm quads off `obstacle` (the cloth
/// 2 m up, `thickness` off solids): at rest, and after a frame started at twice the
/// cloth's rest size (forces none, so it stays so grown).
fn kept_off_at_rest_and_grown(obstacle: Effect, thickness: f32) -> (usize, usize) {
    let at = Vec3::new(0.0, 2.0, 0.0);
    let mesh = GridSpec::square(10, 1.0, GridOrientation::Horizontal, at)
        .build()
        .unwrap();
    let model = ClothModel::new(&mesh, 0.2, &[]);
    let mut params = SimParams::default();
    params.contact.offset = thickness;
    let mut stepper = CpuStepper::new(&model, &params, &[obstacle]);
    let at_rest = kept_off(&stepper);
    let mut state = ClothState::at_rest(&model);
    for p in &mut state.pos {
        *p = at + (*p - at) * 2.0;
    }
    stepper.frame(&model, &mut state).unwrap();
    (at_rest, kept_off(&stepper))
}

/// A cloth of 10 cm quads (4 cm thickness) 2 m above a rail of 40 narrow faces: at rest it
/// cannot reach the rail's ridges, so the stepper keeps it off the 80 creases round the
/// rail's ends alone. Started at twice its rest size, the first frame ends with it grown
/// past what the rail was fitted to, and the stepper fits the rail again: its 40 ridges
/// are kept off too. (With the frame's end not asking, 80 still.)
#[test]
fn a_frame_that_ends_with_the_cloth_grown_fits_the_obstacles_again() {
    assert_eq!(kept_off_at_rest_and_grown(rail(), 0.04), (80, 120));
}

/// A block whose top is flat in frame 0 and rises 4.7° to an apex in frame 1 (an OBJ
/// sequence, one frame a second), 2 m under a cloth of 10 cm quads (2 cm thickness): at
/// rest the cloth reaches no part of the roof in any frame, so the stepper keeps it off
/// the block's 12 creases. Started at twice its rest size, the first frame ends with it
/// grown, and the stepper fits the sequence again, though its frame 0 has no gentle part:
/// the roof's four ridges, which the grown cloth reaches in frame 1, are kept off too.
/// (With a sequence counted gentle by its frame 0 alone, 12 still.)
#[test]
fn a_sequence_flat_at_first_is_fitted_again_as_the_cloth_grows() {
    let dir = tempfile::tempdir().unwrap();
    let (half, base) = (0.8f32, 0.3f32);
    for (k, rise) in [0.0, half * 4.7f32.to_radians().tan()]
        .into_iter()
        .enumerate()
    {
        let mut text = String::new();
        for y in [0.0, base] {
            for [x, z] in [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]] {
                text += &format!("v {} {y} {}\n", half * x, half * z);
            }
        }
        text += &format!("v 0 {} 0\n", base + rise);
        text += "f 1 2 3\nf 1 3 4\nf 5 6 2\nf 5 2 1\nf 6 7 3\nf 6 3 2\nf 7 8 4\nf 7 4 3\n\
                 f 8 5 1\nf 8 1 4\nf 5 9 6\nf 6 9 7\nf 7 9 8\nf 8 9 5\n";
        std::fs::write(dir.path().join(format!("roof_{k}.obj")), text).unwrap();
    }
    let mut roof = Obstacle::sequence("roof_%d.obj", 1.0, false);
    roof.load(Some(dir.path())).unwrap();
    let roof = Effect::Obstacle(roof);
    assert_eq!(kept_off_at_rest_and_grown(roof, 0.02), (12, 16));
}
