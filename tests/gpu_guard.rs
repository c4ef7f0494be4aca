//! The stability guard on the GPU backend (run here on the software adapter): it catches a
//! blow-up, rolls back to a checkpoint kept on the device, refines and recovers as the CPU
//! guard does, and says why when nothing saves a frame.

use clothsim::scene::{Scene, Simulation};
use clothsim::sim::{Effect, GuardAction, GuardEvent, GuardPolicy, IntegratorKind};

mod common;
use common::{farthest, gpu_simulation};

/// The 16 × 16 bench cloth with semi-implicit Euler at `substeps` a frame, springs 30×
/// stiffer, under the guard with `policy`.
fn stiff_cloth(substeps: u32, policy: GuardPolicy) -> Scene {
    let mut scene =
        clothsim::bench::bench_scene(16, IntegratorKind::SemiImplicitEuler).expect("scene");
    let params = &mut scene.params;
    params.step.substeps = substeps;
    params.material.stiffness = params.material.stiffness.map(|k| 30.0 * k);
    params.guard = policy;
    scene
}

/// What the guard did, without the numbers in its reasons (the backends round apart).
fn actions(events: &[GuardEvent]) -> Vec<(String, GuardAction, u32, u32)> {
    (events.iter())
        .map(|e| {
            let time = format!("{:.4}", e.time);
            (time, e.action.clone(), e.substeps_before, e.substeps_after)
        })
        .collect()
}

/// Runs `frames` frames of `scene` on both backends; both simulations and their events.
fn both(scene: Scene, frames: usize) -> (Simulation, Simulation, Vec<GuardEvent>, Vec<GuardEvent>) {
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend on the software adapter");
    let (mut on_cpu, mut on_gpu) = (Vec::new(), Vec::new());
    for _ in 0..frames {
        let (a, b) = (cpu.step_frame(), gpu.step_frame());
        assert_eq!(a.is_ok(), b.is_ok(), "cpu {a:?}, gpu {b:?}");
        on_cpu.extend(cpu.take_guard_events());
        on_gpu.extend(gpu.take_guard_events());
    }
    (cpu, gpu, on_cpu, on_gpu)
}

/// Semi-implicit Euler needs about 52 substeps a frame on the stiff cloth: at 30 the first
/// frame blows up, is redone at 60, and after 10 healthy frames the substeps come back
/// down, blow up again, and are redone from the checkpoint six frames back; the second step
/// down waits twice as long. The GPU does all of it at the same frames as the CPU, and its
/// cloth ends where the CPU's does.
#[test]
fn a_blow_up_on_the_gpu_is_rolled_back_refined_and_recovered_as_on_the_cpu() {
    let policy = GuardPolicy {
        recover_after: 10,
        fallback: None,
        ..GuardPolicy::default()
    };
    let (mut cpu, mut gpu, on_cpu, on_gpu) = both(stiff_cloth(30, policy), 40);
    let expected = [
        ("0.0167", GuardAction::Refined, 30, 60),
        ("0.1833", GuardAction::Recovered, 60, 30),
        ("0.2000", GuardAction::Refined, 30, 60),
        ("0.5333", GuardAction::Recovered, 60, 30),
        ("0.5500", GuardAction::Refined, 30, 60),
    ]
    .map(|(t, a, b, c)| (t.to_string(), a, b, c));
    assert_eq!(actions(&on_cpu), expected);
    assert_eq!(actions(&on_gpu), expected);
    // Each blow-up reached a NaN or infinity within its frame, on both.
    let reasons =
        |events: &[GuardEvent]| events.iter().map(|e| e.reason.clone()).collect::<Vec<_>>();
    assert_eq!(reasons(&on_gpu), reasons(&on_cpu));
    let non_finite = Some("a position or velocity became non-finite".to_string());
    assert_eq!(on_gpu[0].reason, non_finite);
    assert_eq!(gpu.substeps(), 60);
    cpu.sync_state().expect("cpu");
    gpu.sync_state().expect("read back");
    let pos = &gpu.state().pos;
    assert!(pos.iter().all(|p| p.is_finite()));
    let worst = farthest(&cpu.state().pos, pos);
    eprintln!("after 40 frames the backends are {worst:e} m apart");
    assert!(worst < 1e-5, "GPU and CPU differ by {worst} m");
}

/// A reset starts the GPU run over as a new one would: the run above ends with its
/// substeps raised and its guard's wait for a step down doubled, and after a reset it
/// refines and recovers at the same times again; a run that fell back to implicit Euler
/// starts again under the integrator asked for, and falls back in the same frame.
#[test]
fn a_reset_starts_the_gpu_run_over() {
    let run = |gpu: &mut Simulation, frames: usize| {
        for frame in 0..frames {
            (gpu.step_frame()).unwrap_or_else(|e| panic!("frame {frame}: {e}"));
        }
        actions(&gpu.take_guard_events())
    };
    let policy = GuardPolicy {
        recover_after: 10,
        fallback: None,
        ..GuardPolicy::default()
    };
    let (mut gpu, _) = gpu_simulation(stiff_cloth(30, policy), true).expect("GPU backend");
    let first = run(&mut gpu, 40);
    assert_eq!((first.len(), gpu.substeps()), (5, 60), "{first:?}");
    gpu.reset();
    assert_eq!(gpu.substeps(), 30);
    assert_eq!(run(&mut gpu, 40), first);
    let policy = GuardPolicy {
        max_refinements: 1,
        ..GuardPolicy::default()
    };
    let (mut gpu, _) = gpu_simulation(stiff_cloth(8, policy), true).expect("GPU backend");
    let first = run(&mut gpu, 3);
    assert_eq!(gpu.integrator_in_effect(), IntegratorKind::ImplicitEuler);
    gpu.reset();
    assert_eq!(
        gpu.integrator_in_effect(),
        IntegratorKind::SemiImplicitEuler
    );
    assert_eq!(run(&mut gpu, 3), first);
}

/// With one refinement (16 substeps) where 52 are needed, nothing saves the first frame:
/// the GPU run stops with the CPU's cause and count, and its state is the frame's start,
/// to the bit.
#[test]
fn a_frame_nothing_saves_on_the_gpu_stops_at_its_start_and_says_why() {
    let policy = GuardPolicy {
        max_refinements: 1,
        fallback: None,
        ..GuardPolicy::default()
    };
    let scene = stiff_cloth(8, policy);
    let start = scene.initial.pos.clone();
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, false).expect("GPU backend");
    let on_cpu = cpu.step_frame().expect_err("diverges");
    let on_gpu = gpu.step_frame().expect_err("diverges");
    eprintln!("{on_gpu}");
    assert_eq!(on_gpu.cause, on_cpu.cause);
    let speed = "a particle reached inf m/s";
    assert!(on_gpu.reason.starts_with(speed) && on_cpu.reason.starts_with(speed));
    assert_eq!((on_gpu.substeps, on_gpu.time), (16, 0.0));
    assert!(on_gpu.to_string().contains("Too few substeps"), "{on_gpu}");
    let events = gpu.take_guard_events();
    assert_eq!(actions(&events), actions(&cpu.take_guard_events()));
    assert_eq!(events.len(), 1);
    assert_eq!(events[0].action, GuardAction::GaveUp);
    gpu.sync_state().expect("read back");
    assert_eq!(gpu.state().pos, start);
    assert_eq!(gpu.state().time, 0.0);
    assert_eq!(gpu.substeps(), 8);
}

/// With the guard off, the same blow-up runs on: the guard, not the shader, caught it.
#[test]
fn without_the_guard_the_gpu_cloth_blows_up() {
    let policy = GuardPolicy {
        enabled: false,
        ..GuardPolicy::default()
    };
    let (mut gpu, _) = gpu_simulation(stiff_cloth(8, policy), false).expect("GPU backend");
    for _ in 0..3 {
        gpu.step_frame().expect("no guard to stop it");
    }
    gpu.sync_state().expect("read back");
    assert!(gpu.take_guard_events().is_empty());
    let blown = (gpu.state().vel.iter()).filter(|v| !v.is_finite() || v.length() >= 1e6);
    assert!(blown.count() > 0, "every particle slower than 1 km/s");
}

/// A frame that more substeps cannot save (the stiff cloth, at most one refinement) is redone
/// by `fallback` at the requested substeps, on the GPU as on the CPU, in the same frame;
/// `fallback` then stays, and the two cloths go on together for five frames more, to
/// `tolerance` metres.
fn falls_back_as_the_cpu_does(fallback: IntegratorKind, tolerance: f32) {
    let policy = GuardPolicy {
        max_refinements: 1,
        fallback: Some(fallback),
        ..GuardPolicy::default()
    };
    let start = stiff_cloth(8, policy.clone()).initial.pos;
    let (mut cpu, mut gpu, on_cpu, on_gpu) = both(stiff_cloth(8, policy), 6);
    let fell_back = GuardAction::FellBack {
        integrator: fallback,
    };
    let expected = [("0.0167".to_string(), fell_back, 8, 8)];
    assert_eq!(actions(&on_cpu), expected);
    assert_eq!(actions(&on_gpu), expected);
    for sim in [&cpu, &gpu] {
        assert_eq!(sim.integrator_in_effect(), fallback);
    }
    cpu.sync_state().expect("cpu");
    gpu.sync_state().expect("read back");
    // Moved far more than the backends may differ by, or the comparison says nothing.
    let moved = farthest(&gpu.state().pos, &start);
    assert!(moved > 10.0 * tolerance, "the cloth moved {moved} m");
    let worst = farthest(&cpu.state().pos, &gpu.state().pos);
    eprintln!("after falling back to {fallback:?} the backends are {worst:e} m apart");
    assert!(worst < tolerance, "GPU and CPU differ by {worst} m");
}

/// XPBD as the fallback: the two cloths agree to the bit (XPBD's arithmetic is the same on
/// both).
#[test]
fn the_gpu_falls_back_to_xpbd_as_the_cpu_does() {
    falls_back_as_the_cpu_does(IntegratorKind::Xpbd, 1e-5);
}

/// The default fallback, implicit Euler, runs on the GPU too; the cloths agree to the
/// solve's tolerance (measured: 0.13 µm apart, the cloth having moved 0.3 mm; without the
/// GPU solve's `h·(∂f/∂x)·v`, 0.15 mm, which a bound of 0.1 mm had let pass at 96 µm over
/// twelve frames).
#[test]
fn the_gpu_falls_back_to_implicit_euler_by_default_as_the_cpu_does() {
    let default = GuardPolicy::default().fallback;
    assert_eq!(default, Some(IntegratorKind::ImplicitEuler));
    falls_back_as_the_cpu_does(IntegratorKind::ImplicitEuler, 1e-6);
}

/// Story: the GPU counted no pairs that prescribed motion forced, so a run there reported
/// none where the CPU's reported thousands. On [`common::driven_through`] (a handle jumps a
/// pinned square through a pinned square once a frame) the GPU counts the CPU's pairs under
/// the integrators that need no rescue, and a run the guard rescues by finer substeps or
/// the fallback counts those of the tries that stand, not of those rolled back.
#[test]
fn the_gpu_counts_the_pairs_prescribed_motion_forces_in_the_tries_that_stand() {
    let run = |integrator: &str, stiffness: f32, on_gpu: bool| {
        let scene = common::driven_through(integrator, stiffness);
        let mut sim = match on_gpu {
            true => gpu_simulation(scene, false).expect("GPU backend").0,
            false => Simulation::new(scene),
        };
        let summary = sim.run(0.2);
        assert!(summary.error.is_none(), "{:?}", summary.error);
        let rescues: Vec<GuardAction> = (summary.guard_events.iter())
            .map(|e| e.action.clone())
            .collect();
        (sim.forced_pairs().expect("self-collision"), rescues)
    };
    let (expected, _) = run("implicit-euler", 400.0, false);
    assert!(expected > 0, "the jumps force pairs");
    for integrator in ["implicit-euler", "xpbd", "vbd"] {
        assert_eq!(
            run(integrator, 400.0, true),
            (expected, Vec::new()),
            "{integrator}"
        );
    }
    // Symplectic Euler blows up as the free square sags: redone at 8, 16 or 32 substeps at
    // 400 N/m, with implicit Euler at 2 000 (as on the CPU); each try forces the jumps'
    // pairs again. The tries that stand count them as the others do, to within a pair the
    // f32 checks judge apart at the finer substeps.
    for (stiffness, fell_back) in [(400.0, false), (2000.0, true)] {
        let (forced, rescues) = run("semi-implicit-euler", stiffness, true);
        let rescued = rescues.iter().any(|action| match action {
            GuardAction::Refined => !fell_back,
            GuardAction::FellBack { .. } => fell_back,
            _ => false,
        });
        assert!(rescued, "at {stiffness} N/m: {rescues:?}");
        assert!(
            forced.abs_diff(expected) <= 4,
            "{forced} against {expected}"
        );
    }
}

/// A frame nothing saves on the GPU leaves the count where the frame found it, as on the
/// CPU: implicit Euler steps two frames, then symplectic Euler, with one refinement and no
/// fallback, blows up.
#[test]
fn a_frame_the_gpu_gives_up_takes_back_the_pairs_it_forced() {
    let (sim, _) = gpu_simulation(common::driven_to_give_up(), false).expect("GPU backend");
    common::a_frame_given_up_keeps_its_count(sim);
}

/// `flag` on the GPU for `frames` frames with the guard's headroom at `headroom` (or off):
/// the cloth and what the guard did. Without its self-collision: the whip is the wind's and
/// the springs', and the GPU's self-contact on the software adapter would take minutes.
fn gpu_flag(headroom: Option<f32>, frames: usize) -> (Simulation, Vec<GuardEvent>) {
    let mut scene = Scene::builtin("flag").unwrap();
    (scene.effects).retain(|e| !matches!(e, Effect::SelfCollision(_)));
    match headroom {
        Some(h) => scene.params.guard.headroom = h,
        None => scene.params.guard.enabled = false,
    }
    let (mut sim, _) = gpu_simulation(scene, true).expect("GPU backend on the software adapter");
    let mut events = Vec::new();
    for _ in 0..frames {
        sim.step_frame().expect("frame");
        events.extend(sim.take_guard_events());
    }
    (sim, events)
}

/// The GPU's guard judges a frame's end: with the headroom at 1 the flag's whipping corners
/// cross its speed limit there. Twice the substeps agree with the frame, so it stands, as on
/// the CPU: no refinement, no fallback, and the cloth is the unguarded run's.
#[test]
fn a_flags_whip_stands_on_the_gpu_as_on_the_cpu() {
    let (guarded, events) = gpu_flag(Some(1.0), 60);
    let (free, _) = gpu_flag(None, 60);
    assert!(!events.is_empty(), "the limit was crossed");
    for e in &events {
        assert!(matches!(e.action, GuardAction::Raised { .. }), "{e}");
    }
    assert_eq!(
        guarded.integrator_in_effect(),
        IntegratorKind::SemiImplicitEuler
    );
    assert_eq!(guarded.substeps(), 48);
    assert_eq!(farthest(&guarded.state().pos, &free.state().pos), 0.0);
}

/// `crumple` at 32² without its self-collision, under XPBD at one 50 ms substep a frame:
/// where it lands (0.65 s) 8 × the substeps do not save XPBD (a spring stretched 145 %),
/// and implicit Euler at the requested one substep does not either; refined as the
/// integrator asked for was, it stands at 8.
fn crumple_landing_in_long_substeps() -> Scene {
    let mut scene = Scene::open_resized("crumple", None, &Default::default(), Some(32)).unwrap();
    (scene.effects).retain(|e| !matches!(e, Effect::SelfCollision(_)));
    scene.params.step.integrator = IntegratorKind::Xpbd;
    (scene.params.step.dt, scene.params.step.substeps) = (0.05, 1);
    scene.params.guard.max_refinements = 3;
    scene
}

/// The fallback refined on the GPU as on the CPU: in the same frame, to the same substeps,
/// and the run goes on under implicit Euler.
#[test]
fn the_gpu_refines_its_fallback_as_the_cpu_does() {
    let (cpu, gpu, on_cpu, on_gpu) = both(crumple_landing_in_long_substeps(), 14);
    let fell_back = |events: &[GuardEvent]| {
        (events.iter())
            .find(|e| matches!(e.action, GuardAction::FellBack { .. }))
            .map(|e| {
                (
                    format!("{:.2}", e.time),
                    e.substeps_before,
                    e.substeps_after,
                )
            })
    };
    let on_cpu = fell_back(&on_cpu).expect("the CPU falls back");
    assert!(on_cpu.2 > 1, "refined: {on_cpu:?}");
    assert_eq!(fell_back(&on_gpu), Some(on_cpu));
    for sim in [&cpu, &gpu] {
        assert_eq!(sim.integrator_in_effect(), IntegratorKind::ImplicitEuler);
    }
}
