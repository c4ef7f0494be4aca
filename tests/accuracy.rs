//! The accuracy-versus-cost report: its files are complete and its choice holds up.

use glam::Vec3;

use clothsim::mesh::{GridOrientation, GridSpec, MeshBuild};
use clothsim::report::{self, CSV_COLUMNS, SweepConfig};
use clothsim::scene::Scene;
use clothsim::sim::{IntegratorKind, Precision};

/// `hanging` with an 8 × 8-quad cloth: small enough for a sweep in a test.
fn small_hanging() -> Scene {
    let mesh = GridSpec::square(8, 1.0, GridOrientation::Horizontal, Vec3::ZERO)
        .build()
        .unwrap();
    Scene::with_cloth("hanging", &MeshBuild::from(mesh), "grid").unwrap()
}

/// Three steps (1/60 s over 12, 24, 48 substeps), every integrator, 0.2 s.
fn small_config() -> SweepConfig {
    SweepConfig {
        dts: [12.0, 24.0, 48.0]
            .iter()
            .map(|n| 1.0 / (60.0 * n))
            .collect(),
        seconds: 0.2,
        samples: 4,
        tolerance: 1e-3,
        bisection_steps: 2,
        ..SweepConfig::default()
    }
}

#[test]
fn the_report_has_every_row_a_decodable_plot_and_a_choice_that_holds() {
    let scene = small_hanging();
    let config = small_config();
    let mut calls = 0;
    let report = report::sweep(&scene, &config, &mut |p| {
        calls += 1;
        assert!(p.done <= p.total);
        true
    })
    .unwrap();
    // The reference, then every integrator at every step.
    assert!(calls > 7 * 3, "progress reported {calls} times");
    let dir = tempfile::tempdir().unwrap();
    let files = report::write_report(&report, dir.path()).unwrap();
    assert_eq!(files.len(), 3);

    // The CSV: the header, then one row per integrator × step, every column filled.
    let csv = std::fs::read_to_string(dir.path().join("accuracy.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), CSV_COLUMNS.join(","));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), IntegratorKind::ALL.len() * config.dts.len());
    for row in &rows {
        assert_eq!(row.len(), CSV_COLUMNS.len(), "{row:?}");
        assert!(row.iter().all(|cell| !cell.trim().is_empty()), "{row:?}");
    }
    for kind in IntegratorKind::ALL {
        let mine = rows.iter().filter(|r| r[0] == kind.name()).count();
        assert_eq!(mine, config.dts.len(), "{kind}");
    }

    // The plot decodes, at its size, and is not blank: every integrator's colour is in it
    // (its legend line at least), and together they cover far more than the legend. Where
    // each lands depends on measured cost, so one integrator's markers may hide another's:
    // the plot unit tests check each colour's area on points that cannot overlap.
    let png = image::open(dir.path().join("accuracy.png"))
        .unwrap()
        .to_rgb8();
    assert_eq!(png.dimensions(), report::PLOT_SIZE);
    let mut all = 0;
    for kind in IntegratorKind::ALL {
        let (r, g, b) = report::integrator_color(kind);
        let mine = png.pixels().filter(|p| p.0 == [r, g, b]).count();
        assert!(mine >= 50, "only {mine} pixels of {kind}'s colour");
        all += mine;
    }
    assert!(all > 1500, "only {all} pixels in the integrators' colours");

    // The Markdown names the choice.
    let md = std::fs::read_to_string(dir.path().join("accuracy.md")).unwrap();
    assert!(md.contains(&report::choice_sentence(&report)));

    // The choice holds up when measured again, from scratch.
    let chosen = report
        .recommended()
        .expect("a run within 0.1 % of the cloth's size")
        .clone();
    assert!(chosen.stable && chosen.max_error <= config.tolerance);
    let again = report::sweep(
        &scene,
        &SweepConfig {
            integrators: vec![chosen.integrator],
            dts: vec![chosen.dt],
            bisection_steps: 0,
            ..config.clone()
        },
        &mut |_| true,
    )
    .unwrap();
    let rerun = &again.points[0];
    assert!(rerun.stable);
    assert!(
        rerun.max_error <= config.tolerance,
        "rerun error {} above the tolerance {}",
        rerun.max_error,
        config.tolerance
    );
    // And nothing within the tolerance costs less work than the resolution of the cost model
    // below it.
    for p in report
        .points
        .iter()
        .filter(|p| p.stable && p.max_error <= config.tolerance)
    {
        assert!(p.work_per_sim_s * (1.0 + report::COST_RESOLUTION) >= chosen.work_per_sim_s);
    }
}

/// Story: a user runs the report twice and gets the same answer. The choice is made by
/// counted work (force evaluations, solver iterations, sweeps), which is the same bits
/// every time; only the wall time beside it differs.
#[test]
fn two_sweeps_in_a_row_count_the_same_work_and_make_the_same_choice() {
    let config = SweepConfig {
        bisection_steps: 0,
        ..small_config()
    };
    let sweep = || report::sweep(&small_hanging(), &config, &mut |_| true).unwrap();
    let (first, second) = (sweep(), sweep());
    assert!(first.recommendation.is_some());
    assert_eq!(first.recommendation, second.recommendation);
    assert_eq!(first.frontier, second.frontier);
    for (a, b) in first.points.iter().zip(&second.points) {
        let counted = |p: &report::Point| {
            (
                p.integrator,
                p.work_per_sim_s.to_bits(),
                p.max_error.to_bits(),
                p.linear_iterations_per_step.to_bits(),
                p.sweeps_per_step.to_bits(),
            )
        };
        assert_eq!(counted(a), counted(b));
    }
    // Implicit Euler counts its CG iterations, XPBD and VBD their sweeps.
    let of = |kind| first.points.iter().find(|p| p.integrator == kind).unwrap();
    assert!(of(IntegratorKind::ImplicitEuler).linear_iterations_per_step >= 1.0);
    assert_eq!(of(IntegratorKind::Xpbd).sweeps_per_step, 1.0);
    assert_eq!(of(IntegratorKind::Vbd).sweeps_per_step, 1.0);
    assert_eq!(of(IntegratorKind::Rk4).force_evals_per_step, 4.0);
}

#[test]
fn the_reference_is_far_more_accurate_than_the_runs_it_judges() {
    let report = report::sweep(&small_hanging(), &small_config(), &mut |_| true).unwrap();
    let worst_stable_error = report
        .points
        .iter()
        .filter(|p| p.stable)
        .map(|p| p.max_error)
        .fold(0.0, f64::max);
    assert!(report.reference.check_max < 0.01 * worst_stable_error);
    // Explicit Euler blows up at 12 substeps on this undamped cloth; implicit Euler does not.
    let at = |kind, n: f64| {
        report
            .points
            .iter()
            .find(|p| p.integrator == kind && (p.substeps_per_frame - n).abs() < 0.5)
            .unwrap()
            .stable
    };
    assert!(at(IntegratorKind::ImplicitEuler, 12.0));
    let limit = |kind| {
        report
            .limits
            .iter()
            .find(|l| l.integrator == kind)
            .unwrap()
            .dt
    };
    let implicit = limit(IntegratorKind::ImplicitEuler).unwrap();
    let symplectic = limit(IntegratorKind::SemiImplicitEuler).unwrap();
    assert!(
        implicit > symplectic,
        "implicit {implicit} vs symplectic Euler {symplectic}"
    );
}

#[test]
fn a_cancelled_sweep_stops_and_says_so() {
    let mut calls = 0;
    let err = report::sweep(&small_hanging(), &small_config(), &mut |_| {
        calls += 1;
        calls < 3
    })
    .unwrap_err();
    assert!(matches!(err, report::ReportError::Cancelled));
    assert_eq!(calls, 3);
}

#[test]
fn a_bad_sweep_is_refused_before_any_work() {
    for config in [
        SweepConfig {
            dts: vec![],
            ..SweepConfig::default()
        },
        SweepConfig {
            dts: vec![-1e-3],
            ..SweepConfig::default()
        },
        SweepConfig {
            seconds: f64::NAN,
            ..SweepConfig::default()
        },
        SweepConfig {
            tolerance: 0.0,
            ..SweepConfig::default()
        },
    ] {
        let err = report::sweep(&small_hanging(), &config, &mut |_| panic!("no work")).unwrap_err();
        assert!(matches!(err, report::ReportError::Config(_)), "{err}");
    }
}

/// Story: a user runs `clothsim accuracy` with no arguments to see what each integrator's
/// accuracy costs. On the built-in `orders` scene every method's error falls as its order
/// says, over at least 1.5 decades of resolved error: explicit, semi-implicit and implicit
/// Euler, XPBD and VBD first order, Verlet and RK2 second, RK4 fourth. Measured 2026-11-26
/// (in `ALL` order): 1.04, 1.01, 1.99, 2.13, 3.75, 0.95, 0.90, 0.92 over 1.8–2.4 decades.
/// The bands (±20 %, ±15 % for RK4's larger number) reject any other order.
#[test]
fn the_bare_report_shows_every_integrators_order_within_its_band() {
    let scene = Scene::builtin(report::ORDERS_SCENE).unwrap();
    let config = SweepConfig {
        bisection_steps: 0,
        ..SweepConfig::for_scene(report::ORDERS_SCENE)
    };
    let report = report::sweep(&scene, &config, &mut |_| true).unwrap();
    assert_eq!(report.reference.judged, report::Judged::Trajectory);
    // In f64 (the sweep's default, and the report says so) the reference is sure to 10⁻¹³
    // of the cloth's size (measured 1.8e-14; in f32, 1.5e-6).
    assert!(report::markdown(&report).contains("1 s simulated in f64."));
    assert!(report.reference.check_max < 1e-13, "{:?}", report.reference);
    // In f32 the reference is not RK4 at its finest candidate step: there rounding over the
    // many steps leaves the two finest candidates more than ten times further apart than
    // the pair the reference comes from (measured 2.2e-4 of the size against 1.5e-6).
    let single = SweepConfig {
        precision: Precision::F32,
        ..config.clone()
    };
    let (_, r) = report::reference(&single.in_precision(&scene), &single);
    let (finest_pair, finest_gap) = r.ladder[0];
    assert!(r.dt > finest_pair, "{r:?}");
    assert!(finest_gap > 10.0 * r.check_max, "{r:?}");
    for limit in &report.limits {
        let kind = limit.integrator;
        let fit = limit
            .observed_order
            .unwrap_or_else(|| panic!("{kind}: no order observed"));
        let expected = kind.order() as f64;
        let band = if kind.order() == 4 { 0.15 } else { 0.2 };
        assert!(
            (fit.order / expected - 1.0).abs() <= band,
            "{kind}: order {:.2}, expected {expected} ± {:.0} % ({fit:?})",
            fit.order,
            100.0 * band
        );
        assert!(
            fit.decades >= 1.5,
            "{kind}: over {:.2} decades",
            fit.decades
        );
    }
    // The fitted errors are resolved: at least ten times the reference's uncertainty.
    let resolved = report.points.iter().filter(|p| p.resolved());
    assert!(resolved.clone().count() >= 50);
    for p in resolved {
        assert!(p.max_error >= 10.0 * report.reference.check_max, "{p:?}");
    }
    // With no f32 floor under them, the high-order methods' orders span five decades of
    // error and more (measured: Verlet 5.4, RK2 5.2, RK4 9.4; in f32 about two).
    for limit in &report.limits {
        if limit.integrator.order() >= 2 {
            let fit = limit.observed_order.as_ref().expect("an order");
            assert!(fit.decades >= 5.0, "{}: {fit:?}", limit.integrator);
        }
    }
}

/// Story: a user about to simulate a stiffer fabric asks how small a step each method
/// needs. The map's limits follow each method's stability law: symplectic Euler is held by
/// `ωh < 2`, and `ω ∝ √k`, so its largest stable step falls as `k^(−½)`; explicit Euler
/// survives only where damping outweighs its energy gain, `h ≲ γ/ω²`, so as `k⁻¹`; implicit
/// Euler is stable at every step probed. Measured 2026-11-26 from 10 to 100 times the
/// `orders` scene's stiffness: slopes −0.48 and −1.09.
#[test]
fn the_stability_map_follows_each_methods_stability_law() {
    let scene = Scene::builtin(report::ORDERS_SCENE).unwrap();
    let config = SweepConfig {
        integrators: vec![
            IntegratorKind::ExplicitEuler,
            IntegratorKind::SemiImplicitEuler,
            IntegratorKind::ImplicitEuler,
        ],
        ..SweepConfig::for_scene(report::ORDERS_SCENE)
    };
    let map =
        report::stability_map(&scene, &config, &[10.0, 31.6, 100.0], &mut |_, _| true).unwrap();
    assert_eq!(map.points.len(), 9);
    let slope = |kind| {
        map.slope(kind)
            .unwrap_or_else(|| panic!("{kind}: no slope"))
    };
    let symplectic = slope(IntegratorKind::SemiImplicitEuler);
    assert!(
        (symplectic + 0.5).abs() < 0.1,
        "symplectic Euler: {symplectic:.2}"
    );
    let explicit = slope(IntegratorKind::ExplicitEuler);
    assert!(
        (explicit + 1.0).abs() < 0.2,
        "explicit Euler: {explicit:.2}"
    );
    for p in map
        .points
        .iter()
        .filter(|p| p.integrator == IntegratorKind::ImplicitEuler)
    {
        assert!(p.at_upper_bound, "{p:?}");
    }
    let md = map.markdown();
    assert!(md.contains("| 100 | 800.000 |"), "{md}");
}

/// Story: should XPBD or VBD spend a frame's sweeps on substeps or on iterations? Macklin et
/// al.'s answer (SCA 2019) holds here: n substeps of one sweep make the error fall at first
/// order, while one substep of n sweeps converges to that substep's implicit step and its
/// error stops falling, so the small steps win at every budget.
#[test]
fn small_steps_beat_iterations_at_every_budget_and_iterations_plateau() {
    let scene = Scene::builtin(report::ORDERS_SCENE).unwrap();
    let config = SweepConfig::for_scene(report::ORDERS_SCENE);
    let grid = report::small_steps(&scene, &config, &mut |_, _| true).unwrap();
    let duels = grid.duels();
    assert_eq!(duels.len(), 10);
    for d in &duels {
        assert!(d.small_steps_win(), "{d:?}");
    }
    for kind in [IntegratorKind::Xpbd, IntegratorKind::Vbd] {
        let mine: Vec<&report::Duel> = duels.iter().filter(|d| d.integrator == kind).collect();
        // n × 1: halving the step halves the error, near enough (first order), the ratio
        // rising towards 2 as the steps shrink (measured: XPBD 1.60 … 1.89, VBD 1.49 …
        // 1.88 from 2 to 32 substeps a frame).
        let ratios: Vec<f64> = (mine.windows(2))
            .map(|pair| pair[0].small_steps / pair[1].small_steps)
            .collect();
        for (pair, ratio) in mine.windows(2).zip(&ratios) {
            assert!((1.4..2.3).contains(ratio), "{kind}: {ratio:.2} ({pair:?})");
        }
        let finest = ratios[ratios.len() - 1];
        assert!((1.8..2.2).contains(&finest), "{kind}: {ratios:.2?}");
        // 1 × n: the sweeps do move the step (32 of them leave less error than one:
        // measured 0.26 against 0.40 of the cloth's size for XPBD, 0.26 against 0.29 for
        // VBD, whose first guess already follows the swing), then 16 and 32 give the same
        // step to within 1 %.
        let one_sweep = (grid.runs.iter())
            .find(|r| r.point.integrator == kind && r.substeps == 1 && r.iterations == 1)
            .map(|r| r.point.max_error)
            .unwrap();
        let (a, b) = (mine[3].many_iterations, mine[4].many_iterations);
        assert!(
            b < 0.95 * one_sweep,
            "{kind}: {one_sweep} with one sweep, {b} with 32"
        );
        assert!((a / b - 1.0).abs() < 0.01, "{kind}: {a} then {b}");
    }
    assert!(
        grid.verdict()
            .iter()
            .all(|v| v.contains("small steps win at every budget"))
    );
}

/// Story: on a scene with a collider the comparison says what each run let through. On
/// `sphere-drop` every stable run keeps every particle out of the sphere and the cloth
/// clear of it and of itself; a particle pushed 2 cm inside the sphere is measured 2 cm deep,
/// and the cloth triangles it drags in meet the sphere; a scene with nothing to pass through
/// has no contact measures.
#[test]
fn on_a_scene_with_a_collider_each_run_reports_what_it_let_through() {
    use clothsim::sim::Effect;
    let scene = Scene::builtin("sphere-drop").unwrap();
    let config = SweepConfig {
        integrators: vec![IntegratorKind::SemiImplicitEuler, IntegratorKind::Vbd],
        dts: vec![1.0 / (60.0 * 48.0), 1.0 / (60.0 * 6.0)],
        seconds: 0.5,
        samples: 10,
        bisection_steps: 0,
        ..SweepConfig::default()
    };
    let report = report::sweep(&scene, &config, &mut |_| true).unwrap();
    let stable: Vec<&report::Point> = report.points.iter().filter(|p| p.stable).collect();
    assert!(stable.len() >= 3, "{:?}", report.points);
    for p in stable {
        let contact = p.contact.expect("a sphere to measure against");
        assert_eq!(contact.deepest_penetration, 0.0, "{p:?}");
        assert_eq!(contact.intersections, 0, "{p:?}");
    }
    // The measure itself: one particle 2 cm inside the sphere.
    let Some(Effect::Sphere(sphere)) = scene.effects.iter().find(|e| e.is_solid()) else {
        panic!("sphere-drop has a sphere");
    };
    let mut pos = scene.initial.pos.clone();
    let nearest = (0..pos.len())
        .min_by(|&a, &b| {
            let d = |i: usize| pos[i].distance(sphere.center);
            d(a).total_cmp(&d(b))
        })
        .unwrap();
    let out = (pos[nearest] - sphere.center).normalize();
    pos[nearest] = sphere.center + out * (sphere.radius - 0.02);
    let inside =
        report::ContactMeasures::of(&scene.effects, &scene.model.triangles, &pos, 0.0).unwrap();
    assert!(
        (inside.deepest_penetration - 0.02).abs() < 1e-5,
        "{inside:?}"
    );
    assert!(inside.intersections > 0, "{inside:?}");
    let orders = Scene::builtin(report::ORDERS_SCENE).unwrap();
    let none = report::ContactMeasures::of(&orders.effects, &orders.model.triangles, &pos, 0.0);
    assert_eq!(none, None);
}

/// Story: a user sweeps a scene whose folds turn chaotic within the horizon (`hanging` over
/// 1.5 s, on a coarser cloth): the reference cannot agree with itself about where the
/// particles are, so position errors would measure nothing. The report says so, judges runs
/// by the shape in aggregate (centre of mass and spread against the reference's), and that
/// measure still converges: implicit Euler's shape error falls as its step shrinks.
#[test]
fn a_chaotic_scene_is_judged_by_its_shape_and_says_so() {
    let mesh = GridSpec::square(12, 1.0, GridOrientation::Horizontal, Vec3::ZERO)
        .build()
        .unwrap();
    let scene = Scene::with_cloth("hanging", &MeshBuild::from(mesh), "grid").unwrap();
    let config = SweepConfig {
        integrators: vec![IntegratorKind::ImplicitEuler],
        dts: [6.0, 12.0, 24.0, 48.0]
            .iter()
            .map(|n| 1.0 / (60.0 * n))
            .collect(),
        seconds: 1.5,
        samples: 15,
        bisection_steps: 0,
        // In f32, whose rounding this buckling cloth's folds amplify past the tolerance over
        // 1.5 s (in f64 its reference is sure to 1.1e-4 of its size there, and trajectories
        // are judged).
        precision: Precision::F32,
        ..SweepConfig::default()
    };
    let report = report::sweep(&scene, &config, &mut |_| true).unwrap();
    let r = &report.reference;
    assert_eq!(r.judged, report::Judged::Shape, "{r:?}");
    assert!(10.0 * r.check_max > config.tolerance);
    assert!(
        r.check_shape < 0.1 * r.check_max,
        "the shape is surer: {r:?}"
    );
    let shape: Vec<f64> = report.points.iter().map(|p| p.shape_error).collect();
    for pair in shape.windows(2) {
        assert!(pair[1] < 0.8 * pair[0], "shape errors {shape:?}");
    }
    let md = report::markdown(&report);
    assert!(md.contains("Judged by shape"));
    // The choice is by the shape error, within the tolerance.
    if let Some(p) = report.recommended() {
        assert!(p.error_bound() <= config.tolerance && p.shape_error <= config.tolerance);
    }
}
