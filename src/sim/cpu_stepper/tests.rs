use super::*;
use crate::sim::effects::{growing_cloth, rail, rising_roof};

/// How many sharp edges the stepper's first mesh obstacle keeps the cloth off.
fn kept_off(stepper: &CpuStepper) -> usize {
    let obstacle = stepper.effects.iter().find_map(|e| match e {
        Effect::Obstacle(o) => o.placed(),
        _ => None,
    });
    obstacle.map_or(0, |p| p.surface.sharp_edges().len())
}

/// How many sharp edges a stepper keeps a cloth of 10 cm quads off `obstacle` (the
/// cloth 2 m up, `thickness` off solids): at rest, and after a frame that ends with the
/// cloth grown to 1.8 times its rest size (`growing_cloth`).
fn kept_off_at_rest_and_grown(obstacle: Effect, thickness: f32) -> (usize, usize) {
    let (model, params, mut state) = growing_cloth(thickness);
    let mut stepper = CpuStepper::new(&model, &params, &[obstacle]);
    let at_rest = kept_off(&stepper);
    stepper.frame(&model, &mut state).unwrap();
    (at_rest, kept_off(&stepper))
}

/// A cloth of 10 cm quads (4 cm thickness) 2 m above a rail of 40 narrow faces: at rest it
/// cannot reach the rail's ridges, so the stepper keeps it off the 80 creases round the
/// rail's ends alone. Flung out from its middle, the first frame ends with it 1.8 times its
/// size, grown past what the rail was fitted to, and the stepper fits the rail again: its
/// 40 ridges are kept off too. (With nothing measuring the stretch, 80 still.)
#[test]
fn a_frame_that_ends_with_the_cloth_grown_fits_the_obstacles_again() {
    assert_eq!(kept_off_at_rest_and_grown(rail(), 0.04), (80, 120));
}

/// A block whose top is flat in frame 0 and rises 4.7° to an apex in frame 1 (an OBJ
/// sequence, one frame a second), 2 m under a cloth of 10 cm quads (2 cm thickness): at
/// rest the cloth reaches no part of the roof in any frame, so the stepper keeps it off the
/// block's 12 creases. Flung out from its middle, the first frame ends with it 1.8 times
/// its size, and the stepper fits the sequence again, though its frame 0 has no gentle
/// part: the roof's four ridges, which the grown cloth reaches in frame 1, are kept off
/// too. (With a sequence counted gentle by its frame 0 alone, 12 still.)
#[test]
fn a_sequence_flat_at_first_is_fitted_again_as_the_cloth_grows() {
    let dir = tempfile::tempdir().unwrap();
    let roof = rising_roof(dir.path());
    assert_eq!(kept_off_at_rest_and_grown(roof, 0.02), (12, 16));
}

/// The stretch is measured before each substep's contacts, not only where a frame ends: a
/// cloth of 10 cm quads held at 1.8 times its rest size, at rest, 2 m above the rail (4
/// cm thickness), has the rail's 40 ridges kept off beside its 80 end creases after a
/// single substep. (Measured at a frame's end only, 80.)
#[test]
fn a_substep_that_finds_the_cloth_stretched_fits_the_obstacles_before_its_contacts() {
    let (model, params, mut state) = growing_cloth(0.04);
    let at = glam::Vec3::new(0.0, 2.0, 0.0);
    for (p, v) in state.pos.iter_mut().zip(&mut state.vel) {
        (*p, *v) = (at + (*p - at) * 1.8, glam::Vec3::ZERO);
    }
    let mut stepper = CpuStepper::new(&model, &params, &[rail()]);
    assert_eq!(kept_off(&stepper), 80);
    stepper.substep(&model, &mut state).unwrap();
    assert_eq!(kept_off(&stepper), 120);
}
