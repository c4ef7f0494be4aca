//! Wind and dihedral bending on the GPU backend (run here on the software adapter) against
//! the CPU solver, per effect and together, over runs short enough to stay non-chaotic.

use clothsim::gpu::gpu_simulation;
use clothsim::scene::{Scene, Simulation};
use clothsim::sim::{BendingModel, Effect, Wind};

/// The largest distance between the same particle in `a` and `b`, metres.
fn farthest(a: &[glam::Vec3], b: &[glam::Vec3]) -> f32 {
    (a.iter().zip(b))
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f32::max)
}

/// The built-in scene `name` with its grid at 16 quads.
fn small(name: &str) -> Scene {
    let options = clothsim::mesh::ImportOptions::default();
    Scene::open_resized(name, None, &options, Some(16)).expect("a grid scene")
}

/// `frames` frames of `scene` on both backends: the largest distance between the same
/// particle on the two, and the largest distance a particle moved on the CPU.
fn compare(scene: Scene, frames: usize) -> (f32, f32) {
    let start = scene.initial.pos.clone();
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend on the software adapter");
    for _ in 0..frames {
        cpu.step_frame().expect("cpu frame");
        gpu.step_frame().expect("gpu frame");
    }
    assert!(gpu.take_guard_events().is_empty());
    (
        farthest(&cpu.state().pos, &gpu.state().pos),
        farthest(&cpu.state().pos, &start),
    )
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
    let (worst, moved) = compare(hanging_with(Effect::Wind(wind)), 6);
    eprintln!("wind: worst {worst:e} m of {moved} m moved");
    assert!(moved > 0.015, "the wind moves the cloth ({moved} m)");
    assert!(worst < 2e-6, "GPU and CPU differ by {worst} m");
}

/// Dihedral bending instead of bend springs, stiff enough to shape the swing.
#[test]
fn gpu_and_cpu_agree_with_dihedral_bending() {
    let bending = Effect::Bending(BendingModel::Dihedral { stiffness: 0.02 });
    let (worst, moved) = compare(hanging_with(bending), 18);
    eprintln!("dihedral: worst {worst:e} m of {moved} m moved");
    assert!(moved > 0.1, "the cloth swings ({moved} m)");
    assert!(worst < 1e-5, "GPU and CPU differ by {worst} m");
}

/// The flag (wind and dihedral bending together) runs on the GPU as on the CPU.
#[test]
fn gpu_and_cpu_agree_on_the_flag() {
    let (worst, moved) = compare(small("flag"), 18);
    eprintln!("flag: worst {worst:e} m of {moved} m moved");
    assert!(moved > 0.05, "the flag moves ({moved} m)");
    assert!(worst < 1e-5, "GPU and CPU differ by {worst} m");
}
