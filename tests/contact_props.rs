//! Property test of the contact guarantee: the stress scenes with their settings drawn at
//! random (grid, thickness up to near half the spacing, frictions, stiffness, density,
//! integrator and substeps, drop height, sphere, how fast the handles move) never end a
//! frame with the cloth through itself or a solid, unless prescribed motion forced a pair
//! and it was counted, on the CPU and on the GPU. The cases come from a fixed seed: the same
//! ones every run.

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};

use clothsim::scene::Simulation;
use clothsim::sim::IntegratorKind;

mod common;
use common::{edited_builtin, parsed};

/// One draw of a stress scene's settings.
#[derive(Clone, Debug)]
struct Variation {
    scene: &'static str,
    quads: u32,
    /// The self-collision thickness as a share of the grid's spacing.
    thickness: f32,
    /// Every `friction` in the file, in order (the self-contact's among them).
    frictions: [f32; 3],
    structural: f32,
    density: f32,
    integrator: IntegratorKind,
    substeps: u32,
    air_damping: f32,
    /// `crumple`: the drop height above the sphere, m, and the sphere's radius, m.
    drop: (f32, f32),
    /// `fast-fold`: when the fold ends, s (it starts at 0.2); `twist`: how long a turn
    /// takes, s.
    pace: f32,
}

/// A draw among `integrators` on grids of 6 to `most` quads. The integrators stable at a
/// few substeps a frame get 1–8 of them; the explicit ones 8–24 (their guard refines from
/// there).
fn variation(integrators: &[IntegratorKind], most: u32) -> impl Strategy<Value = Variation> {
    let scenes = prop::sample::select(vec!["crumple", "twist", "layers", "fast-fold", "self-fold"]);
    let integrators = prop::sample::select(integrators.to_vec());
    (
        (
            scenes,
            6u32..=most,
            0.05f32..0.45,
            prop::array::uniform3(0.0f32..1.0),
        ),
        (
            prop::sample::select(vec![100.0f32, 400.0, 1500.0, 4000.0]),
            0.7f32..1.3,
            0.05f32..0.6,
        ),
        (integrators, 0usize..4, 0.0f32..1.0),
        ((0.5f32..3.0, 0.05f32..0.35), 0.0f32..1.0),
    )
        .prop_map(
            |(
                (scene, quads, thickness, frictions),
                (stiffness, scale, density),
                (integrator, pick, air_damping),
                (drop, pace),
            )| {
                let stable_at_any_step = matches!(
                    integrator,
                    IntegratorKind::ImplicitEuler | IntegratorKind::Xpbd | IntegratorKind::Vbd
                );
                let substeps = match stable_at_any_step {
                    true => [1, 2, 4, 8][pick],
                    false => [8, 12, 16, 24][pick],
                };
                // A fold over in 0.06–0.4 s (the scene's own: 0.157), a turn in 1–4 s.
                let pace = match scene {
                    "fast-fold" => 0.26 + 0.34 * pace,
                    _ => 1.0 + 3.0 * pace,
                };
                Variation {
                    scene,
                    quads,
                    thickness,
                    frictions,
                    structural: stiffness * scale,
                    density,
                    integrator,
                    substeps,
                    air_damping,
                    drop,
                    pace,
                }
            },
        )
}

/// `text` with the value after `key = ` on each line that starts with it given by `value`
/// (called once per such line, in order).
fn set(text: &str, key: &str, mut value: impl FnMut() -> String) -> String {
    let prefix = format!("{key} = ");
    let lines = text.lines().map(|line| match line.starts_with(&prefix) {
        true => format!("{prefix}{}", value()),
        false => line.to_string(),
    });
    lines.collect::<Vec<_>>().join("\n")
}

/// The scene's file with `v`'s settings written in.
fn scene_text(v: &Variation) -> String {
    let stiffness = (
        "stiffness = { structural = 400.0,",
        format!("stiffness = {{ structural = {},", v.structural),
    );
    let pace = |from: &'static str| (from, format!("time = {}", v.pace));
    let edits = match v.scene {
        "fast-fold" => vec![stiffness, pace("time = 0.357")],
        "twist" => vec![stiffness, pace("time = 4.0")],
        _ => vec![stiffness],
    };
    let text = edited_builtin(v.scene, &edits);
    let q = v.quads;
    let (grid, size) = match v.scene {
        "twist" => (format!("[{q}, {}]", (q / 4).max(2)), "[1.0, 0.25]"),
        "layers" => (q.to_string(), "0.8, layers = 5, spacing = 0.04"),
        _ => (q.to_string(), "1.0"),
    };
    let spacing = if v.scene == "layers" { 0.8 } else { 1.0 } / q as f32;
    let mut text = set(&text, "grid", || {
        format!("{{ quads = {grid}, size = {size} }}")
    });
    text = set(&text, "thickness", || (v.thickness * spacing).to_string());
    let mut frictions = v.frictions.iter().cycle();
    text = set(&text, "friction", || frictions.next().unwrap().to_string());
    text = set(&text, "density", || v.density.to_string());
    text = set(&text, "substeps", || v.substeps.to_string());
    text = set(&text, "rate", || v.air_damping.to_string());
    if v.scene == "crumple" {
        // The cloth's centre comes first, then the sphere's, which rests on the ground.
        let (height, radius) = (v.drop.0 + 2.0 * v.drop.1 + 0.1, v.drop.1);
        let mut centres = [
            format!("[0.05, {height}, 0.08]"),
            format!("[0.0, {radius}, 0.0]"),
        ]
        .into_iter();
        text = set(&text, "center", || centres.next().unwrap_or_default());
        text = set(&text, "radius", || v.drop.1.to_string());
    }
    text
}

/// Runs `v` for a second (on the GPU's software adapter where `on_gpu`), checking every
/// frame. A frame the guard gave up on leaves the last good state, which is checked too,
/// and ends the run.
fn holds(v: &Variation, on_gpu: bool) -> Result<(), TestCaseError> {
    let mut scene = parsed(&scene_text(v));
    scene.params.step.integrator = v.integrator;
    let mut sim = match on_gpu {
        true => {
            common::gpu_simulation(scene, true)
                .expect("the software adapter")
                .0
        }
        false => Simulation::new(scene),
    };
    prop_assert_eq!(sim.intersections().total(), 0, "starts free");
    let frames = (1.0 / sim.params().step.dt as f64).round() as usize;
    for frame in 1..=frames {
        let gave_up = sim.step_frame().is_err();
        let found = sim.intersections();
        let forced = sim.forced_pairs().unwrap_or(0);
        prop_assert!(
            found.total() == 0 || forced > 0,
            "frame {frame}: {found:?} with no pair forced"
        );
        prop_assert!(sim.state().is_finite(), "frame {frame}");
        if gave_up {
            break;
        }
    }
    Ok(())
}

/// Runs `cases` draws of [`variation`] from the fixed seed.
fn run(cases: u32, integrators: &[IntegratorKind], most: u32, on_gpu: bool) {
    let config = Config {
        cases,
        failure_persistence: None,
        // A failing case is reported as drawn: each try is a simulation.
        max_shrink_iters: 0,
        ..Config::default()
    };
    let rng = TestRng::deterministic_rng(RngAlgorithm::ChaCha);
    let mut runner = TestRunner::new_with_rng(config, rng);
    if let Err(e) = runner.run(&variation(integrators, most), |v| holds(&v, on_gpu)) {
        panic!("{e}");
    }
}

#[test]
fn stress_scenes_with_settings_drawn_at_random_never_pass_through() {
    run(24, &IntegratorKind::ALL, 14, false);
}

/// The GPU's own contact code (`shaders/self_contact.wgsl` and its pushes), under the
/// integrators it runs that need few substeps, on grids of up to 8 quads (on the software
/// adapter five stacked 11-quad cloths took 40 s a case).
#[test]
fn stress_scenes_with_settings_drawn_at_random_never_pass_through_on_the_gpu() {
    let few = [
        IntegratorKind::ImplicitEuler,
        IntegratorKind::Xpbd,
        IntegratorKind::Vbd,
    ];
    run(16, &few, 8, true);
}
