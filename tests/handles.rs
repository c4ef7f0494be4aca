//! Handles (moving pins): particles chosen as `[pins]` chooses them follow their keyframes
//! exactly, the Pins switch frees them, and bad handles are named.

use std::path::Path;

use clothsim::scene::{Scene, SceneFile, Simulation};
use clothsim::sim::{Effect, Handle, IntegratorKind};

/// A 1 m × 0.25 m strip whose left end turns a full turn about the strip's length in 2 s
/// while moving 10 cm inwards; its right end is pinned.
const STRIP: &str = r#"
name = "strip"
[cloth]
grid = { quads = [20, 5], size = [1.0, 0.25] }
center = [0.0, 1.0, 0.0]
[pins]
edges = ["right"]
[[effects]]
type = "gravity"
[[handles]]
edges = ["left"]
keyframes = [ { time = 0.0 }, { time = 2.0, translate = [0.1, 0.0, 0.0], rotate = { axis = [1.0, 0.0, 0.0], degrees = 360.0 } } ]
"#;

fn strip(toml: &str) -> Scene {
    let file = SceneFile::parse(toml, Path::new("strip.toml")).unwrap_or_else(|e| panic!("{e}"));
    Scene::from_file(file, None).unwrap_or_else(|e| panic!("{e}"))
}

fn the_handle(sim: &Simulation) -> Handle {
    (sim.effects().iter())
        .find_map(|e| match e {
            Effect::Handle(h) => Some(h.clone()),
            _ => None,
        })
        .expect("a handle")
}

/// After every substep, under every integrator, each handled particle is exactly where the
/// motion puts its place, moving with the motion's velocity there; the rest of the cloth is
/// the integrator's.
#[test]
fn handled_particles_follow_their_keyframes_exactly() {
    for kind in IntegratorKind::ALL {
        let mut scene = strip(STRIP);
        scene.params.step.integrator = kind;
        scene.params.step.substeps = match kind {
            IntegratorKind::ExplicitEuler => 1000,
            IntegratorKind::Rk2 => 150,
            _ => 48,
        };
        let mut sim = Simulation::new(scene);
        let handle = the_handle(&sim);
        assert_eq!(handle.particles.len(), 6, "the left edge");
        while sim.state().time < 0.5 {
            sim.substep().unwrap();
            let pose = handle.motion.at(sim.state().time);
            for (&p, &rest) in handle.particles.iter().zip(&handle.rest) {
                let at = pose.apply(handle.pivot, rest);
                assert_eq!(sim.state().pos[p as usize], at, "{kind:?}");
                let v = pose.velocity_at(handle.pivot, at);
                assert_eq!(sim.state().vel[p as usize], v, "{kind:?}");
            }
        }
        // A quarter turn in 0.5 s: the left edge's back end (z = −0.125) is now on top,
        // 2.5 cm further in.
        let back = handle.particles[0] as usize;
        let p = sim.state().pos[back];
        assert!((p.x - (-0.5 + 0.025)).abs() < 1e-4, "{kind:?}: {p}");
        assert!(
            (p.y - 1.125).abs() < 1e-4 && p.z.abs() < 1e-4,
            "{kind:?}: {p}"
        );
    }
}

/// With the Pins switch off a handle lets go: its particles fall with the cloth; on again,
/// they are caught where the motion has them.
#[test]
fn the_pins_switch_frees_and_takes_back_a_handle() {
    let mut sim = Simulation::new(strip(STRIP));
    let handle = the_handle(&sim);
    let p = handle.particles[0] as usize;
    for _ in 0..6 {
        sim.step_frame().unwrap();
    }
    sim.set_pins_enabled(false);
    let before = sim.state().pos[p];
    for _ in 0..12 {
        sim.step_frame().unwrap();
    }
    assert!(sim.state().pos[p].y < before.y - 0.02, "it fell");
    sim.set_pins_enabled(true);
    sim.step_frame().unwrap();
    let pose = handle.motion.at(sim.state().time);
    assert_eq!(sim.state().pos[p], pose.apply(handle.pivot, handle.rest[0]));
}

/// Saved with a pin toggled by hand, the scene keeps its handle as `[[handles]]` and no
/// handled particle in `[pins]`; read back, it builds the same handle.
#[test]
fn a_saved_scene_keeps_its_handles_as_handles() {
    let mut sim = Simulation::new(strip(STRIP));
    sim.toggle_pin(60);
    let file = sim.scene_file();
    let handle = the_handle(&sim);
    assert!(file.pins.indices.contains(&60));
    assert!(
        !(file.pins.indices.iter()).any(|p| handle.particles.contains(p)),
        "{:?}",
        file.pins
    );
    let again = SceneFile::parse(&file.to_toml(), Path::new("again.toml")).unwrap();
    assert_eq!(again.handles, file.handles);
    let rebuilt = Simulation::new(Scene::from_file(again, None).unwrap());
    assert_eq!(the_handle(&rebuilt), handle);
}

/// A handle that chooses nothing, a particle both handled and pinned, and a bad keyframe in
/// the second handle are each one error that says which and where.
#[test]
fn bad_handles_are_named() {
    let build = |toml: &str| {
        let file = SceneFile::parse(toml, Path::new("strip.toml")).map_err(|e| e.to_string())?;
        Scene::from_file(file, None).map_err(|e| e.to_string())
    };
    let nothing = STRIP.replace("edges = [\"left\"]\nkeyframes", "keyframes");
    let err = build(&nothing).unwrap_err();
    assert!(err.contains("handle 1 chooses no particle"), "{err}");

    let both = STRIP.replace("edges = [\"right\"]", "edges = [\"left\"]");
    let err = build(&both).unwrap_err();
    assert!(err.contains("both in handle 1 and in [pins]"), "{err}");

    let second = format!(
        "{STRIP}[[handles]]\nedges = [\"top\"]\nkeyframes = [ {{ time = 1.0 }}, {{ time = 0.5 }} ]\n"
    );
    let err = build(&second).unwrap_err();
    assert!(
        err.contains("strip.toml:15:31") && err.contains("keyframe 1: `time`"),
        "{err}"
    );
}
