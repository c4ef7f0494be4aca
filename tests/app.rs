//! The desktop app driven through its UI with egui_kittest on the software wgpu adapter:
//! the same panels, viewport and capture path a user gets.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};

use clothsim::app::ClothApp;
use clothsim::mesh::{GridOrientation, GridSpec};

fn harness() -> Harness<'static, ClothApp> {
    harness_sized(1280.0, 800.0)
}

/// A harness whose captures, recordings and exports go to a fresh temporary folder (which
/// lives as long as the first value).
fn harness_in_tempdir() -> (tempfile::TempDir, Harness<'static, ClothApp>) {
    let dir = tempfile::tempdir().unwrap();
    let mut harness = harness();
    harness.state_mut().recording.capture_dir = dir.path().to_path_buf();
    (dir, harness)
}

/// Clicks Capture PNG and lets the app queue the image.
fn click_capture(harness: &mut Harness<'static, ClothApp>) {
    harness.get_by_label("Capture PNG").click();
    harness.run_steps(2);
}

/// The first capture written to `dir`.
fn first_capture(dir: &std::path::Path) -> image::RgbaImage {
    let path = dir.join("clothsim-capture-0001.png");
    image::open(&path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgba8()
}

/// A window of this size (a tall one shows the whole side panel without scrolling).
fn harness_sized(width: f32, height: f32) -> Harness<'static, ClothApp> {
    let mut harness = Harness::builder()
        .with_size([width, height])
        .wgpu_setup(clothsim::app::with_compute_limits(
            egui_kittest::wgpu::default_wgpu_setup(),
        ))
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
/// Runs `frames` UI frames, then waits for the stepping thread to finish what it was asked
/// and shows the result.
fn run_settled(harness: &mut Harness<'static, ClothApp>, frames: usize) {
    harness.run_steps(frames);
    harness.state_mut().settle();
    harness.run_steps(1);
}

/// The app's last error message; there must be one.
fn last_error(harness: &Harness<'static, ClothApp>) -> String {
    harness
        .state()
        .last_error()
        .expect("an error message")
        .to_string()
}

fn drop_obj(harness: &mut Harness<'static, ClothApp>, name: &str, text: &str) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    harness
        .input_mut()
        .dropped_files
        .push(Arc::new(Dropped(path)));
    harness.run_steps(2);
    // An OBJ could be the cloth or an obstacle: the app asks.
    harness.get_by_label("Replace cloth").click();
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
    assert_eq!(harness.state().sim().scenario(), "hanging");
    assert_eq!(harness.state().sim().solids().count(), 0);
    harness.get_by_label("sphere-drop").click();
    harness.run_steps(2);
    let sim = harness.state().sim();
    assert_eq!(sim.scenario(), "sphere-drop");
    assert_eq!(sim.solids().count(), 2, "sphere and ground");
    assert!(sim.model().pins.is_empty(), "sphere-drop pins nothing");
    assert_eq!(sim.frames(), 0, "a new scene starts from its initial state");
}

#[test]
fn dropping_a_valid_obj_changes_the_particle_count() {
    let mut harness = harness();
    harness.get_by_label("rotating-sphere").click();
    harness.run_steps(1);
    assert_eq!(harness.state().sim().model().particle_count(), 625);
    let grid = GridSpec::square(8, 0.6, GridOrientation::Horizontal, glam::Vec3::ZERO);
    drop_obj(&mut harness, "small.obj", &grid.to_obj());
    let app = harness.state();
    assert_eq!(app.sim().model().particle_count(), 81);
    assert_eq!(
        app.sim().scenario(),
        "rotating-sphere",
        "the new cloth keeps the scenario"
    );
    assert_eq!(app.sim().solids().count(), 2, "and its effects");
    assert!(app.cloth_name().ends_with("small.obj"));
}

#[test]
fn dropping_a_malformed_obj_shows_an_error_and_keeps_the_cloth() {
    let mut harness = harness();
    let before = harness.state().sim().model().particle_count();
    drop_obj(
        &mut harness,
        "broken.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
    );
    let error = last_error(&harness);
    assert!(
        error.contains("broken.obj") && error.contains(":4:"),
        "{error}"
    );
    assert_eq!(harness.state().sim().model().particle_count(), before);
    // The user sees it.
    harness.get_by_label_contains("broken.obj:4:");
}

/// With no message the status bar offers nothing to dismiss; a message brings a Dismiss
/// button that clears it, and the bar keeps its height throughout, so the view above it does
/// not jump.
#[test]
fn a_message_is_dismissed_and_the_status_bar_keeps_its_height() {
    let mut harness = harness();
    // The height of the label of simulated time (its width follows the frame rate's before).
    let time_label =
        |h: &Harness<'static, ClothApp>| h.get_by_label_contains("t = ").rect().y_range();
    let quiet = time_label(&harness);
    assert!(harness.query_by_label("Dismiss").is_none());
    drop_obj(&mut harness, "broken.obj", "v 0 0 0\nf 1 2 3\n");
    last_error(&harness);
    assert_eq!(
        time_label(&harness),
        quiet,
        "a message moved the status bar"
    );
    harness.get_by_label("Dismiss").click();
    harness.run_steps(2);
    assert!(harness.state().messages.is_empty());
    assert!(harness.query_by_label("Dismiss").is_none());
    assert_eq!(time_label(&harness), quiet);
}

/// The intersection check, turned on in the View panel: the status bar says nothing of it
/// while it is off; on, it says none were found after the frames of a cloth that keeps
/// clear, and the counts after those of a cloth of two strips through each other (a new
/// cloth starts the count again); off again, it says nothing.
#[test]
fn the_intersection_check_shows_its_counts_in_the_status_bar() {
    // Tall enough that the View section is on screen.
    let mut harness = harness_sized(1280.0, 2000.0);
    let said = |h: &Harness<'static, ClothApp>| {
        h.query_by_label_contains("intersections: ").map(|n| {
            n.value()
                .or_else(|| n.accesskit_node().label())
                .unwrap_or_default()
        })
    };
    assert_eq!(said(&harness), None);
    harness.get_by_label("Check intersections").click();
    harness.run_steps(2);
    assert_eq!(
        said(&harness).as_deref(),
        Some("intersections: no frame checked yet")
    );
    harness.get_by_label("Step").click();
    run_settled(&mut harness, 2);
    assert_eq!(said(&harness).as_deref(), Some("intersections: none"));
    // A strip 2 m long, and a square 0.4 m across through its middle at right angles.
    let crossed = "v -1 0 -0.2\nv 1 0 -0.2\nv 1 0 0.2\nv -1 0 0.2\n\
                   v -0.2 -0.2 0\nv 0.2 -0.2 0\nv 0.2 0.2 0\nv -0.2 0.2 0\n\
                   f 1 2 3\nf 1 3 4\nf 5 6 7\nf 5 7 8\n";
    drop_obj(&mut harness, "crossed.obj", crossed);
    assert_eq!(
        said(&harness).as_deref(),
        Some("intersections: no frame checked yet")
    );
    harness.get_by_label("Step").click();
    run_settled(&mut harness, 2);
    let text = said(&harness).expect("the counts");
    let found = harness
        .state()
        .check
        .found()
        .expect("a frame checked")
        .clone();
    assert!(found.last.self_pairs > 0, "{text}");
    assert_eq!(
        text,
        format!(
            "intersections: {} self, 0 with solids (most {}, 0)",
            found.last.self_pairs, found.most.self_pairs
        )
    );
    harness.get_by_label("Check intersections").click();
    harness.run_steps(2);
    assert_eq!(said(&harness), None);
}

#[test]
fn pause_and_step_advances_exactly_one_frame() {
    let mut harness = harness();
    let dt = harness.state().sim().params().step.dt as f64;
    assert_eq!(harness.state().sim().frames(), 0);
    harness.get_by_label("Step").click();
    run_settled(&mut harness, 3);
    assert_eq!(harness.state().sim().frames(), 1);
    assert!((harness.state().sim().state().time - dt).abs() < 1e-9);
    assert!(!harness.state().transport.playing);
    harness.get_by_label("Step").click();
    run_settled(&mut harness, 3);
    assert_eq!(harness.state().sim().frames(), 2);
    harness.get_by_label("Reset").click();
    run_settled(&mut harness, 1);
    assert_eq!(harness.state().sim().frames(), 0);
    assert_eq!(harness.state().sim().state().time, 0.0);
}

#[test]
fn capture_button_writes_a_png_of_the_view() {
    let (dir, mut harness) = harness_in_tempdir();
    click_capture(&mut harness);
    harness.state_mut().finish_writes();
    harness.run_steps(1);
    // One click, one file (counted once every write is done: how far the writer's thread
    // got by the time the click's frames were drawn is the scheduler's affair).
    let written = std::fs::read_dir(dir.path())
        .expect("the capture folder")
        .count();
    assert_eq!(written, 1, "the click wrote one image");
    let image = first_capture(dir.path());
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
    assert_eq!(harness.state().sim().model().particle_count(), 6);
    harness.get_by_label_contains("duplicate triangle");
}

#[test]
fn record_writes_a_numbered_frame_sequence() {
    let (dir, mut harness) = harness_in_tempdir();
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
    let mut params = harness.state().sim().params().clone();
    params.step.integrator = clothsim::sim::IntegratorKind::Verlet;
    params.step.substeps = 24;
    harness.state_mut().apply_params(params);
    harness.get_by_label("Accuracy").click();
    harness.run_steps(2);
    assert!(harness.state().accuracy.open);
    // A small sweep: the real one takes half a minute on this scene.
    {
        let app = harness.state_mut();
        app.accuracy.config.integrators = vec![
            clothsim::sim::IntegratorKind::SemiImplicitEuler,
            clothsim::sim::IntegratorKind::Xpbd,
        ];
        app.accuracy.config.dts = vec![1.0 / 60.0 / 12.0, 1.0 / 60.0 / 48.0];
        app.accuracy.config.seconds = 0.25;
        app.accuracy.config.samples = 3;
        app.accuracy.config.bisection_steps = 0;
        app.accuracy.tolerance = 0.01;
    }
    harness.get_by_label("Run sweep").click();
    harness.run_steps(1);
    assert!(
        harness.state().accuracy.is_running(),
        "the sweep runs in the background"
    );
    let frames = harness.state().sim().frames();
    harness.state_mut().transport.playing = true;
    harness.run_steps(3);
    assert!(
        harness.state().sim().frames() > frames || harness.state().accuracy.is_running(),
        "the viewport keeps stepping while the sweep runs"
    );
    harness.state_mut().accuracy.wait();
    harness.state_mut().transport.pause();
    harness.run_steps(2);
    let report = harness.state().accuracy.report.clone().expect("a report");
    assert_eq!(report.points.len(), 4);
    // A tolerance of 1 % of the cloth's size rules out the cheapest stable run (XPBD at 12
    // substeps, about 5 % off): the choice is the cheapest by counted work of those within.
    let choice = harness
        .state()
        .accuracy
        .choice()
        .cloned()
        .expect("a choice");
    let by_work = |a: &&clothsim::report::Point, b: &&clothsim::report::Point| {
        a.work_per_sim_s.total_cmp(&b.work_per_sim_s)
    };
    let stable = || report.points.iter().filter(|p| p.stable);
    let cheapest = stable().min_by(by_work).unwrap();
    assert!(
        cheapest.max_error > 0.01,
        "the tolerance rules nothing out: {cheapest:?}"
    );
    let within = stable().filter(|p| p.max_error <= 0.01).min_by(by_work);
    assert_eq!(Some(&choice), within);
    harness.get_by_label("Apply").click();
    harness.run_steps(2);
    let params = harness.state().sim().params();
    assert_eq!(params.step.integrator, choice.integrator);
    assert_eq!(
        params.step.substeps,
        choice.substeps_per_frame.round() as u32
    );
    assert_ne!(
        (params.step.integrator, params.step.substeps),
        (clothsim::sim::IntegratorKind::Verlet, 24),
        "the choice replaced the parameters the sweep started from"
    );
    harness.get_by_label_contains("applied");
}

#[test]
fn a_bad_parameter_is_refused_and_the_simulation_keeps_its_own() {
    let mut harness = harness();
    let before = harness.state().sim().params().clone();
    let mut bad = before.clone();
    bad.step.dt = f32::NAN;
    harness.state_mut().apply_params(bad);
    harness.run_steps(1);
    assert_eq!(harness.state().sim().params(), &before);
    let error = last_error(&harness);
    assert!(error.contains("`dt`") && error.contains("kept"), "{error}");
    harness.get_by_label_contains("`dt`");
}

#[test]
fn a_failed_capture_is_reported_and_loses_nothing() {
    let mut harness = harness();
    harness.state_mut().recording.capture_dir = std::path::PathBuf::from("/no/such/folder");
    let particles = harness.state().sim().model().particle_count();
    click_capture(&mut harness);
    harness.state_mut().finish_writes();
    harness.run_steps(1);
    let error = last_error(&harness);
    assert!(
        error.contains("/no/such/folder") && error.contains("does not exist"),
        "{error}"
    );
    assert_eq!(harness.state().sim().model().particle_count(), particles);
    // The app goes on: a capture to a good folder works.
    let dir = tempfile::tempdir().unwrap();
    harness.state_mut().recording.capture_dir = dir.path().to_path_buf();
    click_capture(&mut harness);
    harness.state_mut().finish_writes();
    assert!(dir.path().join("clothsim-capture-0001.png").is_file());
}

#[test]
fn the_guard_acting_is_shown_to_the_user() {
    let mut harness = harness();
    let mut params = harness.state().sim().params().clone();
    params.step.substeps = 12;
    harness.state_mut().apply_params(params);
    for _ in 0..3 {
        harness.get_by_label("Step").click();
        run_settled(&mut harness, 2);
    }
    let app = harness.state();
    assert!(
        app.messages
            .iter()
            .any(|m| m.text.starts_with("stability guard")),
        "{:?}",
        app.messages
    );
    assert!(app.in_effect().substeps > 12);
    harness.get_by_label_contains("stability guard");
}

/// Drops a file that already exists and waits for it to load.
fn drop_path(harness: &mut Harness<'static, ClothApp>, path: &Path) {
    harness
        .input_mut()
        .dropped_files
        .push(Arc::new(Dropped(path.to_path_buf())));
    harness.run_steps(1);
    harness.state_mut().finish_loading();
    harness.run_steps(2);
}

#[test]
fn dropping_a_scene_file_opens_that_scene_and_a_bad_one_keeps_the_current() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("breeze.toml");
    std::fs::write(
        &good,
        "name = \"breeze\"\n[cloth]\ngrid = { quads = 8, size = 0.5 }\norientation = \"vertical\"\n\
         [pins]\nedges = [\"top\"]\n[[effects]]\ntype = \"gravity\"\n[[effects]]\ntype = \"wind\"\n",
    )
    .unwrap();
    let mut harness = harness();
    drop_path(&mut harness, &good);
    let sim = harness.state().sim();
    assert_eq!(sim.scenario(), "breeze");
    assert_eq!(sim.model().particle_count(), 81);
    assert_eq!(sim.model().pins.len(), 9);
    // The panel shows exactly this scene's effects.
    harness.get_by_label("Wind");
    assert!(harness.query_by_label("Air damping").is_none());

    let bad = dir.path().join("broken.toml");
    std::fs::write(
        &bad,
        "name = \"b\"\n[cloth]\ngrid = { quads = 8, size = 0.5 }\nwobble = 1\n",
    )
    .unwrap();
    drop_path(&mut harness, &bad);
    assert_eq!(
        harness.state().sim().scenario(),
        "breeze",
        "the current scene stays"
    );
    let error = last_error(&harness);
    assert!(
        error.contains("broken.toml:4:1") && error.contains("`wobble`"),
        "{error}"
    );
    harness.get_by_label_contains("broken.toml:4:1");
}

#[test]
fn the_effects_panel_shows_the_scenes_effects_and_adds_and_removes_them() {
    let mut harness = harness_sized(1280.0, 1600.0);
    // Hanging: gravity, air damping, bending; no wind, no colliders, no self-collision.
    for present in ["Gravity", "Air damping", "Bending"] {
        harness.get_by_label(present);
    }
    for absent in ["Wind", "Sphere", "Ground plane", "Self-collision"] {
        assert!(harness.query_by_label(absent).is_none(), "{absent} shown");
    }
    // Add wind through the menu.
    harness.get_by_label("Add effect").click();
    harness.run_steps(2);
    harness.get_by_label("Wind").click();
    harness.run_steps(2);
    assert!(
        harness
            .state()
            .sim()
            .effects()
            .iter()
            .any(|e| matches!(e, clothsim::sim::Effect::Wind(_)))
    );
    harness.get_by_label("Wind");
    // Its phase shows in the status bar once it has run (on the stepping thread: wait).
    harness.get_by_label("Step").click();
    run_settled(&mut harness, 2);
    harness.get_by_label_contains(" wind ");
    // Remove gravity: the first "Remove" belongs to the first removable effect, gravity.
    let before = harness.state().sim().effects().len();
    let removes = harness.query_all_by_label("Remove").count();
    assert_eq!(
        removes,
        before - 1,
        "every effect but the springs can be removed"
    );
    harness.query_all_by_label("Remove").next().unwrap().click();
    harness.run_steps(2);
    let effects = harness.state().sim().effects().to_vec();
    assert_eq!(effects.len(), before - 1);
    assert!(
        !effects
            .iter()
            .any(|e| matches!(e, clothsim::sim::Effect::Gravity(_)))
    );
    assert!(harness.query_by_label("Gravity").is_none());
}

#[test]
fn save_scene_writes_a_file_that_reopens_as_the_same_setup() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("saved.toml");
    let mut harness = harness();
    harness.get_by_label("flag").click();
    harness.run_steps(2);
    harness.state_mut().panels.side.scene.save_path = path.to_string_lossy().into_owned();
    harness.get_by_label("Save scene").click();
    harness.run_steps(2);
    assert!(path.is_file(), "{:?}", harness.state().messages);
    let effects = harness.state().sim().effects().to_vec();
    harness.get_by_label("hanging").click();
    harness.run_steps(2);
    drop_path(&mut harness, &path);
    assert_eq!(harness.state().sim().scenario(), "flag");
    assert_eq!(harness.state().sim().effects(), &effects[..]);
    // An unwritable path is an error and writes nothing.
    harness.state_mut().panels.side.scene.save_path = "/no/such/dir/s.toml".into();
    harness.get_by_label("Save scene").click();
    harness.run_steps(2);
    assert!(last_error(&harness).contains("/no/such/dir"));
}

#[test]
fn export_obj_writes_the_cloth_as_it_is_now() {
    let (dir, mut harness) = harness_in_tempdir();
    for _ in 0..3 {
        harness.get_by_label("Step").click();
        harness.run_steps(1);
    }
    // The stepped frames shown before the export, so that none arrives between the export
    // and the comparison.
    run_settled(&mut harness, 1);
    harness.get_by_label("Export OBJ").click();
    harness.run_steps(2);
    let path = dir.path().join("clothsim-export-0001.obj");
    let back = clothsim::mesh::load_obj(&path).expect("a valid OBJ");
    assert_eq!(back.mesh.positions, harness.state().sim().state().pos);
}

/// On the GPU backend the replica's state is read back only now and then; an export writes
/// the frame just stepped, not an older one. (The export's own catch-up is checked by
/// `catch_up_publishes_the_gpu_state_of_the_latest_frame`; here the thread's read-back when
/// stepping stops often comes first, as a harness frame takes longer than its 30 ms.)
#[test]
fn export_obj_on_the_gpu_writes_the_latest_frame() {
    let (dir, mut harness) = harness_in_tempdir();
    harness.state_mut().set_scenario("sphere-drop");
    harness.run_steps(1);
    harness.get_by_label("GPU").click();
    run_settled(&mut harness, 2);
    assert_eq!(harness.state().in_effect().backend, "gpu");
    let before = harness.state().sim().state().pos.clone();
    let frames = harness.state().sim().frames();
    harness.state_mut().step_once();
    // Once the frame is done (drawn from the GPU's buffer), export.
    for _ in 0..1000 {
        harness.run_steps(1);
        if harness.state().sim().frames() > frames {
            break;
        }
    }
    harness.state_mut().export_obj();
    let path = dir.path().join("clothsim-export-0001.obj");
    let back = clothsim::mesh::load_obj(&path).expect("a valid OBJ");
    run_settled(&mut harness, 1);
    let latest = &harness.state().sim().state().pos;
    assert_ne!(&before, latest, "the cloth moved");
    assert_eq!(
        &back.mesh.positions, latest,
        "the export is the frame stepped"
    );
}

#[test]
fn record_gif_writes_an_animated_gif_of_the_view() {
    let (dir, mut harness) = harness_in_tempdir();
    harness.state_mut().transport.playing = true;
    harness.get_by_label("Record GIF").click();
    harness.run_steps(5);
    assert!(
        harness.state().is_recording_gif(),
        "{:?}",
        harness.state().messages
    );
    harness.get_by_label("Stop GIF").click();
    harness.run_steps(1);
    harness.state_mut().finish_writes();
    harness.run_steps(1);
    let path = dir.path().join("clothsim-recording-0001.gif");
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options
        .read_info(std::fs::File::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())))
        .unwrap();
    assert!(decoder.width() > 400, "the view's size");
    let mut frames = 0;
    while decoder.read_next_frame().unwrap().is_some() {
        frames += 1;
    }
    assert!(frames >= 3, "{frames} frames");
    harness.get_by_label_contains("saved");
}

/// A point in the view over the cloth, and the particle it picks.
fn point_on_cloth(harness: &Harness<'static, ClothApp>) -> (egui::Pos2, u32) {
    let app = harness.state();
    let rect = app.view_rect().expect("the view was drawn");
    let centre = rect.center();
    // Search outwards from the centre of the view.
    for r in 0..40 {
        for k in 0..16 {
            let angle = k as f32 * std::f32::consts::TAU / 16.0;
            let at = centre + egui::vec2(angle.cos(), angle.sin()) * (r as f32 * 8.0);
            if let Some((p, _)) = app.particle_at(rect, at)
                && !app.sim().model().pins.contains(&p)
            {
                return (at, p);
            }
        }
    }
    panic!("no cloth in the view");
}

/// Steps `frames` simulation frames one at a time (paused), then shows the result.
fn step_frames(harness: &mut Harness<'static, ClothApp>, frames: usize) {
    for _ in 0..frames {
        harness.state_mut().step_once();
    }
    run_settled(harness, 1);
}

#[test]
fn dragging_the_cloth_pulls_a_particle_and_ctrl_click_pins_it_under_every_integrator() {
    use clothsim::sim::IntegratorKind;
    let mut harness = harness();
    for kind in IntegratorKind::ALL {
        let mut params = harness.state().sim().params().clone();
        params.step.integrator = kind;
        params.step.substeps = match kind {
            IntegratorKind::ExplicitEuler => 2400,
            IntegratorKind::Rk2 => 150,
            IntegratorKind::ImplicitEuler => 4,
            IntegratorKind::Xpbd | IntegratorKind::Vbd => 10,
            _ => 48,
        };
        harness.state_mut().reset();
        harness.state_mut().apply_params(params);
        // Stepped a frame at a time, not played: frames played follow the wall clock, and
        // pointer moves that meet no frame between them add up to one long jump.
        step_frames(&mut harness, 2);
        let (at, _) = point_on_cloth(&harness);
        // Press on the cloth and drag 60 points to the right, one simulated frame per move.
        harness.hover_at(at);
        harness.run_steps(1);
        let start = harness.state().sim().state().pos.clone();
        harness.drag_at(at);
        harness.run_steps(1);
        for k in 1..=6 {
            harness.hover_at(at + egui::vec2(10.0 * k as f32, 0.0));
            harness.run_steps(1);
            harness.state_mut().step_once();
        }
        harness.state_mut().settle();
        // The particle picked where the drag began (the cloth moves meanwhile).
        let p = harness
            .state()
            .sim()
            .grabbed()
            .unwrap_or_else(|| panic!("{kind:?}: nothing held"));
        let moved = harness.state().sim().state().pos[p as usize] - start[p as usize];
        // The camera looks at the cloth from the front-right: screen-right has +x in it.
        assert!(
            moved.length() > 0.05 && moved.x > 0.0,
            "{kind:?}: moved {moved}"
        );
        harness.drop_at(at + egui::vec2(60.0, 0.0));
        harness.run_steps(1);
        // Let go, it flies on with the pointer's velocity.
        step_frames(&mut harness, 3);
        assert_eq!(harness.state().sim().grabbed(), None, "{kind:?}: let go");
        assert_eq!(harness.state().in_effect().integrator, kind);

        // Ctrl-click pins the particle under the pointer; again frees it (still paused).
        let (at, p) = point_on_cloth(&harness);
        let ctrl_click = |harness: &mut Harness<'static, ClothApp>| {
            harness.hover_at(at);
            harness.run_steps(1);
            harness.event(egui::Event::ModifiersChanged(egui::Modifiers::COMMAND));
            harness.drag_at(at);
            harness.run_steps(1);
            harness.event(egui::Event::PointerButton {
                pos: at,
                button: egui::PointerButton::Primary,
                pressed: false,
                modifiers: egui::Modifiers::COMMAND,
            });
            harness.run_steps(1);
            harness.event(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
            harness.run_steps(1);
        };
        ctrl_click(&mut harness);
        assert!(
            harness.state().sim().model().pins.contains(&p),
            "{kind:?}: pinned"
        );
        harness.get_by_label(&format!("pinned particle {p}"));
        ctrl_click(&mut harness);
        assert!(
            !harness.state().sim().model().pins.contains(&p),
            "{kind:?}: freed {:?}",
            harness.state().messages
        );
    }
}

/// Dragging a particle of `layers` down through the cloths below forces pairs together
/// (the held particle's path is prescribed): the status area says how many, in one message
/// that counts up as the drag goes on.
#[test]
fn a_drag_through_the_cloth_is_reported_with_the_pairs_it_forced() {
    drag_through_layers(false);
}

/// The same on the GPU backend, which takes the drag's move into its first substep too.
#[test]
fn a_drag_through_the_cloth_on_the_gpu_is_reported_with_the_pairs_it_forced() {
    drag_through_layers(true);
}

fn drag_through_layers(on_gpu: bool) {
    let mut harness = harness();
    harness.get_by_label("layers").click();
    harness.run_steps(2);
    if on_gpu {
        harness.get_by_label("GPU").click();
        run_settled(&mut harness, 2);
        let backend = harness.state().in_effect().backend;
        assert_eq!(backend, "gpu", "{:?}", harness.state().last_error());
    }
    step_frames(&mut harness, 1);
    // A point over the top cloth with cloth 10 points below it too (where the drag starts).
    let app = harness.state();
    let rect = app.view_rect().expect("the view was drawn");
    let top = app.sim().model().particle_count() as u32 * 4 / 5;
    let on_top = |at: egui::Pos2| app.particle_at(rect, at).is_some_and(|(p, _)| p >= top);
    let at = (0..1600)
        .map(|k| rect.center() + egui::vec2((k % 40) as f32 - 20.0, (k / 40) as f32 - 30.0) * 8.0)
        .find(|&at| on_top(at) && on_top(at + egui::vec2(0.0, 10.0)))
        .expect("the top cloth in the view");
    harness.hover_at(at);
    harness.run_steps(1);
    harness.drag_at(at);
    harness.run_steps(1);
    for k in 1..=8 {
        harness.hover_at(at + egui::vec2(0.0, 20.0 * k as f32));
        harness.run_steps(1);
        harness.state_mut().step_once();
    }
    harness.state_mut().settle();
    run_settled(&mut harness, 1);
    let app = harness.state();
    assert!(app.sim().grabbed().is_some(), "the drag holds a particle");
    let forced = app.in_effect().forced;
    assert!(forced > 0, "the drag forced no pair");
    let tallies: Vec<_> = (app.messages.iter())
        .filter(|m| m.text.contains("prescribed motion"))
        .collect();
    assert_eq!(tallies.len(), 1, "{:?}", app.messages);
    assert!(
        tallies[0].text.contains(&format!("forced {forced} pairs")),
        "{:?}",
        tallies[0]
    );
}

#[test]
fn the_gpu_button_moves_the_cloth_to_the_gpu_and_back_keeping_its_state() {
    let mut harness = harness();
    harness.get_by_label("Step").click();
    run_settled(&mut harness, 3);
    let before = harness.state().sim().state().clone();
    harness.get_by_label("GPU").click();
    run_settled(&mut harness, 2);
    assert_eq!(
        harness.state().in_effect().backend,
        "gpu",
        "{:?}",
        harness.state().last_error()
    );
    // The GPU continues from the CPU's state and steps the same cloth as the CPU would.
    let mut cpu = clothsim::scene::Simulation::new(harness.state().sim().to_scene());
    cpu.modify_state(|s| *s = before.clone());
    cpu.step_frame().expect("cpu frame");
    harness.get_by_label("Step").click();
    run_settled(&mut harness, 3);
    let gpu = harness.state().sim().state().clone();
    assert_eq!(harness.state().sim().frames(), 2);
    assert_ne!(gpu.pos, before.pos, "the GPU stepped");
    let worst = gpu
        .pos
        .iter()
        .zip(&cpu.state().pos)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f32::max);
    assert!(
        worst < 1e-5,
        "GPU and CPU differ by {worst} m after one frame"
    );
    assert!(
        harness.state().drawn_from_gpu(),
        "the view draws the GPU's buffer"
    );
    harness.get_by_label("CPU").click();
    run_settled(&mut harness, 2);
    assert_eq!(harness.state().in_effect().backend, "cpu");
    assert!(!harness.state().drawn_from_gpu());
    assert_eq!(
        harness.state().sim().state().pos,
        gpu.pos,
        "the state came back"
    );
    // A scene with self-collision goes to the GPU too.
    harness.state_mut().set_scenario("self-fold");
    harness.run_steps(1);
    harness.get_by_label("GPU").click();
    run_settled(&mut harness, 2);
    assert_eq!(harness.state().in_effect().backend, "gpu");
    harness.get_by_label("CPU").click();
    run_settled(&mut harness, 2);
    // A setting the GPU cannot run (RK4) stays on the CPU and says why.
    let mut params = harness.state().sim().params().clone();
    params.step.integrator = clothsim::sim::IntegratorKind::Rk4;
    harness.state_mut().apply_params(params);
    harness.run_steps(1);
    harness.get_by_label("GPU").click();
    run_settled(&mut harness, 2);
    assert_eq!(harness.state().in_effect().backend, "cpu");
    let err = harness.state().last_error().unwrap_or_default().to_string();
    assert!(err.contains("staying on the CPU"), "{err}");
}

#[test]
fn the_antialiasing_setting_redraws_the_view_with_that_many_samples() {
    // Tall enough that the View section is on screen.
    let mut harness = harness_sized(1280.0, 2000.0);
    // A software adapter starts without MSAA: there 4× costs as much as the rest of a frame.
    assert_eq!(harness.state().samples_in_use(), 1);
    assert_eq!(harness.state().view_samples(), Some(1));
    // llvmpipe offers 2× and 4×.
    harness.get_by_label("4×").click();
    harness.run_steps(2);
    assert_eq!(harness.state().view_samples(), Some(4));
    harness.get_by_label("off").click();
    harness.run_steps(2);
    assert_eq!(harness.state().view_samples(), Some(1));
    // Asking for more than the adapter has gives the most it has.
    harness.state_mut().view.samples = 16;
    harness.run_steps(2);
    assert_eq!(harness.state().view_samples(), Some(4));
}

#[test]
fn the_window_shows_the_view_exactly_as_captured() {
    let (dir, mut harness) = harness_in_tempdir();
    click_capture(&mut harness);
    harness.state_mut().finish_writes();
    let capture = first_capture(dir.path());
    // Away from the button, so that no tooltip points into the view.
    harness.event(egui::Event::PointerGone);
    harness.run_steps(2);
    let window = harness.render().expect("the window renders");
    let rect = harness.state().view_rect().expect("the view was drawn");
    let ppp = harness.ctx.pixels_per_point();
    let (left, top) = (
        (rect.min.x * ppp).round() as u32,
        (rect.min.y * ppp).round() as u32,
    );
    assert!(
        left + capture.width() <= window.width() && top + capture.height() <= window.height(),
        "a {:?} view at ({left}, {top}) in a {:?} window",
        capture.dimensions(),
        window.dimensions()
    );
    // Paused, the view is drawn again the same: the window holds the captured image texel
    // for texel, in place and the right way up.
    let differing = capture
        .enumerate_pixels()
        .filter(|&(x, y, p)| window.get_pixel(left + x, top + y) != p)
        .count();
    assert_eq!(differing, 0, "of {} pixels", capture.len() / 4);
}

#[test]
fn the_window_is_cleared_to_the_panels_colour_in_either_theme() {
    // The panels paint no fill of their own (a third of egui's cost on a software
    // adapter): the window's clear colour is what shows behind them.
    let harness = harness();
    for visuals in [egui::Visuals::dark(), egui::Visuals::light()] {
        assert_eq!(
            eframe::App::clear_color(harness.state(), &visuals),
            visuals.panel_fill.to_normalized_gamma_f32()
        );
    }
}

#[test]
fn a_self_collision_thicker_than_the_cloth_is_refused_and_the_effects_stay() {
    let mut harness = harness();
    harness.state_mut().set_scenario("self-fold");
    harness.run_steps(1);
    let before = harness.state().sim().effects().to_vec();
    let mut thick = before.clone();
    for e in &mut thick {
        if let clothsim::sim::Effect::SelfCollision(s) = e {
            s.thickness = 0.1;
        }
    }
    harness.state_mut().apply_effects(thick);
    harness.run_steps(1);
    assert_eq!(harness.state().sim().effects(), before);
    let error = last_error(&harness);
    assert!(
        error.contains("`thickness` = 0.1 m") && error.contains("shortest rest edge"),
        "{error}"
    );
    harness.get_by_label_contains("shortest rest edge");
}

/// A dropped OBJ can be added as an obstacle instead of replacing the cloth: the cloth
/// stays, the scene gains a mesh obstacle (shown in the Effects panel with its triangles).
/// The Effects panel adds one from a typed path; a path that cannot be read is an error
/// naming it, and the effects stay as they were.
#[test]
fn an_obj_can_be_added_as_an_obstacle_by_drop_or_by_path() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("slab.obj");
    std::fs::write(
        &path,
        "v -1 -2 -1\nv 1 -2 -1\nv 1 -2 1\nv -1 -2 1\nf 1 3 2\nf 1 4 3\n",
    )
    .unwrap();
    let mut harness = harness_sized(1280.0, 1600.0);
    let particles = harness.state().sim().model().particle_count();
    let effects = harness.state().sim().effects().len();
    harness
        .input_mut()
        .dropped_files
        .push(Arc::new(Dropped(path.clone())));
    harness.run_steps(2);
    harness.get_by_label("Add as obstacle").click();
    harness.run_steps(2);
    let sim = harness.state().sim();
    assert_eq!(sim.model().particle_count(), particles, "the cloth stays");
    assert_eq!(sim.effects().len(), effects + 1);
    assert!(matches!(
        sim.effects().last(),
        Some(clothsim::sim::Effect::Obstacle(_))
    ));
    assert!(
        harness.query_by_label("Add as obstacle").is_none(),
        "asked once"
    );
    harness.get_by_label_contains("(2 triangles)");

    harness.state_mut().panels.side.effects.obstacle_path =
        dir.path().join("missing.obj").display().to_string();
    harness.get_by_label("Add obstacle").click();
    harness.run_steps(2);
    assert!(last_error(&harness).contains("missing.obj"));
    assert_eq!(harness.state().sim().effects().len(), effects + 1);
    harness.state_mut().panels.side.effects.obstacle_path = path.display().to_string();
    harness.get_by_label("Add obstacle").click();
    harness.run_steps(2);
    assert_eq!(harness.state().sim().effects().len(), effects + 2);
}

/// Story: in the Accuracy window a user asks for the stability map and for small steps on
/// the `orders` scene; each runs in the background and its answer appears in the window.
#[test]
fn the_accuracy_window_answers_the_stability_map_and_small_steps() {
    let mut harness = harness();
    harness.state_mut().set_scenario("orders");
    harness.run_steps(2);
    harness.get_by_label("Accuracy").click();
    harness.run_steps(2);
    harness.get_by_label("Small steps").click();
    harness.run_steps(1);
    assert!(harness.state().accuracy.is_running());
    harness.state_mut().accuracy.wait();
    harness.run_steps(2);
    let grid = harness.state().accuracy.extras.small_steps.clone();
    let grid = grid.expect("small steps answered");
    assert_eq!(grid.scene, "orders");
    harness.get_by_label_contains("XPBD: small steps win");
    harness.get_by_label("Stability map").click();
    harness.run_steps(1);
    harness.state_mut().accuracy.wait();
    harness.run_steps(2);
    let map = harness.state().accuracy.extras.map.clone().expect("a map");
    let kinds = clothsim::sim::IntegratorKind::ALL.len();
    assert_eq!(map.points.len(), kinds * clothsim::report::MAP_SCALES.len());
    harness.get_by_label_contains("Stability map (fewest stable substeps");
}

/// The Solver section's precision switch puts the cloth on the `f64` stepper, from the
/// state it had: the app's next frame has the bits of a headless `f64` frame from that
/// state, not those of an `f32` one. On the way to the GPU, `f64` is refused with the reason.
#[test]
fn the_precision_switch_steps_the_cloth_in_f64() {
    use clothsim::sim::Precision;
    let mut harness = harness();
    harness.state_mut().set_scenario("sphere-drop");
    harness.get_by_label("Step").click();
    run_settled(&mut harness, 3);
    let before = harness.state().sim().state().clone();
    harness.get_by_label("f64").click();
    run_settled(&mut harness, 2);
    assert_eq!(
        harness.state().sim().params().solver.precision,
        Precision::F64,
        "{:?}",
        harness.state().last_error()
    );
    let frame_in = |precision: Precision| {
        let mut scene = harness.state().sim().to_scene();
        scene.params.solver.precision = precision;
        let mut sim = clothsim::scene::Simulation::new(scene);
        sim.modify_state(|s| *s = before.clone());
        sim.step_frame().expect("a frame");
        sim.state().pos.clone()
    };
    let (f64_frame, f32_frame) = (frame_in(Precision::F64), frame_in(Precision::F32));
    assert_ne!(f64_frame, f32_frame, "the precisions round differently");
    harness.get_by_label("Step").click();
    run_settled(&mut harness, 3);
    assert_eq!(harness.state().sim().frames(), 2);
    assert_eq!(harness.state().sim().state().pos, f64_frame);
    // The GPU computes in f32 only: it is not entered, and the message says why.
    harness.get_by_label("GPU").click();
    run_settled(&mut harness, 2);
    assert_eq!(harness.state().in_effect().backend, "cpu");
    let error = harness.state().last_error().unwrap_or_default();
    assert!(error.contains("f32 only"), "{error:?}");
}
