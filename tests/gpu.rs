//! The GPU backend (wgpu compute, run here on the software adapter) against the CPU solver:
//! the same scene after the same simulated time.

use clothsim::gpu::{Backend, gpu_simulation, gpu_support};
use clothsim::scene::{Scene, Simulation};
use clothsim::sim::IntegratorKind;

/// The largest distance between the same particle in `a` and `b`, metres.
fn farthest(a: &[glam::Vec3], b: &[glam::Vec3]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f32::max)
}

/// Runs `scene` for `seconds` on both backends; the largest distance between the same
/// particle's positions, and the largest distance any particle moved (for scale).
fn compare(scene: Scene, frames: usize) -> (f32, f32, Simulation) {
    let start = scene.initial.pos.clone();
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend on the software adapter");
    assert_eq!(gpu.backend_name(), "gpu");
    for _ in 0..frames {
        cpu.step_frame().expect("cpu frame");
        gpu.step_frame().expect("gpu frame");
    }
    gpu.sync_state().expect("read back");
    assert!((cpu.state().time - gpu.state().time).abs() < 1e-9);
    let worst = farthest(&cpu.state().pos, &gpu.state().pos);
    let moved = farthest(&cpu.state().pos, &start);
    (worst, moved, gpu)
}

#[test]
fn gpu_and_cpu_agree_on_every_particle_of_the_hanging_cloth_after_one_second() {
    let scene = clothsim::bench::bench_scene(32, IntegratorKind::SemiImplicitEuler).expect("scene");
    let (worst, moved, _) = compare(scene, 60);
    eprintln!("hanging-bench: worst {worst:e} m of {moved} m moved");
    assert!(moved > 0.005, "the cloth sags");
    assert!(worst < 1e-5, "GPU and CPU differ by {worst} m");
}

/// A cloth hitting a sphere at 3 m/s crumples chaotically (on the CPU alone, moving every
/// particle by 1 µm at the start moves the result by millimetres within a second), so the
/// contacts are compared over the frames around the first impact, where the sphere and
/// the plane are resolved on both backends but no fold has amplified rounding yet.
#[test]
fn gpu_and_cpu_resolve_the_same_sphere_contacts_at_impact() {
    let scene = Scene::builtin("sphere-drop").expect("scene");
    let offset = scene.params.collision_offset;
    let colliders = clothsim::sim::colliders_of(&scene.effects);
    let (worst, moved, gpu) = compare(scene, 20);
    eprintln!("sphere-drop: worst {worst:e} m of {moved} m moved");
    assert!(moved > 0.3, "the cloth falls");
    let touching = gpu
        .state()
        .pos
        .iter()
        .filter(|&&p| colliders[0].surface(p).0 < offset + 1e-4)
        .count();
    assert!(
        touching >= 4,
        "the cloth lies on the sphere ({touching} particles)"
    );
    assert!(worst < 1e-5, "GPU and CPU differ by {worst} m");
}

#[test]
fn gpu_backend_refuses_what_it_cannot_run_with_a_clear_reason() {
    let flag = Scene::builtin("flag").expect("scene");
    let err = gpu_support(&flag.params, &flag.effects).expect_err("wind is CPU only");
    assert!(
        err.to_string().contains("wind") || err.to_string().contains("dihedral"),
        "{err}"
    );
    let mut rk4 = Scene::builtin("hanging").expect("scene");
    rk4.params.integrator = IntegratorKind::Rk4;
    let err = gpu_support(&rk4.params, &rk4.effects).expect_err("RK4 is CPU only");
    assert!(err.to_string().contains("semi-implicit Euler"), "{err}");
    assert_eq!(Backend::default(), Backend::Cpu);
    // Switching the integrator of a running GPU simulation fails the next frame, with the
    // reason, and keeps the state.
    let (mut sim, _) =
        gpu_simulation(Scene::builtin("hanging").expect("scene"), true).expect("gpu");
    sim.step_frame().expect("frame");
    let before = sim.state().clone();
    let mut params = sim.params().clone();
    params.integrator = IntegratorKind::Rk4;
    sim.set_params(params).expect("valid parameters");
    let err = sim.step_frame().expect_err("unsupported");
    assert!(err.reason.contains("semi-implicit Euler"), "{}", err.reason);
    assert_eq!(sim.state().pos, before.pos);
}

/// A parameter change on a running GPU simulation reaches the shader: new spring
/// strengths, substeps and gravity, applied mid-run on both backends, keep them together.
#[test]
fn a_parameter_change_mid_run_reaches_the_gpu() {
    let scene = clothsim::bench::bench_scene(16, IntegratorKind::SemiImplicitEuler).expect("scene");
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, true).expect("gpu");
    for sim in [&mut cpu, &mut gpu] {
        for _ in 0..10 {
            sim.step_frame().expect("frame");
        }
        let mut params = sim.params().clone();
        params.stiffness = params.stiffness.map(|k| 3.0 * k);
        params.substeps = 24;
        params.gravity = glam::Vec3::new(2.0, -5.0, 1.0);
        sim.set_params(params).expect("valid");
        for _ in 0..20 {
            sim.step_frame().expect("frame");
        }
    }
    assert_eq!(gpu.substeps(), 24);
    let worst = farthest(&cpu.state().pos, &gpu.state().pos);
    let drift = cpu
        .state()
        .pos
        .iter()
        .map(|p| p.z.abs())
        .fold(0.0, f32::max);
    assert!(drift > 1e-3, "the sideways gravity acted ({drift} m)");
    assert!(
        worst < 1e-5,
        "GPU and CPU differ by {worst} m after the change"
    );
}
