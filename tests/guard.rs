//! The stability guard: what it catches, how it rolls back, refines, falls back and
//! recovers, and what it records.

use clothsim::scene::{Scene, Simulation};
use clothsim::sim::{FrameOutcome, GuardAction, GuardPolicy, IntegratorKind};

fn hanging(configure: impl FnOnce(&mut Scene)) -> Simulation {
    let mut scene = Scene::builtin("hanging").unwrap();
    configure(&mut scene);
    Simulation::new(scene)
}

fn bits(sim: &Simulation) -> Vec<u32> {
    let s = sim.state();
    s.pos
        .iter()
        .chain(&s.vel)
        .flat_map(|v| v.to_array())
        .map(f32::to_bits)
        .collect()
}

/// Story: the old guard only said the state was "rolled back"; now a frame nothing can
/// save leaves the state bit for bit as it was before the frame, at the same time.
#[test]
fn when_nothing_saves_a_frame_the_rollback_is_exact() {
    let mut sim = hanging(|s| {
        s.params.stiffness = [1e7; 3];
        s.params.substeps = 2;
        s.params.guard = GuardPolicy {
            max_refinements: 1,
            fallback: None,
            ..GuardPolicy::default()
        };
    });
    let (before, time, frames) = (bits(&sim), sim.state().time, sim.frames());
    let err = sim.step_frame().unwrap_err();
    assert_eq!(bits(&sim), before, "the state is exactly the frame's start");
    assert_eq!((sim.state().time, sim.frames()), (time, frames));
    assert_eq!(sim.substeps(), 2, "the request stands");
    assert!(err.to_string().contains("rolled back"), "{err}");
    let events = sim.take_guard_events();
    assert_eq!(events.last().unwrap().action, GuardAction::GaveUp);
}

/// Story: a hard pull raised the limits (the stretch a drag makes is the user's doing, not a
/// blow-up). Raised, they still catch one before anything becomes non-finite: with the
/// cloth held stretched past the default strain limit, explicit Euler at the scene's 48
/// substeps (it needs about 8 × as many) is stopped by a limit in its first frame, rolled
/// back exactly, with the particle still held.
#[test]
fn a_blow_up_is_still_caught_while_a_pull_holds_the_cloth_stretched() {
    let mut sim = hanging(|_| {});
    sim.run(0.5);
    let pos = &sim.state().pos;
    let p = (0..pos.len())
        .min_by(|&a, &b| pos[a].y.total_cmp(&pos[b].y))
        .unwrap() as u32;
    let start = pos[p as usize];
    for k in 1..=30 {
        sim.grab(
            p,
            start + glam::Vec3::new(0.0, 0.0, 4.0) * (k as f32 / 60.0),
        );
        sim.step_frame().unwrap();
    }
    assert!(sim.take_guard_events().is_empty(), "the pull alone is fine");
    let mut params = sim.params().clone();
    params.integrator = IntegratorKind::ExplicitEuler;
    params.guard = GuardPolicy {
        max_refinements: 0,
        fallback: None,
        ..GuardPolicy::default()
    };
    sim.set_params(params).unwrap();
    let (before, time) = (bits(&sim), sim.state().time);
    let err = sim.step_frame().unwrap_err().to_string();
    assert_eq!(bits(&sim), before, "the state is exactly the frame's start");
    assert_eq!(sim.state().time, time);
    assert_eq!(sim.grabbed(), Some(p));
    assert!(
        !err.contains("non-finite") && err.contains("limit"),
        "caught by a limit while still finite: {err}"
    );
}

/// At 100 × the stiffness symplectic Euler would need about 10 × the substeps; one
/// refinement (2 ×) is not enough, so the guard falls back to implicit Euler, which stays.
#[test]
fn the_fallback_integrator_saves_what_refinement_cannot() {
    let mut sim = hanging(|s| {
        s.params.stiffness = s.params.stiffness.map(|k| k * 100.0);
        s.params.guard.max_refinements = 1;
    });
    let summary = sim.run(1.0);
    assert!(
        summary.finite && summary.error.is_none(),
        "{:?}",
        summary.error
    );
    assert_eq!(summary.integrator_in_effect, "implicit-euler");
    let fell_back = summary
        .guard_events
        .iter()
        .find(|e| matches!(e.action, GuardAction::FellBack { .. }))
        .expect("a fallback event");
    assert_eq!(fell_back.substeps_after, 48, "at the requested substeps");
    assert_eq!(summary.requested_substeps, 48);
    // Asking again (any new parameters) tries the requested integrator once more.
    let params = sim.params().clone();
    sim.set_params(params).unwrap();
    assert_eq!(
        sim.integrator_in_effect(),
        IntegratorKind::SemiImplicitEuler
    );
}

/// Story: substeps the guard raised used to stay for the rest of the run, so one bad frame
/// made everything after it 2–8× slower. Once the trouble has passed they come back down.
#[test]
fn substeps_come_back_down_once_the_trouble_has_passed() {
    let mut sim = hanging(|s| s.params.stiffness = s.params.stiffness.map(|k| k * 16.0));
    let mut raised = 0;
    for _ in 0..60 {
        if let Ok(FrameOutcome::Refined { to, .. }) = sim.step_frame() {
            raised = to;
        }
    }
    assert!(
        raised > 48,
        "the stiff cloth made the guard raise the substeps"
    );
    // The cloth softens again: after a second of healthy frames per halving the substeps
    // return to the requested 48.
    let mut params = sim.params().clone();
    params.stiffness = [400.0, 150.0, 20.0];
    sim.set_params(params).unwrap();
    assert_eq!(
        sim.substeps(),
        raised,
        "a parameter change keeps the raised substeps"
    );
    let mut recovered = Vec::new();
    for _ in 0..300 {
        if let Ok(FrameOutcome::Recovered { from, to }) = sim.step_frame() {
            recovered.push((from, to));
        }
    }
    assert_eq!(
        sim.substeps(),
        48,
        "back to the request after {recovered:?}"
    );
    assert_eq!(recovered.last().map(|r| r.1), Some(48));
    assert!(
        sim.take_guard_events()
            .iter()
            .any(|e| e.action == GuardAction::Recovered && e.reason.is_none())
    );
}

/// A rescue rolls back to a state from before the trouble and replays from there at the
/// finer substeps, so no trace of the failed tries survives: a run started at 12 substeps
/// (symplectic Euler needs about 30), rescued at 48, ends where a run at 48 from the start
/// ends — including after the guard stepped back down to 24, failed, and was rescued again.
/// (A comparison with yet finer steps would measure the folding cloth's chaos instead: runs
/// at 48 and 96 substeps are 7 cm apart after 2 s.)
#[test]
fn a_rescued_run_leaves_no_trace_of_its_failed_tries() {
    let mut rescued = hanging(|s| s.params.substeps = 12);
    let summary = rescued.run(2.0);
    let refined = summary
        .guard_events
        .iter()
        .filter(|e| e.action == GuardAction::Refined)
        .count();
    assert!(refined >= 2, "{:?}", summary.guard_events);
    assert!(
        summary
            .guard_events
            .iter()
            .any(|e| e.action == GuardAction::Recovered)
    );
    assert_eq!(rescued.substeps(), 48);
    let mut clean = hanging(|s| s.params.substeps = 48);
    clean.run(2.0);
    let worst = rescued
        .state()
        .pos
        .iter()
        .zip(&clean.state().pos)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f32::max);
    assert!(worst < 1e-6, "{worst} m apart");
}

#[test]
fn the_guard_can_be_switched_off() {
    let mut sim = hanging(|s| {
        s.params.substeps = 2;
        s.params.guard.enabled = false;
    });
    let summary = sim.run(1.0);
    assert!(summary.guard_events.is_empty());
    assert!(!summary.finite, "nothing stopped the blow-up");
    assert!(
        summary.error.is_none(),
        "and nothing was reported as an error"
    );
}

#[test]
fn a_bad_policy_is_refused_by_name() {
    let mut sim = hanging(|_| {});
    let mut params = sim.params().clone();
    params.guard.max_strain = -1.0;
    let err = sim.set_params(params).unwrap_err().to_string();
    assert!(err.contains("guard.max_strain"), "{err}");
}
