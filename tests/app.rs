//! The desktop app driven through its UI with egui_kittest on the software wgpu adapter:
//! the same panels, viewport and capture path a user gets.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;

use clothsim::app::ClothApp;
use clothsim::mesh::{GridOrientation, GridSpec};

fn harness() -> Harness<'static, ClothApp> {
    let mut harness = Harness::builder()
        .with_size([1280.0, 800.0])
        .wgpu()
        .build_eframe(|cc| {
            let mut app = ClothApp::new(cc.wgpu_render_state.clone(), None);
            // Deterministic: nothing advances unless a test asks.
            app.transport.pause();
            app
        });
    harness.run_steps(2);
    harness
}

#[derive(Debug)]
struct Dropped(PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &Path {
        &self.0
    }

    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

/// Writes `text` as the file `name`, drops it on the window, waits for the background
/// import, and lets the UI catch up.
fn drop_obj(harness: &mut Harness<'static, ClothApp>, name: &str, text: &str) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    harness
        .input_mut()
        .dropped_files
        .push(Arc::new(Dropped(path)));
    harness.run_steps(1);
    // A drop starts a background import and says so. (A tiny file may already be done
    // within the same UI frame, so "still loading" is not guaranteed.)
    assert!(
        harness
            .state()
            .messages
            .iter()
            .any(|m| m.text.starts_with("loading") && m.text.contains(name)),
        "{:?}",
        harness.state().messages
    );
    harness.state_mut().finish_loading();
    harness.run_steps(2);
}

#[test]
fn switching_scenario_rebuilds_the_cloth() {
    let mut harness = harness();
    assert_eq!(harness.state().sim.scenario(), "hanging");
    assert!(harness.state().sim.colliders().is_empty());
    harness.get_by_label("sphere-drop").click();
    harness.run_steps(2);
    let sim = &harness.state().sim;
    assert_eq!(sim.scenario(), "sphere-drop");
    assert_eq!(sim.colliders().len(), 2, "sphere and ground");
    assert!(sim.model().pins.is_empty(), "sphere-drop pins nothing");
    assert_eq!(sim.frames(), 0, "a new scene starts from its initial state");
}

#[test]
fn dropping_a_valid_obj_changes_the_particle_count() {
    let mut harness = harness();
    harness.get_by_label("rotating-sphere").click();
    harness.run_steps(1);
    assert_eq!(harness.state().sim.model().particle_count(), 625);
    let grid = GridSpec::square(8, 0.6, GridOrientation::Horizontal, glam::Vec3::ZERO);
    drop_obj(&mut harness, "small.obj", &grid.to_obj());
    let app = harness.state();
    assert_eq!(app.sim.model().particle_count(), 81);
    assert_eq!(
        app.sim.scenario(),
        "rotating-sphere",
        "the new cloth keeps the scenario"
    );
    assert_eq!(app.sim.colliders().len(), 2, "and its effects");
    assert!(app.cloth_name().ends_with("small.obj"));
}

#[test]
fn dropping_a_malformed_obj_shows_an_error_and_keeps_the_cloth() {
    let mut harness = harness();
    let before = harness.state().sim.model().particle_count();
    drop_obj(
        &mut harness,
        "broken.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
    );
    let error = harness
        .state()
        .last_error()
        .expect("an error message")
        .to_string();
    assert!(
        error.contains("broken.obj") && error.contains(":4:"),
        "{error}"
    );
    assert_eq!(harness.state().sim.model().particle_count(), before);
    // The user sees it.
    harness.get_by_label_contains("broken.obj:4:");
}

#[test]
fn pause_and_step_advances_exactly_one_frame() {
    let mut harness = harness();
    let dt = harness.state().sim.params().dt as f64;
    assert_eq!(harness.state().sim.frames(), 0);
    harness.get_by_label("Step").click();
    harness.run_steps(3);
    assert_eq!(harness.state().sim.frames(), 1);
    assert!((harness.state().sim.state().time - dt).abs() < 1e-9);
    assert!(!harness.state().transport.playing);
    harness.get_by_label("Step").click();
    harness.run_steps(3);
    assert_eq!(harness.state().sim.frames(), 2);
    harness.get_by_label("Reset").click();
    harness.run_steps(1);
    assert_eq!(harness.state().sim.frames(), 0);
    assert_eq!(harness.state().sim.state().time, 0.0);
}

#[test]
fn capture_button_writes_a_png_of_the_view() {
    let dir = tempfile::tempdir().unwrap();
    let mut harness = harness();
    harness.state_mut().capture_dir = dir.path().to_path_buf();
    harness.get_by_label("Capture PNG").click();
    harness.run_steps(2);
    assert_eq!(
        harness.state().pending_writes(),
        1,
        "the click queued one image"
    );
    harness.state_mut().finish_writes();
    harness.run_steps(1);
    let path = dir.path().join("clothsim-capture-0001.png");
    let image = image::open(&path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgba8();
    assert!(
        image.width() > 400 && image.height() > 300,
        "the viewport's size, got {:?}",
        image.dimensions()
    );
    // The picture has the cloth in it: plenty of the red front colour.
    let red = image
        .pixels()
        .filter(|p| p[0] > 120 && p[0] as i32 > p[2] as i32 + 50)
        .count();
    assert!(red > 2000, "only {red} cloth-coloured pixels");
    harness.get_by_label_contains("saved");
}

#[test]
fn import_warnings_stay_visible_after_a_drop() {
    // Two quads, the second listed twice: it is dropped, and the user is told.
    let obj =
        "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 2 0 0\nv 2 0 1\nf 1 4 3 2\nf 2 3 6 5\nf 2 3 6 5\n";
    let mut harness = harness();
    drop_obj(&mut harness, "twice.obj", obj);
    assert_eq!(harness.state().sim.model().particle_count(), 6);
    harness.get_by_label_contains("duplicate triangle");
}

#[test]
fn record_writes_a_numbered_frame_sequence() {
    let dir = tempfile::tempdir().unwrap();
    let mut harness = harness();
    harness.state_mut().capture_dir = dir.path().to_path_buf();
    harness.state_mut().transport.playing = true;
    harness.get_by_label("Record").click();
    harness.run_steps(4);
    assert!(harness.state().is_recording());
    harness.get_by_label("Stop recording").click();
    harness.run_steps(1);
    assert!(!harness.state().is_recording());
    harness.state_mut().finish_writes();
    harness.run_steps(1);
    // Frames still queued when recording stopped are written silently: the summary stays
    // the message the user sees.
    let app = harness.state();
    assert!(
        app.messages.iter().all(|m| !m.text.contains("frame_")),
        "{:?}",
        app.messages
    );
    assert!(app.messages.last().unwrap().text.starts_with("recorded"));
    let folder = dir.path().join("clothsim-recording-0001");
    let mut frames: Vec<String> = std::fs::read_dir(&folder)
        .unwrap_or_else(|e| panic!("{}: {e}", folder.display()))
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    frames.sort();
    assert!(
        frames.len() >= 3,
        "one image per drawn frame, got {frames:?}"
    );
    assert_eq!(frames[0], "frame_00000.png");
    assert_eq!(frames[1], "frame_00001.png");
    harness.get_by_label_contains("recorded");
}

#[test]
fn the_accuracy_window_sweeps_in_the_background_and_applies_its_choice() {
    let mut harness = harness();
    // Start from parameters that are not among the sweep's choices.
    let mut params = harness.state().sim.params().clone();
    params.integrator = clothsim::sim::IntegratorKind::Verlet;
    params.substeps = 24;
    harness.state_mut().sim.set_params(params).unwrap();
    harness.get_by_label("Accuracy").click();
    harness.run_steps(2);
    assert!(harness.state().accuracy.open);
    // A small sweep: the real one takes half a minute on this scene.
    {
        let app = harness.state_mut();
        app.accuracy.config.integrators = vec![
            clothsim::sim::IntegratorKind::SemiImplicitEuler,
            clothsim::sim::IntegratorKind::ImplicitEuler,
        ];
        app.accuracy.config.dts = vec![1.0 / 60.0 / 6.0, 1.0 / 60.0 / 48.0];
        app.accuracy.config.seconds = 0.25;
        app.accuracy.config.samples = 3;
        app.accuracy.config.bisection_steps = 0;
        app.accuracy.tolerance = 0.5;
    }
    harness.get_by_label("Run sweep").click();
    harness.run_steps(1);
    assert!(
        harness.state().accuracy.is_running(),
        "the sweep runs in the background"
    );
    let frames = harness.state().sim.frames();
    harness.state_mut().transport.playing = true;
    harness.run_steps(3);
    assert!(
        harness.state().sim.frames() > frames || harness.state().accuracy.is_running(),
        "the viewport keeps stepping while the sweep runs"
    );
    harness.state_mut().accuracy.wait();
    harness.state_mut().transport.pause();
    harness.run_steps(2);
    let report = harness.state().accuracy.report.clone().expect("a report");
    assert_eq!(report.points.len(), 4);
    // With a tolerance of half the cloth's size every stable run qualifies, so the choice
    // is the cheapest stable one.
    let choice = harness
        .state()
        .accuracy
        .choice()
        .cloned()
        .expect("a choice");
    let cheapest = report
        .points
        .iter()
        .filter(|p| p.stable)
        .min_by(|a, b| a.wall_s_per_sim_s.total_cmp(&b.wall_s_per_sim_s))
        .unwrap();
    assert_eq!(&choice, cheapest);
    harness.get_by_label("Apply").click();
    harness.run_steps(2);
    let params = harness.state().sim.params();
    assert_eq!(params.integrator, choice.integrator);
    assert_eq!(params.substeps, choice.substeps_per_frame.round() as u32);
    assert_ne!(
        (params.integrator, params.substeps),
        (clothsim::sim::IntegratorKind::Verlet, 24),
        "the choice replaced the parameters the sweep started from"
    );
    harness.get_by_label_contains("applied");
}

#[test]
fn a_bad_parameter_is_refused_and_the_simulation_keeps_its_own() {
    let mut harness = harness();
    let before = harness.state().sim.params().clone();
    let mut bad = before.clone();
    bad.dt = f32::NAN;
    harness.state_mut().apply_params(bad);
    harness.run_steps(1);
    assert_eq!(harness.state().sim.params(), &before);
    let error = harness
        .state()
        .last_error()
        .expect("an error message")
        .to_string();
    assert!(error.contains("`dt`") && error.contains("kept"), "{error}");
    harness.get_by_label_contains("`dt`");
}

#[test]
fn a_failed_capture_is_reported_and_loses_nothing() {
    let mut harness = harness();
    harness.state_mut().capture_dir = std::path::PathBuf::from("/no/such/folder");
    let particles = harness.state().sim.model().particle_count();
    harness.get_by_label("Capture PNG").click();
    harness.run_steps(2);
    harness.state_mut().finish_writes();
    harness.run_steps(1);
    let error = harness
        .state()
        .last_error()
        .expect("an error message")
        .to_string();
    assert!(
        error.contains("/no/such/folder") && error.contains("does not exist"),
        "{error}"
    );
    assert_eq!(harness.state().sim.model().particle_count(), particles);
    // The app goes on: a capture to a good folder works.
    let dir = tempfile::tempdir().unwrap();
    harness.state_mut().capture_dir = dir.path().to_path_buf();
    harness.get_by_label("Capture PNG").click();
    harness.run_steps(2);
    harness.state_mut().finish_writes();
    assert!(dir.path().join("clothsim-capture-0001.png").is_file());
}

#[test]
fn the_guard_acting_is_shown_to_the_user() {
    let mut harness = harness();
    let mut params = harness.state().sim.params().clone();
    params.substeps = 12;
    harness.state_mut().apply_params(params);
    for _ in 0..3 {
        harness.get_by_label("Step").click();
        harness.run_steps(2);
    }
    let app = harness.state();
    assert!(
        app.messages
            .iter()
            .any(|m| m.text.starts_with("stability guard")),
        "{:?}",
        app.messages
    );
    assert!(app.sim.substeps() > 12);
    harness.get_by_label_contains("stability guard");
}
