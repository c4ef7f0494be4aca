//! Grabbing and pinning particles while the simulation runs, under every integrator, and
//! a reset.

use std::path::Path;

use clothsim::mesh::ImportOptions;
use clothsim::scene::{GRAB_WINDOW, Scene, SceneFile, Simulation};
use clothsim::sim::{GuardAction, IntegratorKind};
use glam::Vec3;

/// A 10×10-quad cloth held by its top corners, run for a moment with `kind` at substeps it
/// is stable with.
fn hanging(kind: IntegratorKind) -> Simulation {
    let text = "name = \"small\"\n\
        [cloth]\ngrid = { quads = 10, size = 1.0 }\norientation = \"vertical\"\ncenter = [0.0, 1.5, 0.0]\n\
        [pins]\ncorners = [\"top-left\", \"top-right\"]\n\
        [material]\ndensity = 0.2\n\
        stiffness = { structural = 400.0, shear = 150.0, bend = 20.0 }\n\
        damping = { structural = 0.02, shear = 0.01, bend = 0.002 }\n\
        [[effects]]\ntype = \"gravity\"\n\
        [[effects]]\ntype = \"air-damping\"\nrate = 0.5\n\
        [[effects]]\ntype = \"bending\"\nmodel = \"springs\"\n";
    let mut scene = Scene::from_file(
        SceneFile::parse(text, Path::new("small.toml")).unwrap(),
        None,
    )
    .unwrap();
    scene.params.step.integrator = kind;
    // Well inside each method's stable range for this cloth (see the accuracy report).
    scene.params.step.substeps = match kind {
        IntegratorKind::ExplicitEuler => 1500,
        IntegratorKind::Rk2 => 120,
        IntegratorKind::ImplicitEuler => 4,
        IntegratorKind::Xpbd | IntegratorKind::Vbd => 10,
        _ => 40,
    };
    let mut sim = Simulation::new(scene);
    sim.run(0.2);
    sim
}

/// The free particle farthest from the pins, and one of its spring neighbours.
fn bottom_middle(sim: &Simulation) -> (u32, u32) {
    let pos = &sim.state().pos;
    let p = (0..pos.len())
        .filter(|&i| i % 11 == 5)
        .min_by(|&a, &b| pos[a].y.total_cmp(&pos[b].y))
        .unwrap() as u32;
    let springs = &sim.model().springs;
    let q = (0..springs.len())
        .find_map(|e| (springs.a[e] == p).then_some(springs.b[e]))
        .unwrap();
    (p, q)
}

#[test]
fn a_grabbed_particle_follows_the_pointer_and_pulls_the_cloth_under_every_integrator() {
    for kind in IntegratorKind::ALL {
        let mut sim = hanging(kind);
        let (p, q) = bottom_middle(&sim);
        let (start, neighbour) = (sim.state().pos[p as usize], sim.state().pos[q as usize]);
        let pull = Vec3::new(0.0, 0.0, 0.3);
        for k in 1..=30 {
            let target = start + pull * (k as f32 / 30.0);
            sim.grab(p, target);
            sim.step_frame().unwrap_or_else(|e| panic!("{kind:?}: {e}"));
            assert_eq!(
                sim.state().pos[p as usize],
                target,
                "{kind:?}: held where the pointer is"
            );
            assert_eq!(sim.grabbed(), Some(p));
        }
        assert_eq!(
            sim.integrator_in_effect(),
            kind,
            "{kind:?} ran without falling back"
        );
        let moved = sim.state().pos[q as usize] - neighbour;
        assert!(
            moved.z > 0.15,
            "{kind:?}: the neighbour followed by only {moved}"
        );
        // Let go: the particle is free again and swings back.
        let held = sim.state().pos[p as usize];
        sim.release();
        assert_eq!(sim.grabbed(), None);
        assert!(
            !sim.model().pins.contains(&p),
            "{kind:?}: released particles are not pins"
        );
        sim.run(0.25);
        let back = held.z - sim.state().pos[p as usize].z;
        assert!(back > 0.02, "{kind:?}: swung back by {back} m");
    }
}

/// Holds particle `p` of `sim` and moves the pointer along `path` (metres from where the
/// particle was, as a function of the simulated seconds since), sampling it every `every`
/// frames for `frames` frames (a multiple of `every`) and at the end.
fn drag(sim: &mut Simulation, p: u32, every: usize, frames: usize, path: impl Fn(f64) -> Vec3) {
    assert_eq!(frames % every, 0);
    let (start, t0) = (sim.state().pos[p as usize], sim.state().time);
    for k in 0..=frames {
        if k % every == 0 {
            sim.grab(p, start + path(sim.state().time - t0));
        }
        if k < frames {
            sim.step_frame().unwrap();
        }
    }
}

/// [`drag`]s the bottom-middle particle, then lets go; returns its velocity as it was let go.
fn fling(sim: &mut Simulation, every: usize, frames: usize, path: impl Fn(f64) -> Vec3) -> Vec3 {
    let (p, _) = bottom_middle(sim);
    drag(sim, p, every, frames, path);
    sim.release();
    sim.state().vel[p as usize]
}

/// Letting go flings the particle on at the pointer's velocity over its last tenth of a
/// simulated second: the same whether the window sampled the pointer every frame or every
/// second, third or ninth one (a frame's move over one frame's time would be 2–9 times it),
/// barely moved by one jittery sample, nothing once the pointer has stopped, and nothing
/// from before a reset.
#[test]
fn a_released_particle_flies_on_at_the_pointers_recent_velocity() {
    let speed = Vec3::new(0.0, 0.0, 0.5);
    // (Every ninth frame is further apart than the window: the sample before it counts.)
    for every in [1, 2, 3, 9] {
        let mut sim = hanging(IntegratorKind::SemiImplicitEuler);
        let v = fling(&mut sim, every, 18, |t| speed * t as f32);
        assert!(
            (v - speed).length() < 1e-3,
            "sampled every {every} frames: let go at {v} m/s, the pointer moved at {speed}"
        );
    }
    // The last sample 2 mm off the line: one frame's move would be off by 0.12 m/s.
    let mut sim = hanging(IntegratorKind::SemiImplicitEuler);
    let last = 12.0 / 60.0;
    let v = fling(&mut sim, 1, 12, |t| {
        speed * t as f32 + Vec3::Y * if t > last - 1e-3 { 0.002 } else { 0.0 }
    });
    let off = (v - speed).length();
    assert!(
        off < 0.025,
        "one jittery sample moved the velocity by {off} m/s"
    );
    // A pointer that stood still for longer than the window lets go of a still particle.
    let mut sim = hanging(IntegratorKind::SemiImplicitEuler);
    let stop = 6.0 / 60.0;
    let frames = 6 + (GRAB_WINDOW * 60.0).ceil() as usize;
    let v = fling(&mut sim, 1, frames, |t| speed * t.min(stop) as f32);
    assert_eq!(v, Vec3::ZERO, "let go after the pointer stopped");
    // A reset while holding turns the clock back: the pointer's moves from before it (later
    // on the clock) no longer count, and sampling every other frame still gives its speed.
    let mut sim = hanging(IntegratorKind::SemiImplicitEuler);
    let (p, _) = bottom_middle(&sim);
    drag(&mut sim, p, 1, 6, |t| -speed * t as f32);
    sim.reset();
    // (Let go within the window: earlier samples would still be in it.)
    drag(&mut sim, p, 2, 4, |t| speed * t as f32);
    sim.release();
    let v = sim.state().vel[p as usize];
    assert!(
        (v - speed).length() < 1e-3,
        "after a reset: let go at {v} m/s"
    );
}

#[test]
fn clicking_pins_a_particle_where_it_is_and_clicking_again_frees_it() {
    for kind in IntegratorKind::ALL {
        let mut sim = hanging(kind);
        let (p, _) = bottom_middle(&sim);
        // Give it some motion first, so pinning must stop it.
        sim.modify_state(|s| s.vel[p as usize] = Vec3::new(0.0, 0.0, 1.0));
        sim.toggle_pin(p);
        assert!(sim.model().pins.contains(&p));
        let at = sim.state().pos[p as usize];
        sim.run(0.25);
        assert_eq!(
            sim.state().pos[p as usize],
            at,
            "{kind:?}: a pinned particle stays put"
        );
        // The rest of the cloth still moves around it.
        assert!(sim.state().kinetic_energy(sim.model()) > 0.0);
        sim.toggle_pin(p);
        assert!(!sim.model().pins.contains(&p));
        sim.run(0.25);
        let moved = sim.state().pos[p as usize].distance(at);
        assert!(moved > 1e-3, "{kind:?}: freed, it moves ({moved} m)");
        // The scene's own pins are toggled the same way.
        let corner = sim.scenario_pins()[0];
        sim.toggle_pin(corner);
        assert!(
            !sim.model().pins.contains(&corner),
            "{kind:?}: a scene pin released"
        );
        let corner_at = sim.state().pos[corner as usize];
        sim.run(0.25);
        assert!(
            sim.state().pos[corner as usize].y < corner_at.y - 0.01,
            "{kind:?}: it drops"
        );
    }
}

/// The largest relative extension of any spring.
fn max_strain(sim: &Simulation) -> f32 {
    let (s, pos) = (&sim.model().springs, &sim.state().pos);
    (0..s.len())
        .map(|e| pos[s.a[e] as usize].distance(pos[s.b[e] as usize]) / s.rest[e] - 1.0)
        .fold(0.0, f32::max)
}

/// Story: dragging the cloth fast made the guard call it a blow-up (the springs at the held
/// particle stretched past its 100 % limit) and freeze it. A hard pull is the user's doing:
/// the bottom-middle particle dragged at 8 m/s for half a second (4 m, four times the
/// cloth's size), then let go to snap back, loses no frame, raises no substeps and changes
/// no integrator, under every integrator.
#[test]
fn a_hard_pull_and_its_snap_back_are_not_mistaken_for_a_blow_up() {
    for kind in IntegratorKind::ALL {
        let mut sim = hanging(kind);
        let (p, _) = bottom_middle(&sim);
        let start = sim.state().pos[p as usize];
        let mut stretched = 0.0f32;
        for k in 1..=30 {
            sim.grab(p, start + Vec3::new(0.0, 0.0, 8.0) * (k as f32 / 60.0));
            sim.step_frame()
                .unwrap_or_else(|e| panic!("{kind:?}, frame {k} of the pull: {e}"));
            stretched = stretched.max(max_strain(&sim));
        }
        assert!(
            stretched > 1.0,
            "{kind:?}: the pull stretched a spring by only {:.0} %",
            100.0 * stretched
        );
        sim.release();
        let let_go = sim.state().pos[p as usize];
        for k in 1..=60 {
            sim.step_frame()
                .unwrap_or_else(|e| panic!("{kind:?}, frame {k} after letting go: {e}"));
        }
        let events = sim.take_guard_events();
        assert!(
            events.is_empty(),
            "{kind:?}: the guard stepped in: {}",
            events[0]
        );
        assert_eq!(sim.integrator_in_effect(), kind);
        let back = let_go.z - sim.state().pos[p as usize].z;
        assert!(back > 1.0, "{kind:?}: sprang back by only {back} m");
    }
}

/// A reset starts the run over as a new simulation would: the frames after it are the
/// first run's, bit for bit, and so are the guard's events. Where the first run left
/// self-contact's search memory behind (`layers`, five stacked cloths, at 16², and `arm`,
/// a cloth a turning body wraps, at 12²: replayed with that memory, they parted from the
/// first run in frames 16 and 13), and where its guard changed how it steps (`hanging` at
/// 100 × the stiffness: with one refinement allowed it falls back to implicit Euler, and
/// the replay starts under the integrator asked for; with three and no fallback it ends
/// with its substeps raised, and the replay starts at those asked for, with the guard's
/// wait for a step down as a new run's).
#[test]
fn a_reset_replays_the_run_bit_for_bit() {
    let replayed = |mut sim: Simulation, frames: usize, name: &str| {
        let first: Vec<(Vec<Vec3>, Vec<Vec3>)> = (0..frames)
            .map(|f| {
                sim.step_frame()
                    .unwrap_or_else(|e| panic!("{name}, frame {f}: {e}"));
                (sim.state().pos.clone(), sim.state().vel.clone())
            })
            .collect();
        let events = sim.take_guard_events();
        sim.reset();
        for (f, (pos, vel)) in first.iter().enumerate() {
            sim.step_frame()
                .unwrap_or_else(|e| panic!("{name}, frame {f} again: {e}"));
            let s = sim.state();
            assert!(s.pos == *pos && s.vel == *vel, "{name}: frame {f} differs");
        }
        assert_eq!(events, sim.take_guard_events(), "{name}");
        events
    };
    for (name, quads, frames) in [("layers", 8, 40), ("layers", 16, 30), ("arm", 12, 30)] {
        let scene = Scene::open_resized(name, None, &ImportOptions::default(), Some(quads));
        let sim = Simulation::new(scene.unwrap_or_else(|e| panic!("{name}: {e}")));
        assert!(sim.self_collision_work().is_some(), "{name}: self-contact");
        replayed(sim, frames, name);
    }
    let stiff = |refinements: u32, fallback: Option<IntegratorKind>| {
        let mut scene = Scene::builtin("hanging").expect("hanging");
        scene.params.material.stiffness = scene.params.material.stiffness.map(|k| k * 100.0);
        scene.params.guard.max_refinements = refinements;
        scene.params.guard.fallback = fallback;
        Simulation::new(scene)
    };
    let events = replayed(
        stiff(1, Some(IntegratorKind::ImplicitEuler)),
        60,
        "fell back",
    );
    assert!(
        (events.iter()).any(|e| matches!(e.action, GuardAction::FellBack { .. })),
        "{events:?}"
    );
    // Refined at the first frame, down again after a second of health, up again at once:
    // the run ends with its substeps raised and its wait for the next step down doubled.
    let events = replayed(stiff(3, None), 90, "refined");
    let actions: Vec<_> = events.iter().map(|e| e.action.clone()).collect();
    use GuardAction::{Recovered, Refined};
    assert_eq!(actions, [Refined, Recovered, Refined], "{events:?}");
}
