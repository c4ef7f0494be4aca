//! Implicit Euler on the GPU (run here on the software adapter) against the CPU's: the
//! same linearised step solved by conjugate gradients with the same preconditioner, first
//! guess and stopping rule, so the two agree to the solve's tolerance, and to rounding when
//! both stop after the same few iterations.

use clothsim::scene::{Scene, Simulation};
use clothsim::sim::IntegratorKind;

mod common;
use common::{apart_after_a_push, farthest, gpu_simulation};

/// The built-in scene `name` at 16 quads, stepped by implicit Euler at `substeps` a frame
/// with the solve's `tolerance` and iteration cap.
fn implicit(name: &str, substeps: u32, tolerance: f32, cap: u32) -> Scene {
    let options = clothsim::mesh::ImportOptions::default();
    let mut scene = Scene::open_resized(name, None, &options, Some(16)).expect("a grid scene");
    scene.params.step.integrator = IntegratorKind::ImplicitEuler;
    scene.params.step.substeps = substeps;
    scene.params.solver.tolerance = tolerance;
    scene.params.solver.max_iterations = cap;
    scene
}

/// `frames` frames of `scene` on both backends: how far apart the two cloths end, and how
/// far the CPU's moved.
fn compare(scene: Scene, frames: usize) -> (f32, f32) {
    let start = scene.initial.pos.clone();
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend on the software adapter");
    for _ in 0..frames {
        cpu.step_frame().expect("cpu frame");
        gpu.step_frame().expect("gpu frame");
    }
    assert_eq!(gpu.integrator_in_effect(), IntegratorKind::ImplicitEuler);
    assert!(gpu.take_guard_events().is_empty());
    let worst = farthest(&cpu.state().pos, &gpu.state().pos);
    (worst, farthest(&cpu.state().pos, &start))
}

/// Solved tightly (to 10⁻⁵ of the right-hand side, at most 20 iterations, on both), the
/// GPU's step is the CPU's to `tolerance` (metres) after `frames` frames of `name`, which
/// move the cloth by more than `least`.
fn agrees(name: &str, substeps: u32, frames: usize, least: f32, tolerance: f32) {
    let (worst, moved) = compare(implicit(name, substeps, 1e-5, 20), frames);
    eprintln!("{name}: worst {worst:e} m of {moved} m moved");
    assert!(moved > least, "{name}: the cloth moves ({moved} m)");
    assert!(worst < tolerance, "{name}: GPU and CPU differ by {worst} m");
}

/// The hanging cloth swinging down (measured: 0.24 µm apart).
#[test]
fn gpu_implicit_euler_swings_the_hanging_cloth_as_the_cpu_does() {
    agrees("hanging", 3, 8, 0.05, 2e-6);
}

/// Into the sphere: the collider resolved after the step, and the first guess's history
/// dropped where it moved a particle, as on the CPU.
#[test]
fn gpu_implicit_euler_drops_the_cloth_on_the_sphere_as_the_cpu_does() {
    agrees("sphere-drop", 2, 22, 0.3, 2e-5);
}

/// The flag: wind and dihedral bending explicit, as on the CPU (measured: 1.5 µm apart).
#[test]
fn gpu_implicit_euler_flies_the_flag_as_the_cpu_does() {
    agrees("flag", 3, 6, 0.02, 5e-6);
}

/// The solve stops where the CPU's does: cut off after one, two or five iterations (far
/// from converged: the cloths end centimetres from the tight solve's), the GPU's cloth is
/// still the CPU's, so it runs the same iterations from the same first guess.
#[test]
fn the_gpu_solve_stops_at_the_cap_as_the_cpus_does() {
    let (_, tight) = {
        let mut sim = Simulation::new(implicit("hanging", 2, 1e-6, 200));
        (0..6).for_each(|_| sim.step_frame().map(drop).expect("frame"));
        ((), sim.state().pos.clone())
    };
    for cap in [1, 2, 5] {
        let scene = implicit("hanging", 2, 1e-6, cap);
        let mut cpu = Simulation::new(scene.clone());
        let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend");
        for _ in 0..6 {
            cpu.step_frame().expect("cpu frame");
            gpu.step_frame().expect("gpu frame");
        }
        let worst = farthest(&cpu.state().pos, &gpu.state().pos);
        let short = farthest(&cpu.state().pos, &tight);
        eprintln!("cap {cap}: GPU {worst:e} m from the CPU, {short:e} m from the tight solve");
        assert!(
            short > 1e-3,
            "cap {cap}: the cap cuts the solve short ({short} m)"
        );
        assert!(worst < 2e-6, "cap {cap}: GPU and CPU differ by {worst} m");
    }
}

/// Cut off after two iterations, where the first guess decides much of the step: through
/// the impact on the sphere, the GPU drops the last Δv from its guess wherever the collider
/// moved a particle, as the CPU does, and the two cloths stay together.
#[test]
fn the_gpu_forgets_its_guess_where_a_collider_moved_the_cloth() {
    let (worst, moved) = compare(implicit("sphere-drop", 2, 1e-6, 2), 22);
    eprintln!("sphere-drop, 2 iterations: worst {worst:e} m of {moved} m moved");
    assert!(moved > 0.3, "the cloth falls onto the sphere ({moved} m)");
    assert!(worst < 2e-5, "GPU and CPU differ by {worst} m");
}

/// After an outside change (every particle pushed sideways mid-run), the GPU's first guess
/// starts from zero, as the CPU's does: cut off after two iterations, where the guess
/// decides much of the step, the two cloths stay together.
#[test]
fn the_gpu_forgets_its_guess_after_an_outside_change() {
    let worst = apart_after_a_push(implicit("hanging", 2, 1e-6, 2), 4);
    eprintln!("pushed: worst {worst:e} m");
    assert!(worst < 2e-6, "GPU and CPU differ by {worst} m");
}

/// The GPU counts the iterations each solve took, as the CPU does: over a run of the
/// hanging cloth the two counts are within a few per cent of each other (their rounding
/// differs, so a solve may stop an iteration earlier or later), and the solves that stop at
/// the cap are reported as not converged, the same ones as on the CPU.
#[test]
fn the_gpu_reports_the_solves_iterations() {
    for (cap, converges) in [(200, true), (3, false)] {
        let scene = implicit("hanging", 3, 1e-5, cap);
        let mut cpu = Simulation::new(scene.clone());
        let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend");
        for _ in 0..6 {
            cpu.step_frame().expect("cpu frame");
            gpu.step_frame().expect("gpu frame");
        }
        let (on_cpu, on_gpu) = (cpu.take_stats(), gpu.take_stats());
        eprintln!("cap {cap}: CPU {on_cpu:?}, GPU {on_gpu:?}");
        assert_eq!(on_gpu.steps, 18);
        // The solves do iterate: more than the cap of 3 on average when uncapped.
        let most = if converges { 3 } else { 0 };
        assert!(on_cpu.solver_iterations > 18 * most, "{on_cpu:?}");
        let (a, b) = (
            on_cpu.solver_iterations as f64,
            on_gpu.solver_iterations as f64,
        );
        assert!(
            (a - b).abs() <= 0.05 * a,
            "cap {cap}: {a} against {b} iterations"
        );
        assert_eq!(on_gpu.unconverged == 0, converges, "cap {cap}");
        assert_eq!(on_gpu.unconverged, on_cpu.unconverged, "cap {cap}");
    }
}

/// Implicit Euler refined by Newton's method is the CPU's: the GPU refuses it with the
/// reason, the next frame says so, and the state stays as it was.
#[test]
fn newton_iterations_are_refused_on_the_gpu_with_the_reason() {
    let scene = implicit("hanging", 2, 1e-5, 50);
    let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend");
    gpu.step_frame().expect("one linearised step runs");
    let before = gpu.state().clone();
    let mut params = gpu.params().clone();
    params.solver.newton_iterations = 3;
    gpu.set_params(params).expect("valid parameters");
    let err = gpu.step_frame().expect_err("refused");
    let why = format!("{err:?}");
    assert!(why.contains("3 Newton iterations"), "{why}");
    assert_eq!(gpu.state().pos, before.pos);
}

/// Handles carry the cloth under implicit Euler on the GPU as on the CPU: `fast-fold`'s back
/// edge flung over at 10 m/s (without its self-collision, whose pushes the two backends order differently), the carried
/// particles' velocities entering the springs' damping and `∂f/∂x·v` as on the CPU
/// (measured: 0.4 µm apart after the cloth moved 0.48 m). Solved to 10⁻⁵ but at most 20
/// iterations, at 4 substeps, the two ended 0.7 mm apart after 24 frames: the flung cloth's
/// solves stop at the cap, where rounding in other orders leaves other iterates, and the
/// fling amplifies it.
#[test]
fn gpu_implicit_euler_follows_the_handles_as_the_cpu_does() {
    let mut scene = implicit("fast-fold", 2, 1e-5, 200);
    (scene.effects).retain(|e| !matches!(e, clothsim::sim::Effect::SelfCollision(_)));
    let (worst, moved) = compare(scene, 15);
    eprintln!("fast-fold: worst {worst:e} m of {moved} m moved");
    assert!(moved > 0.05, "the handle moves the cloth ({moved} m)");
    assert!(worst < 5e-6, "GPU and CPU differ by {worst} m");
}

/// A tolerance changed mid-run reaches the GPU's solve: from 10⁻⁶ to 10⁻², both backends'
/// solves take far fewer iterations, the same number within a few per cent.
#[test]
fn a_tolerance_changed_mid_run_reaches_the_gpu() {
    let scene = implicit("hanging", 3, 1e-6, 200);
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend");
    let mut counts = Vec::new();
    for tolerance in [1e-6, 1e-2] {
        for sim in [&mut cpu, &mut gpu] {
            let mut params = sim.params().clone();
            params.solver.tolerance = tolerance;
            sim.set_params(params).expect("valid");
            sim.take_stats();
            for _ in 0..3 {
                sim.step_frame().expect("frame");
            }
            counts.push(sim.take_stats().solver_iterations as f64);
        }
    }
    eprintln!("iterations, CPU and GPU, tight then loose: {counts:?}");
    let [tight_cpu, tight_gpu, loose_cpu, loose_gpu] = counts[..] else {
        unreachable!()
    };
    assert!(loose_cpu < 0.5 * tight_cpu, "{counts:?}");
    for (a, b) in [(tight_cpu, tight_gpu), (loose_cpu, loose_gpu)] {
        assert!((a - b).abs() <= 0.05 * a, "{counts:?}");
    }
}
