//! The `clothsim` binary's headless contract: JSON keys, exit codes, one-line errors.

use std::process::{Command, Output};

fn clothsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_clothsim"))
        .args(args)
        .env("RUST_LOG", "off")
        .output()
        .expect("the clothsim binary runs")
}

fn json(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object on stdout")
}

#[test]
fn info_json_counts_a_quad_grid() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("grid.obj");
    let grid = clothsim(&[
        "grid",
        "--quads",
        "10",
        "--size",
        "1",
        "--out",
        path.to_str().unwrap(),
    ]);
    assert!(grid.status.success());
    let v = json(&clothsim(&["info", path.to_str().unwrap(), "--json"]));
    assert_eq!(v["particles"], 121);
    assert_eq!(v["triangles"], 200);
    assert_eq!(v["edges"], 320);
    assert_eq!(v["structural"], 220);
    assert_eq!(v["shear"], 200);
    assert_eq!(v["bend"], 180);
    assert_eq!(v["springs"], 600);
    // The same grid written as triangles has no quads: one diagonal per cell is an edge
    // and the other only a bend pair.
    let tris = dir.path().join("tris.obj");
    let out = clothsim(&[
        "grid",
        "--quads",
        "10",
        "--triangles",
        "--out",
        tris.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let v = json(&clothsim(&["info", tris.to_str().unwrap(), "--json"]));
    assert_eq!(
        (v["edges"].clone(), v["shear"].clone()),
        (320.into(), 0.into())
    );
    assert_eq!(
        v["structural"], 320,
        "every triangle side is a polygon side"
    );
    assert_eq!(v["bend"], 280);
}

#[test]
fn a_bad_file_is_one_line_on_stderr_naming_file_and_problem() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.obj");
    std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap();
    for file in [path.to_str().unwrap(), "/definitely/missing.obj"] {
        let out = clothsim(&["info", file]);
        assert!(!out.status.success(), "{file}: must fail");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.trim_end().lines().count(), 1, "one line: {stderr}");
        assert!(stderr.contains(file), "names the file: {stderr}");
        assert!(out.stdout.is_empty());
    }
}

#[test]
fn a_self_collision_thicker_than_the_cloth_is_one_line_naming_file_line_and_lengths() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("thick.toml");
    std::fs::write(
        &path,
        "name = \"thick\"\n[cloth]\ngrid = { quads = 20, size = 1.0 }\n\
         [[effects]]\ntype = \"self-collision\"\nthickness = 0.2\n",
    )
    .unwrap();
    let file = path.to_str().unwrap();
    for args in [&["simulate", "--scene", file][..], &["scenes", file]] {
        let out = clothsim(args);
        assert!(!out.status.success(), "{args:?}: must fail");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.trim_end().lines().count(), 1, "one line: {stderr}");
        assert!(
            stderr.contains("thick.toml:6:1")
                && stderr.contains("0.2 m")
                && stderr.contains("0.05 m"),
            "{stderr}"
        );
    }
}

#[test]
fn simulate_json_has_the_documented_keys() {
    let v = json(&clothsim(&[
        "simulate",
        "--scene",
        "sphere-drop",
        "--seconds",
        "0.5",
        "--json",
    ]));
    for key in [
        "particles",
        "springs",
        "simulated_seconds",
        "substeps",
        "finite",
        "max_speed",
        "min_collider_distance",
        "kinetic_energy",
        "wall_seconds",
    ] {
        assert!(v.get(key).is_some(), "missing `{key}` in {v}");
    }
    assert_eq!(v["finite"], true);
    assert!((v["simulated_seconds"].as_f64().unwrap() - 0.5).abs() < 1e-6);
    assert!(
        v["min_collider_distance"].as_f64().unwrap() > 0.0,
        "nothing inside a collider"
    );
    // Without colliders the distance is null.
    let hanging = json(&clothsim(&[
        "simulate",
        "--scene",
        "hanging",
        "--seconds",
        "0.1",
        "--json",
    ]));
    assert!(hanging["min_collider_distance"].is_null());
}

#[test]
fn bad_arguments_fail_with_a_reason() {
    for (args, expect) in [
        (
            &["simulate", "--scene", "nope"][..],
            "unknown scenario `nope`",
        ),
        (&["simulate", "--dt", "-1"][..], "`dt`"),
        (
            &["simulate", "--integrator", "magic"][..],
            "unknown integrator",
        ),
        (
            &["simulate", "--integrator", "vbd", "--iterations", "0"][..],
            "--iterations must be in 1..=10000, got 0",
        ),
        (
            &["render", "--out", "/no/such/dir/x.png", "--seconds", "0"][..],
            "does not exist",
        ),
    ] {
        let out = clothsim(args);
        assert!(!out.status.success(), "{args:?} must fail");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(expect), "{args:?}: {stderr}");
    }
}

#[test]
fn scenes_lists_the_registry() {
    let out = clothsim(&["scenes"]);
    let text = String::from_utf8_lossy(&out.stdout);
    for name in ["hanging", "sphere-drop", "rotating-sphere"] {
        assert!(
            text.lines().any(|l| l.starts_with(name)),
            "{name} missing: {text}"
        );
    }
}

#[test]
fn render_writes_an_image_or_a_numbered_sequence() {
    let dir = tempfile::tempdir().unwrap();
    let single = dir.path().join("one.png");
    let out = clothsim(&[
        "render",
        "--scene",
        "sphere-drop",
        "--seconds",
        "0.1",
        "--size",
        "192x128",
        "--out",
        single.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        image::open(&single).unwrap().to_rgba8().dimensions(),
        (192, 128)
    );

    // 0.1 s at 60 frames per second is 6 frames; every 3rd, counting frame 0, makes 3 images.
    let frames = dir.path().join("frames");
    std::fs::create_dir(&frames).unwrap();
    let args = [
        "render",
        "--scene",
        "hanging",
        "--seconds",
        "0.1",
        "--size",
        "128x64",
        "--every",
        "3",
        "--out-dir",
    ];
    let out = clothsim(&[&args[..], &[frames.to_str().unwrap()]].concat());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut names: Vec<String> = std::fs::read_dir(&frames)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        ["frame_00000.png", "frame_00001.png", "frame_00002.png"]
    );
    // The cloth moved between the first and the last frame.
    let first = image::open(frames.join("frame_00000.png"))
        .unwrap()
        .to_rgba8();
    let last = image::open(frames.join("frame_00002.png"))
        .unwrap()
        .to_rgba8();
    assert_ne!(first, last);
}

#[test]
fn accuracy_writes_its_three_files_and_names_its_choice() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("report");
    let out = clothsim(&[
        "accuracy",
        "--integrators",
        "semi-implicit-euler,implicit-euler",
        "--dts",
        "0.002,0.001",
        "--seconds",
        "0.05",
        "--tolerance",
        "0.05",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("for a tolerance of 0.05"), "{stdout}");
    for name in ["accuracy.csv", "accuracy.md", "accuracy.png"] {
        assert!(out_dir.join(name).is_file(), "{name} missing");
    }
    let csv = std::fs::read_to_string(out_dir.join("accuracy.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 2 * 2, "{csv}");
}

#[test]
fn accuracy_refuses_bad_settings_before_working() {
    for (args, expect) in [
        (
            &["accuracy", "--dts", "-0.001", "--out", "/tmp/x"][..],
            "step size",
        ),
        (
            &["accuracy", "--seconds", "0", "--out", "/tmp/x"][..],
            "--seconds",
        ),
        (
            &["accuracy", "--integrators", "magic", "--out", "/tmp/x"][..],
            "unknown integrator",
        ),
        (
            &["accuracy", "--out", "/proc/forbidden/report"][..],
            "cannot create",
        ),
    ] {
        let out = clothsim(args);
        assert!(!out.status.success(), "{args:?} must fail");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(expect), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "one line: {stderr}");
    }
}

/// Runs the binary, giving it at most ten seconds (a hang is a failure, not a wait).
fn clothsim_bounded(args: &[&str]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_clothsim"))
        .args(args)
        .env("RUST_LOG", "off")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    for _ in 0..100 {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    child.kill().unwrap();
    panic!("clothsim {args:?} did not return");
}

/// Story: `clothsim info /dev/zero` never returned. Every bad input now ends promptly with
/// one line naming it and a non-zero exit.
#[test]
fn every_bad_input_is_one_line_and_a_non_zero_exit() {
    let dir = tempfile::tempdir().unwrap();
    let big = dir.path().join("big.obj");
    std::fs::write(&big, "v 0 0 0\nv 1e30 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    for (args, expect) in [
        (vec!["info", "/dev/zero"], "/dev/zero: is a device"),
        (vec!["info", big.to_str().unwrap()], "too large"),
        (vec!["simulate", "--obj", "/dev/zero"], "is a device"),
        (
            vec!["info", "x.obj", "--weld-tolerance", "nan"],
            "--weld-tolerance",
        ),
        (vec!["simulate", "--seconds", "inf"], "--seconds"),
        (vec!["simulate", "--substeps", "0"], "substeps"),
        (
            vec!["render", "--size", "0x10", "--out", "/tmp/x.png"],
            "--size",
        ),
        (
            vec!["grid", "--quads", "0", "--out", "/tmp/x.obj"],
            "--quads",
        ),
        (vec!["simulate", "--bogus"], "unexpected argument"),
    ] {
        let out = clothsim_bounded(&args);
        assert!(!out.status.success(), "{args:?} must fail");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
        assert!(stderr.contains(expect), "{args:?}: {stderr}");
    }
}

#[test]
fn simulate_json_records_what_the_guard_did() {
    let v = json(&clothsim(&[
        "simulate",
        "--scene",
        "hanging",
        "--substeps",
        "12",
        "--seconds",
        "0.5",
        "--json",
    ]));
    let events = v["guard_events"].as_array().expect("guard_events");
    let first = events.first().expect("the guard acted at 12 substeps");
    for key in [
        "time",
        "reason",
        "action",
        "substeps_before",
        "substeps_after",
    ] {
        assert!(first.get(key).is_some(), "missing `{key}` in {first}");
    }
    assert_eq!(first["action"], "refined");
    assert_eq!(first["substeps_before"], 12);
    assert_eq!(v["requested_substeps"], 12);
    assert!(v["substeps"].as_u64().unwrap() > 12);
    // A clean run records nothing.
    let calm = json(&clothsim(&["simulate", "--seconds", "0.2", "--json"]));
    assert_eq!(calm["guard_events"].as_array().unwrap().len(), 0);
}

#[test]
fn simulate_json_lists_only_the_phases_that_ran() {
    let phases = |scene: &str| {
        let v = json(&clothsim(&[
            "simulate",
            "--scene",
            scene,
            "--seconds",
            "0.05",
            "--json",
        ]));
        let phases = v["phases"]
            .as_object()
            .expect("phases is an object")
            .clone();
        for (name, p) in &phases {
            assert!(p["calls"].as_u64().unwrap() > 0, "{name}: {p}");
            assert!(p["seconds"].as_f64().unwrap() >= 0.0, "{name}: {p}");
        }
        phases.keys().cloned().collect::<Vec<String>>()
    };
    let hanging = phases("hanging");
    for absent in ["sphere", "plane", "self-collision", "wind"] {
        assert!(
            !hanging.contains(&absent.to_string()),
            "{absent}: {hanging:?}"
        );
    }
    assert!(hanging.contains(&"bending".to_string()), "{hanging:?}");
    let drop = phases("sphere-drop");
    assert!(drop.contains(&"sphere".to_string()) && drop.contains(&"plane".to_string()));
    assert!(phases("flag").contains(&"wind".to_string()));
    assert!(phases("self-fold").contains(&"self-collision".to_string()));
}

#[test]
fn scene_files_run_from_the_cli_and_bad_ones_name_file_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy("assets/cloth.obj", dir.path().join("c.obj")).unwrap();
    let path = dir.path().join("mine.toml");
    std::fs::write(
        &path,
        "name = \"mine\"\n[cloth]\nobj = \"c.obj\"\ncenter = [0.0, 1.0, 0.0]\n\
         [pins]\ncorners = [\"top-left\"]\n\
         [[effects]]\ntype = \"gravity\"\n[[effects]]\ntype = \"wind\"\n",
    )
    .unwrap();
    let file = path.to_str().unwrap();
    // `scenes FILE` checks it and says what it holds, run from another directory.
    let out = clothsim(&["scenes", file]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("mine") && text.contains("wind"), "{text}");
    let v = json(&clothsim(&[
        "simulate",
        "--scene",
        file,
        "--seconds",
        "0.05",
        "--json",
    ]));
    assert_eq!(v["scene"], "mine");
    assert_eq!(v["particles"], 625);
    assert!(v["phases"].get("wind").is_some(), "{v}");

    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "name = \"b\"\n[cloth]\nobj = \"c.obj\"\nspin = 3\n").unwrap();
    for args in [
        vec!["scenes", bad.to_str().unwrap()],
        vec!["simulate", "--scene", bad.to_str().unwrap()],
    ] {
        let out = clothsim(&args);
        assert!(!out.status.success());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        assert!(
            stderr.contains("bad.toml:4:1:") && stderr.contains("`spin`"),
            "{stderr}"
        );
    }
}

#[test]
fn simulate_exports_the_final_cloth_as_obj() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("final.obj");
    let v = json(&clothsim(&[
        "simulate",
        "--scene",
        "sphere-drop",
        "--seconds",
        "1.5",
        "--json",
        "--export-obj",
        path.to_str().unwrap(),
    ]));
    let info = json(&clothsim(&["info", path.to_str().unwrap(), "--json"]));
    assert_eq!(info["particles"], v["particles"]);
    assert_eq!(info["triangles"], 1152);
    // Not the rest shape: the cloth fell.
    let text = std::fs::read_to_string(&path).unwrap();
    let heights: Vec<f32> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| l.split_whitespace().nth(1).unwrap().parse().unwrap())
        .collect();
    let spread = heights.iter().fold(f32::MIN, |a, &b| a.max(b))
        - heights.iter().fold(f32::MAX, |a, &b| a.min(b));
    assert!(
        spread > 0.01,
        "the exported cloth is draped, not flat: {spread}"
    );
    // An unwritable path fails before the run, in one line.
    let out = clothsim(&[
        "simulate",
        "--seconds",
        "0.1",
        "--export-obj",
        "/no/such/dir/x.obj",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("/no/such/dir"));
}

#[test]
fn render_gif_writes_an_animation() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.gif");
    let out = clothsim(&[
        "render",
        "--scene",
        "flag",
        "--seconds",
        "0.25",
        "--size",
        "96x64",
        "--every",
        "5",
        "--gif",
        path.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options
        .read_info(std::fs::File::open(&path).unwrap())
        .unwrap();
    assert_eq!((decoder.width(), decoder.height()), (96, 64));
    let mut frames = Vec::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        // Five simulation frames at 60 per second each: 1/12 s, 8 hundredths rounded.
        assert_eq!(frame.delay, 8);
        frames.push(frame.buffer.to_vec());
    }
    // 15 frames, every 5th counting frame 0: 0, 5, 10, 15.
    assert_eq!(frames.len(), 4);
    assert_ne!(frames[0], frames[3], "the flag moved");
    let out = clothsim(&["render", "--seconds", "0", "--gif", "/no/such/dir/x.gif"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("/no/such/dir"));
}

/// `simulate --every K --out-dir DIR` writes the cloth and each obstacle every K frames,
/// numbered as `render --every` numbers its PNGs; the drum of `carousel`, turning at
/// 1 rad/s, is written turned by 0.1 rad at the third of them (frame 6, t = 0.1 s); the cloth
/// reads back with all its particles.
#[test]
fn simulate_writes_the_cloth_and_its_obstacles_every_k_frames() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let out = clothsim(&[
        "simulate",
        "--scene",
        "carousel",
        "--seconds",
        "0.1",
        "--every",
        "3",
        "--out-dir",
        d,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "cloth_00000.obj",
            "cloth_00001.obj",
            "cloth_00002.obj",
            "obstacle-1_00000.obj",
            "obstacle-1_00001.obj",
            "obstacle-1_00002.obj"
        ]
    );
    let vertices = |name: &str| -> Vec<glam::Vec3> {
        let soup = clothsim::mesh::read_obj(&dir.path().join(name)).unwrap();
        soup.positions
    };
    let (start, turned) = (
        vertices("obstacle-1_00000.obj"),
        vertices("obstacle-1_00002.obj"),
    );
    let rotation = glam::Quat::from_rotation_y(0.1);
    let worst = (start.iter().zip(&turned))
        .map(|(a, b)| (rotation * *a).distance(*b))
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-4, "the drum is off its turn by {worst} m");
    let cloth = clothsim::mesh::load_obj(&dir.path().join("cloth_00002.obj")).unwrap();
    assert_eq!(cloth.mesh.positions.len(), 31 * 31);
    // Without --out-dir, --every is refused.
    let out = clothsim(&["simulate", "--scene", "carousel", "--every", "3"]);
    assert!(!out.status.success());
}

#[test]
fn simulate_counts_intersections_and_resizes_a_grid() {
    let simulate = |line: &str| clothsim(&line.split_whitespace().collect::<Vec<_>>());
    let v = json(&simulate(
        "simulate --scene crumple --quads 8 --seconds 0.5 --check-intersections --json",
    ));
    assert_eq!(v["particles"], 81);
    assert_eq!(v["intersections"]["self"], 0);
    // The sphere and the ground, in the scene's order.
    assert_eq!(v["intersections"]["obstacles"], serde_json::json!([0, 0]));
    // Nothing prescribed forced a pair; a scene without self-collision has no count.
    assert_eq!(v["forced_pairs"], 0);
    let v = json(&simulate("simulate --scene hanging --seconds 0.1 --json"));
    assert!(v.get("forced_pairs").is_none());
    // Without the switch there is no count.
    let v = json(&simulate(
        "simulate --scene crumple --quads 8 --seconds 0.1 --json",
    ));
    assert!(v.get("intersections").is_none());
    // An OBJ cloth cannot be resized.
    let out = simulate("simulate --obj assets/cloth.obj --quads 8 --seconds 0.1");
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--quads"));
}

/// A cloth that already crosses itself at the start is warned about on stderr, with the
/// count of triangle pairs that meet, beside the import's own warnings; one that starts
/// free is not.
#[test]
fn simulate_warns_of_a_cloth_that_starts_through_itself() {
    let dir = tempfile::tempdir().unwrap();
    // A strip lying flat and a small square standing up through it, clear of the strip's
    // diagonal (their two pieces warned about by the import).
    let crossed = "v -0.5 0 -0.1\nv 0.5 0 -0.1\nv 0.5 0 0.1\nv -0.5 0 0.1\n\
                   v 0.05 -0.3 0.05\nv 0.05 0.3 0.05\nv 0.15 0.3 0.05\nv 0.15 -0.3 0.05\n\
                   f 1 2 3 4\nf 5 6 7 8\n";
    let path = dir.path().join("crossed.obj");
    std::fs::write(&path, crossed).unwrap();
    let run = |scene: &str, obj: &str| {
        let args = [
            "simulate",
            "--scene",
            scene,
            "--obj",
            obj,
            "--seconds",
            "0.05",
        ];
        let out = clothsim(&args);
        assert!(out.status.success(), "{out:?}");
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let warned = run("self-fold", path.to_str().unwrap());
    assert!(warned.contains("2 disconnected pieces"), "{warned}");
    // Each of the square's two triangles crosses the one of the strip's it stands in.
    let start = "crossed.obj: the cloth intersects itself at the start (2 triangle pairs meet)";
    assert!(warned.contains(start), "{warned}");
    let free = run("self-fold", "assets/cloth.obj");
    assert!(!free.contains("at the start"), "{free}");
    // `--json` carries them too; a cloth with nothing to warn of has no `warnings`.
    let obj = path.to_str().unwrap();
    let args = ["simulate", "--scene", "self-fold", "--obj", obj, "--json"];
    let v = json(&clothsim(&[&args[..], &["--seconds", "0.05"]].concat()));
    let warnings = v["warnings"].as_array().expect("a list of warnings");
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    assert!(
        warnings[1]
            .as_str()
            .unwrap()
            .contains("(2 triangle pairs meet)")
    );
    let v = json(&clothsim(&["simulate", "--seconds", "0.05", "--json"]));
    assert!(v.get("warnings").is_none(), "{v}");
}

/// `--iterations` sets XPBD's and VBD's sweeps per substep: VBD reports three a step.
#[test]
fn iterations_set_the_sweeps_per_substep() {
    let out = clothsim(&[
        "simulate",
        "--integrator",
        "vbd",
        "--iterations",
        "3",
        "--seconds",
        "0.05",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(json(&out)["solver_iterations_per_step"], 3.0);
}

/// `--map` and `--small-steps` write their files beside the report and say how long they
/// took; `--calibrate` prints the unit costs beside the built-in ones, and needs no `--out`.
#[test]
fn accuracy_answers_the_map_and_small_steps_and_calibrates() {
    let dir = tempfile::tempdir().unwrap();
    let out = clothsim(&[
        "accuracy",
        "--integrators",
        "semi-implicit-euler,implicit-euler",
        "--map",
        "--small-steps",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("stability map: "), "{stdout}");
    assert!(stdout.contains("small steps: "), "{stdout}");
    assert!(stdout.contains("XPBD: "), "{stdout}");
    for name in [
        "stability-map.csv",
        "stability-map.md",
        "stability-map.png",
        "small-steps.csv",
        "small-steps.md",
    ] {
        assert!(dir.path().join(name).is_file(), "{name} missing");
    }
    let map = std::fs::read_to_string(dir.path().join("stability-map.csv")).unwrap();
    assert_eq!(map.lines().count(), 1 + 2 * 7, "{map}");
    let out = clothsim(&["accuracy", "--calibrate"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("a VBD sweep") && stdout.contains("built in"),
        "{stdout}"
    );
}

/// A precision that is neither f32 nor f64 is refused by every command that takes one,
/// naming the choices, before any work; the GPU's bench refuses f64 with the reason; and
/// `simulate --precision f64` reports a run that computed in it.
#[test]
fn a_bad_precision_is_refused_and_f64_runs() {
    for command in ["simulate", "render", "accuracy", "bench"] {
        let out = clothsim(&[command, "--precision", "f16"]);
        assert!(!out.status.success(), "{command}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains("unknown precision `f16`; choose one of: f32, f64"),
            "{command}: {stderr}"
        );
    }
    let out = clothsim(&[
        "bench",
        "--backend",
        "gpu",
        "--precision",
        "f64",
        "--sizes",
        "8",
    ]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("f32 only, not f64"), "{stderr}");
    let row = |precision| {
        let out = clothsim(&[
            "bench",
            "--sizes",
            "8",
            "--threads",
            "1",
            "--json",
            "--integrators",
            "rk4",
            "--precision",
            precision,
        ]);
        json(&out)
    };
    let (single, double) = (row("f32"), row("f64"));
    assert_eq!(double["precision"], "f64");
    assert_eq!(single["precision"], "f32");
    // The same sag to f32's rounding, but not the same numbers.
    let sag = |v: &serde_json::Value| v["sag_m"].as_f64().expect("a sag");
    let gap = (sag(&single) - sag(&double)).abs();
    assert!(gap > 0.0 && gap < 1e-5, "{gap}");
}
