//! The GPU backend (run here on the software adapter) against the CPU per effect and per
//! integrator over runs short enough to stay non-chaotic: wind and dihedral bending, each
//! alone and together; XPBD and VBD, the same constraints projected, or particles
//! descended, colour by colour in the same order, so the two agree to rounding. And
//! friction between layers of the cloth, against Coulomb's law on an incline.

use clothsim::scene::{Scene, Simulation};
use clothsim::sim::{BendingModel, Effect, IntegratorKind, Wind};

mod common;
use common::{
    apart_after_a_push, farthest, gpu_simulation, incline, slope_acceleration, slope_speed,
};

/// The built-in scene `name` with its grid at 16 quads.
fn small(name: &str) -> Scene {
    let options = clothsim::mesh::ImportOptions::default();
    Scene::open_resized(name, None, &options, Some(16)).expect("a grid scene")
}

/// [`small`] stepped by `kind` with `sweeps` sweeps a substep.
fn with(kind: IntegratorKind, name: &str, sweeps: u32) -> Scene {
    let mut scene = small(name);
    scene.params.step.integrator = kind;
    scene.params.solver.xpbd_iterations = sweeps;
    scene.params.solver.vbd_iterations = sweeps;
    scene
}

/// `frames` frames of `scene` on both backends: the largest distance between the same
/// particle on the two, the largest distance a particle moved on the CPU, and both.
fn compare(scene: Scene, frames: usize) -> (f32, f32, Simulation, Simulation) {
    let start = scene.initial.pos.clone();
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend on the software adapter");
    for _ in 0..frames {
        cpu.step_frame().expect("cpu frame");
        gpu.step_frame().expect("gpu frame");
    }
    assert_eq!(gpu.integrator_in_effect(), cpu.integrator_in_effect());
    assert!(gpu.take_guard_events().is_empty());
    let worst = farthest(&cpu.state().pos, &gpu.state().pos);
    let moved = farthest(&cpu.state().pos, &start);
    (worst, moved, cpu, gpu)
}

/// XPBD: the hanging cloth swinging down for half a second at one sweep a substep and two
/// (the GPU's cloth is the CPU's to 2–3 µm of the 1.4 m it swung; projecting the seam's
/// colours before the halves' instead, 150 µm away), four frames into the sphere impact
/// (the colliders resolved after the projection, as on the CPU; the fall is the CPU's to
/// the bit, and the impact amplifies rounding: on the CPU alone, every particle moved by
/// 10⁻⁷ m at the start is 6 µm apart four frames in, 70 µm two frames later), and the flag
/// (the element forces move the predictions).
/// VBD over the same runs: the GPU descends the CPU's stencil colour by colour, with the
/// CPU's first guess, and agrees with it to 2–4 µm, and to 16 µm on the swinging cloth at
/// one sweep: there the guess follows the swing and carries rounding further (on the CPU
/// alone, particles moved by 5 × 10⁻⁸ m end 4.9 µm apart after the same 30 frames, against
/// 2.6 µm with the guess along gravity alone). The GPU starting from that older guess ends
/// 2.4 cm away.
///
/// `name` at 16 quads under `kind` at `sweeps` a substep, `frames` frames on both
/// backends: the cloth moves (the flag 5 cm, the others 30 cm) and the GPU's is the CPU's
/// to `tolerance` metres.
fn solver_agrees(kind: IntegratorKind, name: &str, sweeps: u32, frames: usize, tolerance: f32) {
    let least = if name == "flag" { 0.05 } else { 0.3 };
    let (worst, moved, ..) = compare(with(kind, name, sweeps), frames);
    let name = format!("{kind:?} {name} × {sweeps}");
    eprintln!("{name}: worst {worst:e} m of {moved} m moved");
    assert!(moved > least, "{name}: the cloth moves ({moved} m)");
    assert!(worst < tolerance, "{name}: GPU and CPU differ by {worst} m");
}

/// [`solver_agrees`] on the cloth dropped onto the sphere (22 frames) and the flag (12),
/// at one sweep a substep; VBD's drop at four. The sphere keeps the cloth's faces out
/// too, and at one sweep VBD's first guess, which follows each particle's last change of
/// velocity, carries what the face pass changed so far that the two part by 0.6 mm in
/// the three frames after the cloth lands (0.2 µm in the first); at four sweeps they agree
/// to 12 µm.
fn drops_and_flies_as_the_cpu_does(kind: IntegratorKind) {
    let sweeps = if kind == IntegratorKind::Vbd { 4 } else { 1 };
    solver_agrees(kind, "sphere-drop", sweeps, 22, 2e-5);
    solver_agrees(kind, "flag", 1, 12, 1e-5);
}

/// The hanging cloth swinging for 30 frames at one sweep a substep (below, at two).
#[test]
fn gpu_xpbd_swings_the_hanging_cloth_as_the_cpu_does() {
    solver_agrees(IntegratorKind::Xpbd, "hanging", 1, 30, 1e-5);
}

/// At two sweeps for 20 frames (0.57 m swung; 2.6 µm apart, and 17 µm with the seam's
/// colours projected before the halves').
#[test]
fn gpu_xpbd_swings_the_hanging_cloth_as_the_cpu_does_at_two_sweeps() {
    solver_agrees(IntegratorKind::Xpbd, "hanging", 2, 20, 1e-5);
}

#[test]
fn gpu_xpbd_drops_the_cloth_on_the_sphere_and_flies_the_flag_as_the_cpu_does() {
    drops_and_flies_as_the_cpu_does(IntegratorKind::Xpbd);
}

#[test]
fn gpu_vbd_swings_the_hanging_cloth_as_the_cpu_does() {
    solver_agrees(IntegratorKind::Vbd, "hanging", 1, 30, 3e-5);
}

#[test]
fn gpu_vbd_swings_the_hanging_cloth_as_the_cpu_does_at_two_sweeps() {
    solver_agrees(IntegratorKind::Vbd, "hanging", 2, 30, 1e-5);
}

#[test]
fn gpu_vbd_drops_the_cloth_on_the_sphere_and_flies_the_flag_as_the_cpu_does() {
    drops_and_flies_as_the_cpu_does(IntegratorKind::Vbd);
}

/// Switched to XPBD mid-run, the GPU colours the constraints from the cloth where it is
/// then, as the CPU does, and the two go on together; back to semi-implicit Euler too.
#[test]
fn gpu_switches_to_xpbd_and_back_mid_run_as_the_cpu_does() {
    let mut scene = with(IntegratorKind::Xpbd, "hanging", 1);
    scene.params.step.integrator = IntegratorKind::SemiImplicitEuler;
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, false).expect("GPU backend");
    for kind in [IntegratorKind::SemiImplicitEuler, IntegratorKind::Xpbd] {
        for sim in [&mut cpu, &mut gpu] {
            let mut params = sim.params().clone();
            params.step.integrator = kind;
            sim.set_params(params).expect("valid");
            for _ in 0..10 {
                sim.step_frame().expect("frame");
            }
        }
    }
    gpu.sync_state().expect("read back");
    assert_eq!(gpu.integrator_in_effect(), IntegratorKind::Xpbd);
    let worst = farthest(&cpu.state().pos, &gpu.state().pos);
    eprintln!("switched: worst {worst:e} m");
    assert!(worst < 1e-5, "GPU and CPU differ by {worst} m");
}

/// After an outside change (here every particle pushed sideways mid-run), VBD forgets the
/// accelerations its first guess reads and starts from the inertial guess, on the GPU as
/// on the CPU. At 4 substeps a frame the two guesses are g·h² = 0.17 mm apart; going on
/// from the stale memory, the GPU ends 0.5 mm from the CPU (measured: 0.3 µm).
#[test]
fn gpu_vbd_starts_afresh_after_an_outside_change_as_the_cpu_does() {
    let mut scene = with(IntegratorKind::Vbd, "hanging", 1);
    scene.params.step.substeps = 4;
    let worst = apart_after_a_push(scene, 10);
    eprintln!("pushed: worst {worst:e} m");
    assert!(worst < 5e-6, "GPU and CPU differ by {worst} m");
}

/// The hanging cloth with `effect` in place of its bend springs or beside them.
fn hanging_with(effect: Effect) -> Scene {
    let mut scene = small("hanging");
    if matches!(effect, Effect::Bending(_)) {
        (scene.effects).retain(|e| !matches!(e, Effect::Bending(_)));
    }
    scene.effects.push(effect);
    scene
}

/// Wind across the hanging cloth, gusting and veering, with lift: after 0.1 s the GPU's
/// cloth is where the CPU's is, to 2 µm of the 18 mm or more the wind moved it. A cloth
/// face-on to the wind amplifies rounding (on the CPU alone, every particle moved by
/// 10⁻⁷ m at the start is 6 µm apart after 0.1 s and 0.4 mm after 0.3 s), so the run is
/// short; without lift the cloth ends 5 mm elsewhere, and a gust a frame late 0.1 mm.
#[test]
fn gpu_and_cpu_agree_under_gusting_wind() {
    let wind = Wind {
        velocity: glam::Vec3::new(0.0, 0.0, 8.0),
        gust: 0.6,
        gust_period: 0.4,
        ..Wind::default()
    };
    let (worst, moved, ..) = compare(hanging_with(Effect::Wind(wind)), 6);
    eprintln!("wind: worst {worst:e} m of {moved} m moved");
    assert!(moved > 0.015, "the wind moves the cloth ({moved} m)");
    assert!(worst < 2e-6, "GPU and CPU differ by {worst} m");
}

/// Dihedral bending instead of bend springs, stiff enough to shape the swing.
#[test]
fn gpu_and_cpu_agree_with_dihedral_bending() {
    let bending = Effect::Bending(BendingModel::Dihedral { stiffness: 0.02 });
    let (worst, moved, ..) = compare(hanging_with(bending), 18);
    eprintln!("dihedral: worst {worst:e} m of {moved} m moved");
    assert!(moved > 0.1, "the cloth swings ({moved} m)");
    assert!(worst < 1e-5, "GPU and CPU differ by {worst} m");
}

/// The flag (wind and dihedral bending together) runs on the GPU as on the CPU.
#[test]
fn gpu_and_cpu_agree_on_the_flag() {
    let (worst, moved, ..) = compare(small("flag"), 18);
    eprintln!("flag: worst {worst:e} m of {moved} m moved");
    assert!(moved > 0.05, "the flag moves ({moved} m)");
    assert!(worst < 1e-5, "GPU and CPU differ by {worst} m");
}

/// `name` at 16 quads without its self-collision, stepped by `kind` (the two backends
/// order self-contact's pushes differently, so its folds part: the handles are compared
/// without it).
fn handled(name: &str, kind: IntegratorKind) -> Scene {
    let mut scene = with(kind, name, 1);
    (scene.effects).retain(|e| !matches!(e, Effect::SelfCollision(_)));
    scene
}

/// Handles (moving pins): the strip whose ends turn a full turn each and move closer, and
/// the cloth whose back edge is flung over at 10 m/s. The GPU puts each carried particle
/// where the CPU's handle does after every substep (the host computes the targets on the
/// CPU's clock), under semi-implicit Euler, XPBD and VBD, and the cloths agree to rounding.
/// The twisting strip amplifies it under semi-implicit Euler (on the CPU alone, particles
/// moved by 1 µm at random are 0.4 mm apart after 0.5 s; the GPU is 12 µm from the CPU).
/// Targets a substep late leave the strip 9 mm off; particles left unplaced, 11 cm.
#[test]
fn gpu_handles_carry_the_cloth_as_the_cpus_do() {
    for (name, kind, frames, tolerance) in [
        ("twist", IntegratorKind::SemiImplicitEuler, 30, 4e-5),
        ("twist", IntegratorKind::Vbd, 30, 1e-5),
        ("fast-fold", IntegratorKind::Xpbd, 24, 1e-5),
    ] {
        let mut scene = handled(name, kind);
        if kind != IntegratorKind::SemiImplicitEuler {
            scene.params.step.substeps = 16;
        }
        let (worst, moved, ..) = compare(scene, frames);
        let name = format!("{name} {kind:?}");
        eprintln!("{name}: worst {worst:e} m of {moved} m moved");
        assert!(
            moved > 0.05,
            "{name}: the handles move the cloth ({moved} m)"
        );
        assert!(worst < tolerance, "{name}: GPU and CPU differ by {worst} m");
    }
}

/// A grab on the GPU moves the cloth as on the CPU: the hanging cloth's lowest corner
/// dragged sideways 1 cm a frame for ten frames. The held particle is where the pointer
/// holds it for the springs from the frame's start, on both, and only the contacts see its
/// path from where it was; it ends at the pointer's velocity, and the cloths agree to
/// 8 µm. (Carried to the pointer over the first substep instead, as a handle carries its
/// particles, the springs feel the move a substep late, and the cloths part by 4 mm.)
#[test]
fn a_grab_moves_the_cloth_on_the_gpu_as_on_the_cpu() {
    let scene = small("hanging");
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend");
    let pos = &cpu.state().pos;
    let p = (0..pos.len()).min_by(|&a, &b| pos[a].y.total_cmp(&pos[b].y));
    let p = p.expect("particles") as u32;
    let start = pos[p as usize];
    for k in 1..=10 {
        let target = start + glam::Vec3::new(0.01 * k as f32, 0.0, 0.0);
        for sim in [&mut cpu, &mut gpu] {
            sim.grab(p, target);
            sim.step_frame().expect("a frame");
        }
    }
    let (on_cpu, on_gpu) = (cpu.state(), gpu.state());
    let held = p as usize;
    assert_eq!(on_gpu.pos[held], on_cpu.pos[held], "the held particle");
    let speed = on_cpu.vel[held].length();
    assert!(speed > 0.5, "the pointer moves at 0.6 m/s: {speed}");
    assert!((on_gpu.vel[held] - on_cpu.vel[held]).length() < 1e-5 * speed);
    let worst = farthest(&on_cpu.pos, &on_gpu.pos);
    eprintln!("grab: worst {worst:e} m");
    assert!(worst < 2e-5, "GPU and CPU differ by {worst} m");
}

/// A handle taken away mid-run: its particles stay pinned where they are, the other handle
/// goes on, on the GPU (read back only at the end: the device's state is stamped anew
/// from its own latest) as on the CPU, to 1 µm three frames later (the released strip
/// amplifies rounding from there: 12 µm seven frames on).
#[test]
fn a_handle_taken_away_mid_run_stops_on_the_gpu_as_on_the_cpu() {
    const FRAMES_AFTER: usize = 3;
    let mut scene = handled("twist", IntegratorKind::Vbd);
    // Without the guard, which would read the state back to derive its limits anew.
    scene.params.guard.enabled = false;
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, false).expect("GPU backend");
    for sim in [&mut cpu, &mut gpu] {
        for _ in 0..10 {
            sim.step_frame().expect("frame");
        }
        let mut effects = sim.effects().to_vec();
        let first = effects.iter().position(|e| matches!(e, Effect::Handle(_)));
        effects.remove(first.expect("a handle"));
        sim.set_effects(effects).expect("valid");
        for _ in 0..FRAMES_AFTER {
            sim.step_frame().expect("frame");
        }
    }
    gpu.sync_state().expect("read back");
    let worst = farthest(&cpu.state().pos, &gpu.state().pos);
    eprintln!("a handle taken away: worst {worst:e} m");
    assert!(worst < 5e-6, "GPU and CPU differ by {worst} m");
}

/// The wind turned and strengthened mid-run reaches the GPU's element pass (a new strength
/// retunes it, its buffers stay): the flag goes on as the CPU's does.
#[test]
fn a_wind_changed_mid_run_reaches_the_gpu() {
    let scene = small("flag");
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend");
    for sim in [&mut cpu, &mut gpu] {
        for _ in 0..6 {
            sim.step_frame().expect("frame");
        }
        let mut effects = sim.effects().to_vec();
        for e in &mut effects {
            if let Effect::Wind(w) = e {
                w.velocity = glam::Vec3::new(3.0, 0.0, 9.0);
            }
        }
        sim.set_effects(effects).expect("valid");
        for _ in 0..6 {
            sim.step_frame().expect("frame");
        }
    }
    let worst = farthest(&cpu.state().pos, &gpu.state().pos);
    eprintln!("wind changed: worst {worst:e} m");
    assert!(worst < 1e-5, "GPU and CPU differ by {worst} m");
}

/// Friction between layers on the GPU is Coulomb's, as on the CPU (`tests/contact.rs`):
/// two 2-quad cloths, the upper resting on the lower, pinned one on an incline of 30° with
/// friction 0.3 between them. The upper slides with acceleration g (sin θ − μ cos θ) =
/// 2.356 m/s² (measured over 0.05 s after 0.02 s settling: 2.3561; with no friction,
/// 4.905, g sin θ).
#[test]
fn a_cloth_slides_off_another_as_coulomb_friction_says_on_the_gpu() {
    let (degrees, mu) = (30.0, 0.3);
    let (mut gpu, _) = gpu_simulation(incline(degrees, mu, 2), false).expect("GPU backend");
    let (a, expected) = slope_acceleration(&mut gpu, (degrees, mu), (0.02, 0.05));
    eprintln!("{degrees}°: {a} m/s² against Coulomb's {expected}");
    assert!(
        (a - expected).abs() < 0.02 * expected,
        "{a} m/s² against Coulomb's {expected}"
    );
}

/// Below the angle of friction the upper cloth stays on the lower on the GPU: at 10°, tan
/// θ = 0.18 < μ = 0.3 (measured: 0.4 µm/s along the slope after 0.07 s; with no friction
/// it slid at 11 cm/s by then, g sin θ = 1.7 m/s²).
#[test]
fn a_cloth_on_another_holds_below_the_angle_of_friction_on_the_gpu() {
    let (mut gpu, _) = gpu_simulation(incline(10.0, 0.3, 2), false).expect("GPU backend");
    gpu.run(0.07);
    gpu.sync_state().expect("read back");
    let speed = slope_speed(&gpu);
    eprintln!("10°: {speed} m/s along the slope");
    assert!(speed.abs() < 0.001, "{speed} m/s along the slope");
}
