//! What a cut leaves of a particle's velocity, on the GPU as on the CPU: the share of its
//! velocity that it keeps of its motion. A particle's motion in a substep can hold a
//! push's move, which is no velocity; made one, a pressed stack buzzed.

use glam::Vec3;

use super::{edited, trial};
use crate::scene::{Scene, Simulation};
use crate::sim::FrameOutcome;

/// The thickness of `layers`, m.
const THICKNESS: f32 = 0.006;

/// Three 4 × 4-quad sheets of `layers` (0.8 m wide; 25 particles each, bottom first), with
/// nothing acting on them but self-contact, at one substep a frame under semi-implicit
/// Euler, so that a sheet at rest stays at rest and a moving one keeps its velocity.
fn three_sheets() -> Scene {
    let edits = [
        (
            "integrator = \"implicit-euler\"",
            "integrator = \"semi-implicit-euler\"",
        ),
        ("substeps = 4", "substeps = 1"),
        ("layers = 5", "layers = 3"),
        ("[[effects]]\ntype = \"gravity\"\n\n", ""),
        ("[[effects]]\ntype = \"air-damping\"\nrate = 0.3\n\n", ""),
        (
            "[[effects]]\ntype = \"sphere\"\ncenter = [0.0, 0.3, 0.0]\nradius = 0.3\nfriction = 0.5\n\n",
            "",
        ),
        ("[[effects]]\ntype = \"plane\"\nfriction = 0.5\n\n", ""),
    ];
    edited(
        include_str!("../../../../assets/scenes/layers.toml"),
        &edits,
        4,
    )
}

/// The three sheets stepped one frame on a backend `make` sets up for them, from this: the
/// bottom one at rest; the middle one at rest, half a sheet to the side and half the
/// thickness above it, so the pushes lift it where the two overlap; the top one `above`
/// the middle, 0.3 m further to the side (over both of the others where the middle is
/// pushed), coming down by six thicknesses in the frame. Returns the start and the end
/// state's positions and velocities. The frame stands, on the same backend, and leaves no
/// two triangles through each other.
fn step_sheets(make: fn(Scene) -> Simulation, above: f32) -> [(Vec<Vec3>, Vec<Vec3>); 2] {
    let mut sim = make(three_sheets());
    let dt = sim.params().step.dt;
    sim.modify_state(|state| {
        let base = state.pos[0].y;
        for (i, (x, v)) in state.pos.iter_mut().zip(&mut state.vel).enumerate() {
            let (shift, height, speed) = match i / 25 {
                0 => (Vec3::ZERO, 0.0, 0.0),
                1 => (Vec3::new(0.4, 0.0, 0.0), 0.5 * THICKNESS, 0.0),
                _ => (
                    Vec3::new(0.7, 0.0, 0.05),
                    0.5 * THICKNESS + above,
                    6.0 * THICKNESS / dt,
                ),
            };
            *x = Vec3::new(x.x, base + height, x.z) + shift;
            *v = Vec3::new(0.0, -speed, 0.0);
        }
    });
    let start = (sim.state().pos.clone(), sim.state().vel.clone());
    let backend = sim.backend_name();
    let outcome = sim.step_frame().expect("a frame");
    assert_eq!(
        outcome,
        FrameOutcome::Stepped,
        "the frame stands as stepped"
    );
    sim.sync_state().expect("the state");
    assert_eq!(sim.backend_name(), backend, "stepped where it was set up");
    let found = sim.intersections();
    assert_eq!(found.total(), 0, "{found:?}");
    [start, (sim.state().pos.clone(), sim.state().vel.clone())]
}

/// On a backend `make` sets up: the middle sheet is pushed up by the bottom one (as the
/// same frame with the top sheet a metre away shows), and the top sheet, coming down from
/// three thicknesses above, is cut short of the middle one, and so are some of the pushed
/// particles of the middle (they end lower than that frame left them); yet every particle
/// of the middle sheet keeps the velocity it had, none (the average velocity of what the
/// cut ones kept of their motion, as a cut particle was given before, is up to 4.2 cm/s
/// up: measured, both backends going red so).
/// Each particle of the top sheet keeps the share of its velocity that it kept of its
/// motion.
fn a_pushed_particle_cut_short_keeps_no_velocity(make: fn(Scene) -> Simulation) {
    let [_, (alone, _)] = step_sheets(make, 1.0);
    let [(start, start_vel), (end, vel)] = step_sheets(make, 3.0 * THICKNESS);
    let rise = |i: usize, end: &[Vec3]| end[i].y - start[i].y;
    let pushed: Vec<usize> = (25..50)
        .filter(|&i| rise(i, &alone) > 0.1 * THICKNESS)
        .collect();
    let cut = (pushed.iter())
        .filter(|&&i| rise(i, &end) < rise(i, &alone) - 0.01 * THICKNESS)
        .count();
    let fastest = (vel[25..50].iter()).fold(0.0f32, |m, v| m.max(v.length()));
    eprintln!(
        "middle: {} pushed, {cut} of them cut short; fastest {fastest} m/s",
        pushed.len()
    );
    assert!(
        pushed.len() >= 5 && cut >= 1,
        "{} pushed, {cut} cut",
        pushed.len()
    );
    // What the sheets' springs, their rest shapes moved in f32, give them (58 µm/s).
    assert!(
        fastest < 1e-4,
        "the middle sheet keeps no velocity: {fastest} m/s"
    );
    // The top sheet's speed, six thicknesses in the frame.
    let speed = -start_vel[50].y;
    let mut stopped = 0;
    for i in 50..75 {
        let share = (start[i].y - end[i].y) / (6.0 * THICKNESS);
        let kept = Vec3::new(0.0, -speed * share, 0.0);
        assert!(
            (vel[i] - kept).length() < 1e-3 * speed,
            "top particle {i}: {}",
            vel[i]
        );
        stopped += usize::from(share < 0.6);
    }
    assert!(stopped >= 5, "the top sheet is stopped: {stopped}");
}

#[test]
fn a_pushed_particle_cut_short_keeps_no_velocity_on_the_cpu() {
    a_pushed_particle_cut_short_keeps_no_velocity(Simulation::new);
}

#[test]
fn a_pushed_particle_cut_short_keeps_no_velocity_on_the_gpu() {
    a_pushed_particle_cut_short_keeps_no_velocity(|scene| trial(scene, true, None));
}
