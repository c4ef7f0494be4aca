//! The simulation in `f64`: the same code as in `f32`, agreeing with it to `f32`'s rounding
//! on a smooth run, free of the floor that rounding puts under `f32`'s errors, and a state
//! of its own that follows every outside change.

use std::path::Path;

use clothsim::scene::{Scene, SceneFile, Simulation};
use clothsim::sim::{IntegratorKind, Precision};
use glam::DVec3;

/// `orders` (7 × 7, soft, smooth over its first second) run for `seconds` with `integrator`
/// at `substeps` a frame in `precision`: the positions, to every digit computed.
fn run(
    integrator: IntegratorKind,
    substeps: u32,
    precision: Precision,
    seconds: f64,
) -> Vec<DVec3> {
    let mut scene = Scene::builtin("orders").expect("scene");
    scene.params.step.integrator = integrator;
    scene.params.step.substeps = substeps;
    scene.params.solver.precision = precision;
    let mut sim = Simulation::new(scene);
    let frames = (seconds * 60.0).round() as usize;
    for _ in 0..frames {
        sim.step_frame().expect("a healthy frame");
    }
    sim.positions_f64()
}

fn largest_gap(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max)
}

/// Every integrator gives in `f64` what it gives in `f32`, to `f32`'s rounding: over a
/// quarter second (15 frames) the two stay within 5·10⁻⁶ m of each other (measured: 1.4 to
/// 7.6·10⁻⁷ m, a few `f32` roundings of the cloth's coordinates), yet are not the same
/// numbers. The springs' dashpots left out of the `f64` path put them 2.2·10⁻⁵ m apart.
#[test]
fn f64_and_f32_agree_to_f32_rounding_with_every_integrator() {
    for integrator in IntegratorKind::ALL {
        // Explicit Euler needs small steps on this cloth; the others are stable at 8.
        let substeps = if integrator == IntegratorKind::ExplicitEuler {
            64
        } else {
            8
        };
        let single = run(integrator, substeps, Precision::F32, 0.25);
        let double = run(integrator, substeps, Precision::F64, 0.25);
        let gap = largest_gap(&single, &double);
        assert!(gap < 5e-6, "{integrator}: f32 and f64 {gap:.2e} m apart");
        assert!(gap > 0.0, "{integrator}: f64 gave f32's numbers");
    }
}

/// What `f64` is for: RK4's error falls by its order as the step halves where `f32`'s
/// rounding has put a floor under it. Against 512 substeps a frame, 64 and 128 substeps
/// over one second: in `f64` the error falls sixteen-fold (2⁴; measured 16.07); in `f32` it
/// does not fall at all (0.98: its rounding is larger than the truncation left).
#[test]
fn in_f64_rk4_shows_its_fourth_order_where_f32_rounding_hides_it() {
    let ratio = |precision| {
        let fine = run(IntegratorKind::Rk4, 512, precision, 1.0);
        let coarse = largest_gap(&run(IntegratorKind::Rk4, 64, precision, 1.0), &fine);
        let finer = largest_gap(&run(IntegratorKind::Rk4, 128, precision, 1.0), &fine);
        coarse / finer
    };
    let (double, single) = (ratio(Precision::F64), ratio(Precision::F32));
    assert!(
        (12.0..20.0).contains(&double),
        "f64: the error fell {double:.1}-fold"
    );
    assert!(single < 4.0, "f32: the error fell {single:.1}-fold");
}

/// The `f64` stepper keeps a state of its own; an outside change to the simulation's state
/// (a drag) is taken at the next frame, not stepped over. Moved up by 1 m, the cloth goes on
/// from there: its positions after the next frame are within one frame's travel of the
/// moved ones, as in `f32`.
#[test]
fn an_outside_change_reaches_the_f64_state() {
    let mut both = [Precision::F32, Precision::F64].map(|precision| {
        let mut scene = Scene::builtin("orders").expect("scene");
        scene.params.solver.precision = precision;
        let mut sim = Simulation::new(scene);
        sim.step_frame().expect("frame");
        sim.modify_state(|s| s.pos.iter_mut().for_each(|p| p.y += 1.0));
        sim.step_frame().expect("frame");
        sim.positions_f64()
    });
    let [single, double] = &mut both;
    let gap = largest_gap(single, double);
    assert!(gap < 1e-6, "f32 and f64 {gap:.2e} m apart after the move");
    assert!(double.iter().all(|p| p.y > 1.0), "the move was kept");
}

/// A scene file asks for `f64` in `[solver]`; a precision there that is neither is refused
/// naming its line and column and the choices. A saved setup keeps it.
#[test]
fn a_scene_file_chooses_the_precision() {
    let text = "name = \"p\"\n\n[cloth]\ngrid = { quads = 4, size = 1.0 }\n\n[solver]\nprecision = \"f64\"\n";
    let file = SceneFile::parse(text, Path::new("p.toml")).expect("valid");
    let scene = Scene::from_file(file, None).expect("scene");
    assert_eq!(scene.params.solver.precision, Precision::F64);
    let saved = scene.file.with_setup(&scene.params, &scene.effects, None);
    assert!(saved.to_toml().contains("precision = \"f64\""));
    let bad = text.replace("f64", "f16");
    let err = SceneFile::parse(&bad, Path::new("p.toml")).expect_err("f16 is no precision");
    let err = err.to_string();
    assert!(err.contains("p.toml:7:"), "{err}");
    assert!(err.contains("f32") && err.contains("f64"), "{err}");
}
