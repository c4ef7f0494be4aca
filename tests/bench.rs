//! The `hanging-bench` scene is the scene the peer frameworks run (`../shared/peers`): same
//! particles, springs, masses and pins, and the same sag after 2 s.

use std::process::Command;

use clothsim::bench::{
    BENCH_SECONDS, FrameSpread, REFERENCE_SAG, bench_in, bench_one, bench_scene, central,
    frame_spread,
};
use clothsim::mesh::SpringKind;
use clothsim::scene::Simulation;
use clothsim::sim::{IntegratorKind, Precision};

#[test]
fn bench_scene_has_the_peers_particles_springs_masses_and_pins() {
    let n = 32usize;
    let scene = bench_scene(n as u32, IntegratorKind::SemiImplicitEuler).expect("builds");
    let model = &scene.model;
    assert_eq!(model.particle_count(), n * n);
    // The 12-neighbour stencil: (1,0),(0,1) structural, (1,±1) shear, (2,0),(0,2) bend.
    let s = &model.springs;
    assert_eq!(s.count(SpringKind::Structural), 2 * n * (n - 1));
    assert_eq!(s.count(SpringKind::Shear), 2 * (n - 1) * (n - 1));
    assert_eq!(s.count(SpringKind::Bend), 2 * n * (n - 2));
    assert_eq!(s.len(), 5826);
    let h = 1.0 / (n - 1) as f32;
    for e in 0..s.len() {
        let (a, b) = (
            model.rest_positions[s.a[e] as usize],
            model.rest_positions[s.b[e] as usize],
        );
        let d = (b - a).abs();
        let want = match s.kind[e] {
            SpringKind::Structural => h,
            SpringKind::Shear => h * 2f32.sqrt(),
            // Bend springs skip one particle along a grid line.
            SpringKind::Bend => 2.0 * h,
        };
        assert!(
            (s.rest[e] - want).abs() < 1e-5,
            "spring {e} rest {}",
            s.rest[e]
        );
        if s.kind[e] == SpringKind::Bend {
            assert!(d.x < 1e-5 || d.y < 1e-5, "bend spring {e} is along an axis");
        }
    }
    // Total mass 1 kg shared equally; the top corners pinned, nothing else.
    for &m in &model.mass {
        assert!((m * (n * n) as f32 - 1.0).abs() < 1e-5, "mass {m}");
    }
    let top = model
        .rest_positions
        .iter()
        .map(|p| p.y)
        .fold(f32::MIN, f32::max);
    let pinned: Vec<_> = model
        .pins
        .iter()
        .map(|&p| model.rest_positions[p as usize])
        .collect();
    assert_eq!(pinned.len(), 2);
    for p in pinned {
        assert!(
            (p.y - top).abs() < 1e-6 && (p.x.abs() - 0.5).abs() < 1e-6,
            "{p}"
        );
    }
}

#[test]
fn bench_sag_matches_the_reference_at_n32() {
    let row = bench_one(32, IntegratorKind::SemiImplicitEuler).expect("runs");
    let reference = REFERENCE_SAG[0].1;
    assert!(row.finite);
    assert!(
        (row.sag_m - reference).abs() < 0.01 * reference,
        "sag {} vs {reference}",
        row.sag_m
    );
    assert_eq!(row.sag_ok, Some(true));
    assert_eq!(row.substeps_per_frame, 32);
    // The CPU finishes each frame before the clock stops: a median and a best frame.
    let (median, best) = (
        row.median_frame_us.expect("a median"),
        row.best_frame_us.expect("a best"),
    );
    assert!(
        0.0 < best && best <= median,
        "best {best} µs, median {median} µs"
    );
}

/// VBD's bench row (N/2 substeps of one sweep) sags within its 5 % at N = 32: measured
/// 2.3 % off. It is the descent's adaptive start (each particle's last acceleration along
/// the external one) that gets it there; started from the inertial guess it sagged 152 %
/// too far.
#[test]
fn bench_gives_vbd_a_sag_within_its_tolerance() {
    let row = bench_one(32, IntegratorKind::Vbd).expect("runs");
    assert_eq!(row.substeps_per_frame, 16);
    let error = row.sag_error.expect("a reference at N = 32");
    assert!(error < 0.05, "sag {:.1} % off", 100.0 * error);
    assert_eq!(row.sag_ok, Some(true));
}

/// The frame spread is the median and the least, whatever the order the frames came in.
#[test]
fn frame_spread_is_the_median_and_the_fastest_frame() {
    assert_eq!(
        frame_spread(&mut [9.0, 3.0, 5.0]),
        Some(FrameSpread {
            median: 5.0,
            best: 3.0
        })
    );
    // An even count: the mean of the two middle frames.
    assert_eq!(
        frame_spread(&mut [8.0, 2.0, 40.0, 4.0]),
        Some(FrameSpread {
            median: 6.0,
            best: 2.0
        })
    );
    assert_eq!(frame_spread(&mut []), None);
}

/// Story: with one Gauss–Seidel sweep per substep XPBD's cloth is too soft (sag 12 % over
/// the reference at N = 32), so its speed would not count; the bench gives it the sweeps
/// that bring the sag within tolerance, and says so.
#[test]
fn bench_gives_xpbd_the_sweeps_its_sag_needs() {
    let row = bench_one(32, IntegratorKind::Xpbd).expect("runs");
    assert_eq!(
        row.sag_ok,
        Some(true),
        "sag {} with the bench's sweeps",
        row.sag_m
    );
    let one_sweep =
        clothsim::bench::bench_for(32, IntegratorKind::Xpbd, BENCH_SECONDS, |mut scene| {
            scene.params.solver.xpbd_iterations = 1;
            Ok(clothsim::scene::Simulation::new(scene))
        })
        .expect("runs");
    assert_eq!(one_sweep.sag_ok, Some(false), "sag {}", one_sweep.sag_m);
    assert!(one_sweep.sag_m > row.sag_m, "one sweep is softer");
}

/// A row names the threads that step: the team's members, which the pool's size picks up
/// to the team's limit of 16, not the pool's size beyond it.
#[test]
fn bench_rows_name_the_teams_threads_not_a_larger_pools() {
    let threads_in = |pool: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(pool)
            .build()
            .expect("a pool");
        pool.install(|| bench_one(8, IntegratorKind::SemiImplicitEuler))
            .expect("runs")
            .threads
    };
    assert_eq!(threads_in(3), 3);
    assert_eq!(threads_in(17), 16);
}

/// Runs `clothsim` with `args`, which must succeed; its output.
fn output_of(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_clothsim"))
        .args(args)
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Runs `clothsim` with `args` (a `--json` bench), which must succeed, and reads one JSON
/// row per line of its output.
fn json_rows(args: &[&str]) -> Vec<serde_json::Value> {
    (output_of(args).lines())
        .map(|l| serde_json::from_str(l).expect("one JSON object per line"))
        .collect()
}

#[test]
fn bench_cli_prints_one_json_row_per_size_and_thread_count() {
    let rows = json_rows(&[
        "bench",
        "--sizes",
        "8,12",
        "--integrators",
        "semi-implicit-euler",
        "--threads",
        "1,2",
        "--json",
    ]);
    assert_eq!(rows.len(), 4);
    for row in &rows {
        for key in [
            "n",
            "integrator",
            "threads",
            "us_per_substep",
            "sag_m",
            "finite",
            "median_frame_us",
            "best_frame_us",
        ] {
            assert!(row.get(key).is_some(), "{key} missing in {row}");
        }
        assert_eq!(row["finite"], true);
        assert!(
            row["sag_m"].as_f64().expect("number") > 0.0,
            "the cloth sags"
        );
    }
    let threads: Vec<_> = rows.iter().map(|r| r["threads"].as_u64()).collect();
    assert_eq!(threads, [Some(1), Some(1), Some(2), Some(2)]);
    // The same cloth gives the same sag on 1 and 2 threads.
    assert_eq!(rows[0]["sag_m"], rows[2]["sag_m"]);
    // A bad size is one clear line, not a panic.
    let bad = Command::new(env!("CARGO_BIN_EXE_clothsim"))
        .args(["bench", "--sizes", "2"])
        .output()
        .expect("runs");
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("--sizes") && err.contains("3..=2048"), "{err}");
}

/// `bench --crumple`: a row per grid size × integrator, each substep counted (XPBD has no
/// spring-force phase to count them by, and no spring cost to compare with).
#[test]
fn crumple_bench_prints_a_row_per_size_and_integrator() {
    let rows = json_rows(&[
        "bench",
        "--crumple",
        "--quads",
        "6,8",
        "--integrators",
        "xpbd,implicit-euler",
        "--threads",
        "1",
        "--repeat",
        "2",
        "--json",
    ]);
    let shape: Vec<_> = (rows.iter())
        .map(|r| (r["quads"].as_u64(), r["integrator"].as_str()))
        .collect();
    assert_eq!(
        shape,
        [
            (Some(6), Some("xpbd")),
            (Some(6), Some("implicit-euler")),
            (Some(8), Some("xpbd")),
            (Some(8), Some("implicit-euler")),
        ]
    );
    for row in &rows {
        // 60 frames of the scene's 4 substeps.
        assert_eq!(row["substeps"], 240, "{row}");
        assert!(row["contact_us"].as_f64().unwrap() > 0.0, "{row}");
        // Self-contact is one of the contact phases (and the rows' medians keep the order
        // each run's times have).
        let own = row["self_contact_us"].as_f64().unwrap();
        assert!(
            own > 0.0 && own <= row["contact_us"].as_f64().unwrap(),
            "{row}"
        );
        let ratios = ["self_per_springs", "contact_per_springs"].map(|k| row[k].as_f64().unwrap());
        assert!(ratios[0] <= ratios[1], "{row}");
        assert_eq!(row["forced"], 0, "{row}");
        // Each row the medians of its two runs.
        assert_eq!(row["runs"], 2, "{row}");
    }
    assert_eq!(rows[0]["springs_us"], 0.0);
    assert_eq!(rows[0]["contact_per_springs"], 0.0);
    assert!(rows[1]["springs_us"].as_f64().unwrap() > 0.0);
    assert!(rows[1]["contact_per_springs"].as_f64().unwrap() > 0.0);
    assert!(rows.iter().all(|r| r.get("fell_back_to").is_none()));
}

/// At the targets' grid (64²), a row's text says what it reached beside them, met or
/// not; at another grid, nothing of them.
#[test]
fn a_crumple_row_at_64_quads_says_what_it_reached_beside_the_targets() {
    let text = |quads: &str| {
        output_of(&[
            "bench",
            "--crumple",
            "--quads",
            quads,
            "--threads",
            "2",
            "--repeat",
            "1",
        ])
    };
    let at_64 = text("64");
    let line = (at_64.lines())
        .find(|l| l.contains("beside the targets"))
        .unwrap_or_else(|| panic!("{at_64}"));
    assert!(
        line.contains("at 64²: contact") && line.contains("× the springs (at most 10×: "),
        "{line}"
    );
    assert!(
        line.contains("of wall a simulated second (at most 1 on 2 threads: "),
        "{line}"
    );
    assert!(!text("8").contains("beside the targets"));
}

/// A row is named by the integrator asked for, and says where the stability guard fell
/// back from it: semi-implicit Euler at 48², the scene's 4 substeps a frame, is refined in
/// vain in the first frame and the rest of the second is implicit Euler's.
#[test]
fn a_crumple_row_says_where_the_guard_fell_back() {
    let args =
        "bench --crumple --quads 48 --integrators semi-implicit-euler --threads 1 --repeat 1";
    let rows = json_rows(&[args.split(' ').collect::<Vec<_>>(), vec!["--json"]].concat());
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0]["integrator"], "semi-implicit-euler");
    assert_eq!(rows[0]["fell_back_to"], "implicit-euler", "{}", rows[0]);
}

#[test]
fn bench_cli_refuses_bad_thread_counts_and_gpu_integrators_in_one_line() {
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_clothsim"))
            .args(args)
            .output()
            .expect("runs");
        assert!(!out.status.success(), "{args:?} succeeded");
        // Refused before anything is printed: no table header left half-filled.
        assert!(out.stdout.is_empty(), "{args:?} printed before failing");
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        err
    };
    let err = run(&["bench", "--crumple", "--quads", "0"]);
    assert!(err.contains("--quads") && err.contains("1..=2048"), "{err}");
    let err = run(&["bench", "--crumple", "--quads", "8", "--repeat", "0"]);
    assert!(err.contains("--repeat") && err.contains("1..=100"), "{err}");
    let err = run(&["bench", "--sizes", "8", "--threads", "0"]);
    assert!(
        err.contains("--threads") && err.contains("1..=256"),
        "{err}"
    );
    let err = run(&[
        "bench",
        "--sizes",
        "8",
        "--backend",
        "gpu",
        "--integrators",
        "rk4",
    ]);
    assert!(
        err.contains("semi-implicit-euler, implicit-euler, xpbd, vbd only, not rk4"),
        "{err}"
    );
    let err = run(&["bench", "--sizes", "8", "--backend", "tpu"]);
    assert!(err.contains("--backend"), "{err}");
    for seconds in ["0.01", "NaN", "-1", "1e9"] {
        let err = run(&["bench", "--sizes", "8", "--seconds", seconds]);
        assert!(
            err.contains("--seconds") && err.contains("two frames (1/30 s) to an hour"),
            "{seconds}: {err}"
        );
    }
}

/// A run of `seconds` lasts that long: the sag it reports is the cloth's after that many
/// frames, stepped plainly; it is held against the reference only at the reference's 2 s.
#[test]
fn a_bench_run_lasts_the_seconds_asked_for() {
    let (n, kind) = (32, IntegratorKind::SemiImplicitEuler);
    let row = bench_in(n, kind, Precision::F32, 0.5).expect("runs");
    let mut sim = Simulation::new(bench_scene(n, kind).expect("builds"));
    let central = central(&sim);
    let height =
        |pos: &[glam::Vec3]| central.iter().map(|&p| f64::from(pos[p].y)).sum::<f64>() / 4.0;
    let start = height(&sim.state().pos);
    for _ in 0..30 {
        sim.step_frame().expect("a frame");
    }
    let sag = start - height(&sim.state().pos);
    assert_eq!(row.sag_m, sag, "the sag after 30 frames");
    assert_eq!((row.reference_sag_m, row.sag_ok), (None, None));
    let full = bench_one(n, kind).expect("runs");
    assert!(full.reference_sag_m.is_some() && full.sag_m != row.sag_m);
}

/// The table says why a row has no reference: at another time than the reference's 2 s
/// for a size that has one, and plainly for a size that has none.
#[test]
fn the_bench_table_says_why_a_row_has_no_reference() {
    let text = output_of(&[
        "bench",
        "--sizes",
        "8,32",
        "--integrators",
        "semi-implicit-euler",
        "--threads",
        "1",
        "--seconds",
        "0.5",
    ]);
    let row = |n: &str| {
        (text.lines())
            .find(|l| l.split_whitespace().next() == Some(n))
            .unwrap_or_else(|| panic!("no row for {n} in {text}"))
            .to_string()
    };
    assert!(
        row("32").ends_with("no reference at this time (2 s)"),
        "{text}"
    );
    assert!(row("8").ends_with("  no reference"), "{text}");
}
