//! The desktop application: state, actions, and the per-frame flow.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crate::mesh::MeshBuild;
use crate::render::{DevicePositions, OrbitCamera, RenderOptions};
use crate::scene::{Scene, Simulation};
use crate::sim::{Effect, GuardAction, PhaseTimings, SimParams};
use crate::view;

use super::accuracy::{AccuracyWindow, Start};
use super::background::{Load, PngWriter};
use super::intersection_check::IntersectionCheck;
use super::messages::{Level, Message, forced_pairs};
use super::panel::{Action, Panel, PanelContext, Status};
use super::panels::{SidePanel, StatusBar, TransportBar, drop_hint};
use super::pointer::{Pointer, particle_at};
use super::stepping::{InEffect, News, SimThread};
use super::transport::Transport;
use super::viewport::Viewport;

/// Smoothed per-frame statistics.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    /// UI frames per second.
    pub fps: f64,
    /// Milliseconds of simulation per simulated frame, by phase.
    pub phase_ms: Vec<(&'static str, f64)>,
}

/// How long "slower than real time" stays shown after the simulation last fell behind.
const BEHIND_SHOWN: Duration = Duration::from_secs(1);

/// The 3D view: how it is drawn and looked at.
pub struct ViewState {
    pub camera: OrbitCamera,
    pub options: RenderOptions,
    /// Antialiasing: MSAA samples per pixel of the 3D view (the quality setting; 1 is the
    /// fastest on a software adapter).
    pub samples: u32,
    /// The MSAA counts the adapter supports, ascending.
    sample_choices: Vec<u32>,
    /// Width / height of the 3D view when last drawn, for framing the camera.
    aspect: f32,
    /// Where the 3D view was last drawn, in points.
    rect: Option<egui::Rect>,
    render_state: Option<egui_wgpu::RenderState>,
    /// "name (backend, type)" of the adapter drawing the view, shown in the status bar.
    adapter: Option<String>,
    pub(super) viewport: Option<Viewport>,
    /// The GPU backend's display buffer (on the view's device), drawn from while the
    /// stepping copy runs on the GPU: the view then reads nothing back.
    gpu_display: Option<wgpu::Buffer>,
    /// The view was last drawn from `gpu_display`.
    drawn_from_gpu: bool,
    pointer: Pointer,
    /// Print each UI frame's wall time to stderr (`frame_ms …`; the window sets it from
    /// `CLOTHSIM_FRAME_TIMES`), for measuring frame rates.
    pub log_frame_times: bool,
}

/// Captures and recordings, and the thread that writes them.
pub struct Recording {
    /// Where captures and recordings go.
    pub capture_dir: PathBuf,
    pub(super) capture_requested: bool,
    /// The folder of a PNG sequence being recorded, and its next frame number.
    pub(super) sequence: Option<(PathBuf, u64)>,
    /// The GIF being recorded and when its last frame was drawn.
    pub(super) gif: Option<(PathBuf, Option<Instant>)>,
    pub(super) writer: PngWriter,
}

/// Files being opened, and the cloth the user opened.
#[derive(Default)]
pub struct Loading {
    pub(super) load: Option<Load>,
    /// A cloth the user opened (unplaced, with its name): a scenario switch places it again.
    /// `None`: each scene brings its own cloth.
    pub(super) custom_cloth: Option<(MeshBuild, String)>,
    /// An OBJ dropped on the window, waiting for the user to say whether it is the cloth or
    /// an obstacle.
    pub(super) dropped_obj: Option<PathBuf>,
}

/// The window's panels.
#[derive(Default)]
pub struct Panels {
    pub transport: TransportBar,
    pub status: StatusBar,
    pub side: SidePanel,
}

/// The eframe application.
pub struct ClothApp {
    /// The UI's replica of the simulation: what is shown and edited. The copy that steps
    /// lives on its own thread (see [`super::stepping`]). Read it through
    /// [`ClothApp::sim`]; change it only through [`ClothApp::edit`] (and
    /// [`ClothApp::replace_sim`] for a new scene), which change both copies alike.
    sim: Simulation,
    stepping: SimThread,
    /// What the stepping copy has in effect (backend, substeps, integrator).
    in_effect: InEffect,
    /// When the simulation last ran slower than real time.
    last_behind: Option<Instant>,
    pub transport: Transport,
    pub view: ViewState,
    pub recording: Recording,
    pub(super) loading: Loading,
    pub messages: Vec<Message>,
    pub stats: Stats,
    pub(super) last_update: Option<Instant>,
    pub panels: Panels,
    /// The accuracy-versus-cost sweep of the current scene.
    pub accuracy: AccuracyWindow,
    /// The intersection check after every frame, where the user turned it on.
    pub check: IntersectionCheck,
}

impl ClothApp {
    /// Creates the app on the GUI's wgpu device (`None` shows no 3D view, e.g. without a GPU
    /// renderer), starting with `obj` if given.
    pub fn new(render_state: Option<egui_wgpu::RenderState>, obj: Option<&Path>) -> Self {
        let scene = Scene::builtin("hanging").unwrap_or_else(|e| unreachable!("{e}"));
        let sim = Simulation::new(scene);
        let camera = view::default_camera(&sim, DEFAULT_ASPECT);
        let stepping = SimThread::start(sim.fork());
        let mut app = Self {
            in_effect: stepping.in_effect(),
            stepping,
            last_behind: None,
            sim,
            transport: Transport::default(),
            view: ViewState {
                camera,
                options: RenderOptions::default(),
                samples: render_state.as_ref().map_or(1, default_samples),
                sample_choices: render_state.as_ref().map_or_else(
                    || vec![1],
                    |rs| crate::render::supported_sample_counts(&rs.adapter),
                ),
                aspect: DEFAULT_ASPECT,
                rect: None,
                adapter: render_state
                    .as_ref()
                    .map(|rs| crate::device::describe_adapter(&rs.adapter)),
                render_state,
                viewport: None,
                gpu_display: None,
                drawn_from_gpu: false,
                pointer: Pointer::default(),
                log_frame_times: false,
            },
            recording: Recording {
                capture_dir: std::env::current_dir().unwrap_or_else(|_| PathBuf::from(".")),
                capture_requested: false,
                sequence: None,
                gif: None,
                writer: PngWriter::default(),
            },
            loading: Loading::default(),
            messages: Vec::new(),
            stats: Stats::default(),
            last_update: None,
            panels: Panels::default(),
            accuracy: AccuracyWindow::default(),
            check: IntersectionCheck::default(),
        };
        if app.view.render_state.is_none() {
            app.message(
                Level::Warning,
                "no wgpu renderer: the 3D view and capture are unavailable".into(),
            );
        }
        if let Some(path) = obj {
            app.open_path(path.to_path_buf());
        }
        app
    }

    pub fn message(&mut self, level: Level, text: String) {
        match level {
            Level::Error => log::error!("{text}"),
            Level::Warning => log::warn!("{text}"),
            Level::Info => log::info!("{text}"),
        }
        self.messages.push(Message { level, text });
        if self.messages.len() > 50 {
            self.messages.remove(0);
        }
    }

    /// The last error message, if any.
    pub fn last_error(&self) -> Option<&str> {
        self.messages
            .iter()
            .rev()
            .find(|m| m.level == Level::Error)
            .map(|m| m.text.as_str())
    }

    /// The adapter drawing the 3D view, if any.
    pub fn adapter(&self) -> Option<&str> {
        self.view.adapter.as_deref()
    }

    pub fn cloth_name(&self) -> &str {
        self.sim.cloth_name()
    }

    /// The simulation as the UI shows it: its scene, parameters and effects, and the
    /// latest state the stepping thread finished.
    pub fn sim(&self) -> &Simulation {
        &self.sim
    }

    /// What the stepping simulation has in effect: its backend, and the substeps and
    /// integrator the stability guard left in force.
    pub fn in_effect(&self) -> InEffect {
        self.in_effect
    }

    /// Applies `change` to the UI's replica now and to the stepping copy after everything
    /// sent before it (the same change on the same data: the two stay equal).
    /// Returns what the change returned on the replica.
    pub(super) fn edit<R>(&mut self, change: impl Fn(&mut Simulation) -> R + Send + 'static) -> R {
        self.send_edit(change, false)
    }

    /// As [`ClothApp::edit`], for a change that replaces the state outright (a reset): no
    /// state stepped before it is shown afterwards.
    fn edit_state<R>(&mut self, change: impl Fn(&mut Simulation) -> R + Send + 'static) -> R {
        self.send_edit(change, true)
    }

    fn send_edit<R>(
        &mut self,
        change: impl Fn(&mut Simulation) -> R + Send + 'static,
        replaces_state: bool,
    ) -> R {
        let out = change(&mut self.sim);
        let job: super::stepping::Edit = Box::new(move |s| {
            change(s);
            None
        });
        if replaces_state {
            self.send_new_run(job);
        } else {
            let sent = self.stepping.edit(job);
            self.report_sent(sent);
        }
        out
    }

    /// Sends `job`, which replaces the state outright: nothing the run before it stepped is
    /// shown afterwards, neither its states nor what the intersection check found in it.
    fn send_new_run(&mut self, job: super::stepping::Edit) {
        self.check.restart();
        let sent = self.stepping.edit_state(job);
        self.report_sent(sent);
    }

    /// Makes `sim` the simulation, shown and stepped from its state (a new scene or cloth).
    pub(super) fn replace_sim(&mut self, sim: Simulation) {
        let copy = sim.fork();
        self.sim = sim;
        // The new copy steps on the CPU.
        self.view.gpu_display = None;
        self.send_new_run(Box::new(move |s| {
            *s = copy;
            None
        }));
    }

    pub(super) fn report_sent(&mut self, sent: Result<(), String>) {
        if let Err(e) = sent {
            self.transport.pause();
            self.message(Level::Error, e);
        }
    }

    /// Plays or pauses; pausing drops the frames already due.
    pub fn set_playing(&mut self, playing: bool) {
        if playing {
            self.transport.playing = true;
        } else {
            self.transport.pause();
            let sent = self.stepping.hold();
            self.report_sent(sent);
        }
    }

    /// Waits until the stepping thread has done everything asked of it and shows the
    /// result (tests; anything that must see a step's outcome at once).
    pub fn settle(&mut self) {
        self.stepping.settle();
        self.poll_stepping();
    }

    /// Where the 3D view was last drawn, in points (`None` before the first frame or
    /// without a renderer).
    pub fn view_rect(&self) -> Option<egui::Rect> {
        self.view.rect
    }

    /// Whether the user opened a cloth that replaces each scene's own.
    pub fn has_custom_cloth(&self) -> bool {
        self.loading.custom_cloth.is_some()
    }

    pub fn is_loading(&self) -> bool {
        self.loading.load.is_some()
    }

    /// Switches scenario. A cloth the user opened is kept; otherwise the scene brings its
    /// own. Parameters and effects become the scenario's; the camera frames the new scene.
    pub fn set_scenario(&mut self, name: &str) {
        let scene = match &self.loading.custom_cloth {
            Some((cloth, cloth_name)) => Scene::with_cloth(name, cloth, cloth_name),
            None => Scene::builtin(name),
        };
        match scene {
            Ok(scene) => {
                self.replace_sim(Simulation::new(scene));
                self.reset_camera();
                self.recording.sequence = None;
            }
            Err(e) => self.message(Level::Error, e.to_string()),
        }
    }

    /// Moves the simulation to the CPU or the GPU (the view's device), keeping its state. A
    /// scene the GPU cannot run is refused with the reason and stays on the CPU.
    pub fn set_backend(&mut self, backend: crate::gpu::Backend) {
        use crate::gpu::{Backend, GpuStepper};
        match backend {
            Backend::Cpu => {
                self.view.gpu_display = None;
                let sent = self.stepping.edit(Box::new(|s| {
                    (s.use_cpu().err()).map(|e| format!("{e}; staying on the GPU"))
                }));
                self.report_sent(sent);
                self.message(Level::Info, "stepping on the CPU".into());
            }
            Backend::Gpu => {
                let Some(rs) = &self.view.render_state else {
                    self.message(
                        Level::Error,
                        "no wgpu device: the GPU backend is unavailable".into(),
                    );
                    return;
                };
                let (model, params, effects) =
                    (self.sim.model(), self.sim.params(), self.sim.effects());
                // Not read back every frame: the view draws from the stepper's display buffer.
                match GpuStepper::new(&rs.device, &rs.queue, model, params, effects, false) {
                    Ok(mut stepper) => {
                        self.view.gpu_display = Some(stepper.display_buffer());
                        // The stepping copy moves to the GPU; the replica never steps.
                        let sent = self.stepping.edit(Box::new(move |s| {
                            s.set_backend(Box::new(stepper))
                                .err()
                                .map(|e| e.to_string())
                        }));
                        self.report_sent(sent);
                        let text =
                            format!("stepping on the GPU ({})", self.adapter().unwrap_or("wgpu"));
                        self.message(Level::Info, text);
                    }
                    Err(e) => self.message(Level::Error, format!("{e}; staying on the CPU")),
                }
            }
        }
    }

    /// Frames the current scene with its default camera.
    pub fn reset_camera(&mut self) {
        self.view.camera = view::default_camera(&self.sim, self.view.aspect);
    }

    /// Applies edited parameters to the running simulation; a bad value is reported and
    /// the previous parameters stay.
    pub fn apply_params(&mut self, params: SimParams) {
        if let Err(e) = self.edit(move |s| s.set_params(params.clone())) {
            self.message(Level::Error, e.to_string());
        }
    }

    /// Applies an edited effect list (collider settings) to the running simulation; a
    /// refused list (a self-collision thickness the cloth cannot take) is reported and the
    /// effects stay as they were.
    pub fn apply_effects(&mut self, effects: Vec<Effect>) {
        match self.edit(move |s| s.set_effects(effects.clone())) {
            Ok(warnings) => {
                for warning in warnings {
                    self.message(Level::Warning, warning);
                }
            }
            Err(e) => self.message(Level::Error, format!("{e}; the effects are kept")),
        }
    }

    /// Turns the scene's pins on or off.
    pub fn set_pins_enabled(&mut self, enabled: bool) {
        self.edit(move |s| s.set_pins_enabled(enabled));
    }

    /// Back to each scene's own cloth.
    pub fn use_default_cloth(&mut self) {
        self.loading.custom_cloth = None;
        let scenario = self.sim.scenario().to_string();
        self.set_scenario(&scenario);
    }

    pub fn reset(&mut self) {
        self.edit_state(Simulation::reset);
    }

    /// Pauses and advances exactly one simulation frame.
    pub fn step_once(&mut self) {
        self.set_playing(false);
        let sent = self.stepping.advance(1);
        self.report_sent(sent);
    }

    /// Shows what the stepping thread finished: its latest state, the guard's events, a
    /// frame that failed (which pauses), and the timings.
    pub(super) fn poll_stepping(&mut self) {
        let sim = &mut self.sim;
        let (news, in_effect) = self
            .stepping
            .take(|state, frames| sim.adopt_state(state, frames));
        let News {
            stepped,
            timings,
            guard_events,
            failed,
            notes,
            behind,
            checked,
            ..
        } = news;
        self.check.take(checked);
        let forced_before = self.in_effect.forced;
        self.in_effect = in_effect;
        if in_effect.forced > forced_before
            && let Some(m) = forced_pairs(self.messages.last_mut(), in_effect.forced)
        {
            self.message(m.level, m.text);
        }
        for event in guard_events {
            let level = match event.action {
                GuardAction::Recovered | GuardAction::Raised { .. } => Level::Info,
                GuardAction::Refined | GuardAction::FellBack { .. } => Level::Warning,
                // The failure below says it.
                GuardAction::GaveUp => continue,
            };
            self.message(level, format!("stability guard: {event}"));
        }
        for note in notes {
            self.message(Level::Error, note);
        }
        if let Some(failed) = failed {
            self.set_playing(false);
            self.message(Level::Error, failed);
        }
        if stepped > 0 {
            self.record_timings(timings, stepped);
        }
        let now = Instant::now();
        if behind && self.transport.playing {
            self.last_behind = Some(now);
        }
        self.transport.behind = self.transport.playing
            && self
                .last_behind
                .is_some_and(|t| now.duration_since(t) < BEHIND_SHOWN);
    }

    fn record_timings(&mut self, timings: PhaseTimings, frames: u32) {
        let new: Vec<(&'static str, f64)> = timings
            .phases()
            .iter()
            .map(|p| (p.name, p.time.as_secs_f64() * 1e3 / frames as f64))
            .collect();
        // Exponential smoothing so the numbers are readable; phases that stopped running vanish.
        let old = std::mem::take(&mut self.stats.phase_ms);
        self.stats.phase_ms = new
            .into_iter()
            .map(|(name, ms)| {
                let prev = old.iter().find(|(n, _)| *n == name).map_or(ms, |(_, p)| *p);
                (name, 0.8 * prev + 0.2 * ms)
            })
            .collect();
    }

    /// The MSAA count in use: the one asked for, or the largest supported below it (1 if
    /// none is).
    pub fn samples_in_use(&self) -> u32 {
        let fits = (self.view.sample_choices.iter()).filter(|&&n| n <= self.view.samples);
        fits.max().copied().unwrap_or(1)
    }

    /// Whether the 3D view was last drawn straight from the GPU backend's buffer (the
    /// stepping copy runs on the GPU; nothing was read back to draw it).
    pub fn drawn_from_gpu(&self) -> bool {
        self.view.drawn_from_gpu
    }

    /// MSAA samples of the 3D view as last drawn (`None` before the first draw or without a
    /// renderer).
    pub fn view_samples(&self) -> Option<u32> {
        self.view.viewport.as_ref().map(Viewport::samples)
    }

    /// Draws the 3D view into the available space and handles capture.
    fn viewport_ui(&mut self, ui: &mut egui::Ui) {
        let Some(rs) = self.view.render_state.clone() else {
            ui.centered_and_justified(|ui| ui.label("No wgpu renderer: 3D view unavailable."));
            return;
        };
        let size = ui.available_size();
        let ppp = ui.ctx().pixels_per_point();
        let (w, h) = (
            ((size.x * ppp).round() as u32).max(1),
            ((size.y * ppp).round() as u32).max(1),
        );
        // A new quality setting takes a new target (and pipelines for it).
        let samples = self.samples_in_use();
        if let Some(old) = self.view.viewport.take_if(|v| v.samples() != samples) {
            // (Its image would stay shown, and its target alive, until the new one replaces it.)
            old.free(&rs);
        }
        if self.view.viewport.is_none() {
            match Viewport::new(&rs, w, h, samples) {
                Ok(v) => self.view.viewport = Some(v),
                Err(e) => {
                    ui.label(format!("3D view unavailable: {e}"));
                    return;
                }
            }
        }
        let Some(viewport) = self.view.viewport.as_mut() else {
            return;
        };
        self.view.aspect = w as f32 / h as f32;
        let mut frame = view::frame(&self.sim);
        if self.in_effect.on_gpu() {
            frame.device_positions = self
                .view
                .gpu_display
                .as_ref()
                .map(|buffer| DevicePositions {
                    buffer,
                    stride: crate::gpu::GpuStepper::DISPLAY_STRIDE,
                });
        }
        self.view.drawn_from_gpu = frame.device_positions.is_some();
        if let Err(e) = viewport.draw(&rs, w, h, &frame, &self.view.camera, &self.view.options) {
            ui.label(format!("3D view: {e}"));
            return;
        }
        let (rect, response) = ui.allocate_exact_size(size, egui::Sense::click_and_drag());
        viewport.paint(ui.painter(), rect);
        self.view.rect = Some(response.rect);
        if Pointer::presses(ui, &response) {
            self.catch_up();
        }
        let mut actions = Vec::new();
        let view = &mut self.view;
        (view.pointer).input(ui, &response, &mut view.camera, &self.sim, &mut actions);
        self.apply_all(actions);
        self.capture_drawn(&rs);
    }

    /// Draws one of the panels (`which` picks it) from what the window shows, then carries
    /// out what it asked for.
    fn show_panel(&mut self, ui: &mut egui::Ui, which: fn(&mut Panels) -> &mut dyn Panel) {
        let mut actions = Vec::new();
        let status = Status {
            in_effect: self.in_effect,
            playing: self.transport.playing,
            speed: self.transport.speed,
            behind: self.transport.behind,
            fps: self.stats.fps,
            phase_ms: &self.stats.phase_ms,
            adapter: self.view.adapter.as_deref(),
            message: self.messages.last(),
            loading: self.loading.load.is_some(),
            recording: self.recording.sequence.is_some(),
            recording_gif: self.recording.gif.is_some(),
            custom_cloth: self.loading.custom_cloth.is_some(),
            samples_in_use: self.samples_in_use(),
            sample_choices: &self.view.sample_choices,
            check: (self.check.is_on(), self.check.found()),
        };
        let mut ctx = PanelContext::new(&self.sim, status, &mut self.view.options, &mut actions);
        which(&mut self.panels).ui(ui, &mut ctx);
        self.apply_all(actions);
    }

    fn apply_all(&mut self, actions: Vec<Action>) {
        for action in actions {
            self.apply(action);
        }
    }

    /// Does what a panel or the pointer asked for, through the functions that keep the
    /// window's copy of the simulation and the stepping copy in step.
    pub fn apply(&mut self, action: Action) {
        match action {
            Action::SetPlaying(playing) => self.set_playing(playing),
            Action::StepOnce => self.step_once(),
            Action::Reset => self.reset(),
            Action::SetSpeed(speed) => self.transport.speed = speed,
            Action::Capture => self.request_capture(),
            Action::OpenAccuracy => self.accuracy.open = true,
            Action::ToggleRecording => self.toggle_recording(),
            Action::ToggleGif => self.toggle_gif(),
            Action::SetScenario(name) => self.set_scenario(&name),
            Action::Open(path) => self.open_path(path),
            Action::UseDefaultCloth => self.use_default_cloth(),
            Action::SaveScene(path) => self.save_scene(&path),
            Action::AddObstacle(path) => self.add_obstacle(&path),
            Action::ExportObj => self.export_obj(),
            Action::SetPinsEnabled(enabled) => self.set_pins_enabled(enabled),
            Action::SetBackend(backend) => self.set_backend(backend),
            Action::ApplyParams(params) => self.apply_params(params),
            Action::ApplyEffects(effects) => self.apply_effects(effects),
            Action::SetSamples(samples) => self.view.samples = samples,
            Action::ResetCamera => self.reset_camera(),
            Action::DismissMessages => self.messages.clear(),
            Action::CheckIntersections(on) => self.check.set(on, &self.stepping),
            Action::TogglePin(p) => self.edit(move |s| s.toggle_pin(p)),
            Action::Grab { particle, target } => self.edit(move |s| s.grab(particle, target)),
            Action::Release => self.edit(Simulation::release),
            Action::Tell(level, text) => self.message(level, text),
        }
    }

    /// The particle under the pointer at `at` in the view `rect`, and where it is.
    pub fn particle_at(&self, rect: egui::Rect, at: egui::Pos2) -> Option<(u32, glam::Vec3)> {
        particle_at(&self.view.camera, &self.sim, rect, at)
    }

    /// Before picking or exporting: on the GPU backend the replica's state is read back only
    /// now and then (the view draws from the GPU's buffer); bring it to the latest frame so
    /// the pointer picks, and an export writes, the cloth as it is drawn. One read-back.
    pub(super) fn catch_up(&mut self) {
        if self.in_effect().on_gpu() {
            let sent = self.stepping.catch_up();
            self.report_sent(sent);
            self.poll_stepping();
        }
    }

    /// One UI frame: input, simulation, panels, viewport.
    pub fn frame_ui(&mut self, ui: &mut egui::Ui) {
        let now = Instant::now();
        let wall_dt = self
            .last_update
            .map_or(0.0, |t| now.duration_since(t).as_secs_f64());
        self.last_update = Some(now);
        if wall_dt > 0.0 {
            self.stats.fps = 0.9 * self.stats.fps + 0.1 / wall_dt;
        }
        if self.view.log_frame_times {
            eprintln!("frame_ms {:.2}", wall_dt * 1000.0);
        }

        let dropped: Vec<PathBuf> = ui.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .collect()
        });
        if let Some(path) = dropped.into_iter().next() {
            // A scene file replaces the scene; an OBJ could be the cloth or an obstacle.
            if path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
            {
                self.open_path(path);
            } else {
                self.loading.dropped_obj = Some(path);
            }
        }
        self.poll_loading();
        self.poll_writes();

        self.poll_stepping();
        let due = self
            .transport
            .credit(wall_dt, self.sim.params().step.dt as f64);
        if due > 0 {
            let sent = self.stepping.advance(due);
            self.report_sent(sent);
        }

        // The window's clear colour is the panels' fill (`clear_color`), so the panels
        // paint none of their own: on a software adapter that is a third of egui's cost.
        let frame = egui::Frame::side_top_panel(ui.style()).fill(egui::Color32::TRANSPARENT);
        egui::Panel::top("transport")
            .frame(frame)
            .show(ui, |ui| self.show_panel(ui, |p| &mut p.transport));
        egui::Panel::bottom("status")
            .frame(frame)
            .show(ui, |ui| self.show_panel(ui, |p| &mut p.status));
        egui::Panel::left("controls")
            .frame(frame)
            .resizable(true)
            .default_size(300.0)
            .show(ui, |ui| self.show_panel(ui, |p| &mut p.side));
        egui::CentralPanel::no_frame().show(ui, |ui| self.viewport_ui(ui));
        self.accuracy_ui(ui.ctx());
        self.dropped_obj_ui(ui.ctx());

        let hovering = ui.input(|i| !i.raw.hovered_files.is_empty());
        if hovering {
            drop_hint(ui);
        }
        let busy = self.loading.load.is_some()
            || self.recording.writer.pending() > 0
            || self.accuracy.is_running();
        if self.transport.playing || busy {
            ui.ctx().request_repaint();
        } else {
            ui.ctx().request_repaint_after(Duration::from_millis(250));
        }
    }

    /// The Accuracy window: collects a finished sweep, starts one, applies a choice.
    fn accuracy_ui(&mut self, ctx: &egui::Context) {
        self.accuracy.poll();
        if !self.accuracy.open {
            return;
        }
        let (apply, start) = self.accuracy.ui(ctx, self.sim.params());
        match start {
            Some(Start::Sweep) => self.accuracy.start(self.sim.to_scene()),
            Some(Start::Question(q)) => self.accuracy.ask(q, self.sim.to_scene()),
            None => {}
        }
        if let Some(params) = apply {
            let text = format!(
                "applied {} with {} substeps per frame",
                params.step.integrator.label(),
                params.step.substeps
            );
            self.apply_params(params);
            self.message(Level::Info, text);
        }
    }

    /// Finishes queued PNG writes and frees GPU resources registered with egui.
    pub fn shutdown(&mut self) {
        // Quitting right after a capture or while recording must not lose frames.
        self.finish_writes();
        if let (Some(v), Some(rs)) = (self.view.viewport.take(), &self.view.render_state) {
            v.free(rs);
        }
    }
}

impl eframe::App for ClothApp {
    /// The panels' fill: the panels are drawn without one (see `frame_ui`).
    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        visuals.panel_fill.to_normalized_gamma_f32()
    }

    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.frame_ui(ui);
    }

    fn on_exit(&mut self) {
        self.shutdown();
    }
}

/// MSAA samples asked for at start on a GPU.
const DEFAULT_SAMPLES: u32 = 4;

/// MSAA samples asked for at start: [`DEFAULT_SAMPLES`] on a GPU, none on a software
/// adapter (llvmpipe), where 4× adds about half again to a frame (1280 × 720:
/// 27 against 36 frames per second; 2× costs the same as 4× there). The View panel's
/// Antialiasing setting changes it either way.
fn default_samples(rs: &egui_wgpu::RenderState) -> u32 {
    if rs.adapter.get_info().device_type == wgpu::DeviceType::Cpu {
        1
    } else {
        DEFAULT_SAMPLES
    }
}

/// Width / height assumed for framing before the 3D view was first drawn.
const DEFAULT_ASPECT: f32 = 1.4;
