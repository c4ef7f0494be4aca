//! The Accuracy window: the same sweep as `clothsim accuracy`, for the current scene, on a
//! background thread while the viewport keeps running; its plot, its table, and a button
//! that applies the cheapest integrator and substeps for a typed tolerance.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, channel};
use std::sync::{Arc, Mutex};

use egui::{Color32, RichText};
use egui_plot::{HLine, Legend, Line, LineStyle, Plot, PlotPoints, Points};

use super::accuracy_extras::{Extras, Question};
use crate::report::{
    AccuracyReport, Progress, ReportError, SweepConfig, integrator_color, recommend, sweep,
};
use crate::scene::Scene;
use crate::sim::{IntegratorKind, SimParams};

/// What the window asks to start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    Sweep,
    Question(Question),
}

/// A sweep running on its own thread.
struct Job {
    progress: Arc<Mutex<Progress>>,
    cancel: Arc<AtomicBool>,
    result: Receiver<Result<AccuracyReport, ReportError>>,
}

/// The window's state.
pub struct AccuracyWindow {
    pub open: bool,
    /// The sweep the window runs (the CLI's defaults, on one thread).
    pub config: SweepConfig,
    job: Option<Job>,
    /// The stability map and small steps, when asked.
    pub extras: Extras,
    pub report: Option<AccuracyReport>,
    /// Tolerance the user typed, as a fraction of the cloth's size.
    pub tolerance: f64,
    pub error: Option<String>,
}

impl Default for AccuracyWindow {
    fn default() -> Self {
        Self {
            open: false,
            config: SweepConfig {
                parallel_reference: false,
                ..SweepConfig::default()
            },
            job: None,
            extras: Extras::default(),
            report: None,
            tolerance: crate::report::DEFAULT_TOLERANCE,
            error: None,
        }
    }
}

impl AccuracyWindow {
    /// The sweep's configuration for `scene`: the window's, or, left as it came, the scene's
    /// own (the `orders` scene's spans the steps its orders need); one thread.
    fn config_for(&self, scene: &Scene) -> SweepConfig {
        let base = if self.config == Self::default().config {
            SweepConfig {
                parallel_reference: false,
                ..SweepConfig::for_scene(&scene.scenario)
            }
        } else {
            self.config.clone()
        };
        SweepConfig {
            tolerance: self.tolerance,
            ..base
        }
    }

    /// Asks the stability map or small steps about `scene` in the background.
    pub fn ask(&mut self, question: Question, scene: Scene) {
        let config = self.config_for(&scene);
        self.extras.start(question, scene, config);
    }

    /// Starts a sweep of `scene` in the background (one thread, so the viewport keeps a core).
    pub fn start(&mut self, scene: Scene) {
        let progress = Arc::new(Mutex::new(Progress {
            done: 0,
            total: 1,
            what: "starting".into(),
        }));
        let cancel = Arc::new(AtomicBool::new(false));
        let (tx, rx) = channel();
        let config = self.config_for(&scene);
        let (p, c) = (progress.clone(), cancel.clone());
        std::thread::spawn(move || {
            let result = sweep(&scene, &config, &mut |now| {
                if let Ok(mut slot) = p.lock() {
                    *slot = now.clone();
                }
                !c.load(Ordering::Relaxed)
            });
            let _ = tx.send(result);
        });
        self.error = None;
        self.job = Some(Job {
            progress,
            cancel,
            result: rx,
        });
    }

    pub fn is_running(&self) -> bool {
        self.job.is_some() || self.extras.is_running()
    }

    /// Asks a running sweep to stop.
    pub fn cancel(&mut self) {
        if let Some(job) = &self.job {
            job.cancel.store(true, Ordering::Relaxed);
        }
    }

    /// Collects a finished sweep or question.
    pub fn poll(&mut self) {
        self.extras.poll();
        let Some(job) = &self.job else { return };
        if let Ok(result) = job.result.try_recv() {
            match result {
                Ok(report) => self.report = Some(report),
                Err(e) => self.error = Some(e.to_string()),
            }
            self.job = None;
        }
    }

    /// Waits for a running sweep and question (tests).
    pub fn wait(&mut self) {
        self.extras.wait();
        if let Some(job) = self.job.take() {
            match job.result.recv() {
                Ok(Ok(report)) => self.report = Some(report),
                Ok(Err(e)) => self.error = Some(e.to_string()),
                Err(e) => self.error = Some(e.to_string()),
            }
        }
    }

    /// The cheapest measured point within the typed tolerance.
    pub fn choice(&self) -> Option<&crate::report::Point> {
        let report = self.report.as_ref()?;
        recommend(&report.points, self.tolerance).map(|i| &report.points[i])
    }

    /// `params` with the chosen integrator and the substeps that give its step at `params.step.dt`.
    pub fn applied(&self, params: &SimParams) -> Option<SimParams> {
        let p = self.choice()?;
        let substeps = (params.step.dt as f64 / p.dt).round().max(1.0) as u32;
        let mut applied = params.clone();
        applied.step.integrator = p.integrator;
        applied.step.substeps = substeps;
        Some(applied)
    }

    /// Draws the window; returns parameters to apply when the user asked for it, and
    /// whether a sweep should start.
    pub fn ui(
        &mut self,
        ctx: &egui::Context,
        params: &SimParams,
    ) -> (Option<SimParams>, Option<Start>) {
        let mut apply = None;
        let mut start = None;
        let mut open = self.open;
        egui::Window::new("Accuracy")
            .open(&mut open)
            .default_size([720.0, 560.0])
            .show(ctx, |ui| {
                ui.label("Error against a reference trajectory (RK4 at the step it is surest at) and counted work (force evaluations, CG iterations, sweeps), for every integrator and step size, on the current scene. The `orders` scene shows every method's order of accuracy.");
                ui.horizontal(|ui| {
                    if let Some(job) = &self.job {
                        let p = job.progress.lock().map(|p| p.clone()).unwrap_or(Progress { done: 0, total: 1, what: String::new() });
                        ui.add(egui::ProgressBar::new(p.done as f32 / p.total.max(1) as f32).text(p.what).desired_width(380.0));
                        if ui.button("Cancel").clicked() {
                            self.cancel();
                        }
                    } else if ui.button("Run sweep").clicked() {
                        start = Some(Start::Sweep);
                    }
                });
                if let Some(e) = &self.error {
                    ui.label(RichText::new(e).color(Color32::from_rgb(240, 80, 70)));
                }
                ui.horizontal(|ui| {
                    ui.label("Tolerance");
                    let mut percent = self.tolerance * 100.0;
                    if ui
                        .add(egui::DragValue::new(&mut percent).range(1e-4..=100.0).speed(0.01).suffix(" % of cloth size"))
                        .changed()
                    {
                        self.tolerance = percent / 100.0;
                    }
                    match self.choice() {
                        Some(p) => {
                            ui.label(format!("use {} at {:.0} substeps per frame", p.integrator.label(), params.step.dt as f64 / p.dt));
                            if ui.button("Apply").clicked() {
                                apply = self.applied(params);
                            }
                        }
                        None if self.report.is_some() => {
                            ui.label("no measured run is that accurate");
                        }
                        None => {}
                    }
                });
                if let Some(question) = self.extras.ui(ui) {
                    start = Some(Start::Question(question));
                }
                if let Some(report) = &self.report {
                    plot(ui, report, self.tolerance);
                    orders(ui, report);
                    table(ui, report);
                }
            });
        self.open = open;
        (apply, start)
    }
}

fn plot(ui: &mut egui::Ui, report: &AccuracyReport, tolerance: f64) {
    let log = |x: f64| x.max(1e-300).log10();
    Plot::new("accuracy plot")
        .height(300.0)
        .legend(Legend::default())
        .x_axis_label("log10 of cost (work per simulated s, in force evaluations)")
        .y_axis_label("log10 of max error / cloth size")
        .x_axis_formatter(|m, _| format!("1e{:.0}", m.value))
        .y_axis_formatter(|m, _| format!("1e{:.0}", m.value))
        .show(ui, |plot_ui| {
            plot_ui.hline(
                HLine::new("tolerance", log(tolerance))
                    .color(Color32::from_rgb(220, 60, 50))
                    .style(LineStyle::dashed_loose())
                    .width(2.0),
            );
            let floor = report.reference.check_max;
            if floor.is_finite() && floor > 0.0 {
                plot_ui.hline(
                    HLine::new("reference uncertainty", log(floor))
                        .color(Color32::LIGHT_GRAY)
                        .style(LineStyle::dotted_dense())
                        .width(1.5),
                );
            }
            let frontier: Vec<[f64; 2]> = report
                .frontier
                .iter()
                .map(|&i| {
                    [
                        log(report.points[i].work_per_sim_s),
                        log(report.points[i].judged_error().0),
                    ]
                })
                .collect();
            plot_ui.line(
                Line::new("frontier", PlotPoints::from(frontier))
                    .width(6.0)
                    .color(Color32::from_white_alpha(60)),
            );
            for kind in IntegratorKind::ALL {
                let (r, g, b) = integrator_color(kind);
                let color = Color32::from_rgb(r, g, b);
                let mut mine: Vec<(bool, [f64; 2])> = report
                    .points
                    .iter()
                    // An error of exactly zero is the reference's own run: no point on a
                    // log scale.
                    .filter(|p| p.integrator == kind && p.stable && p.judged_error().0 > 0.0)
                    .map(|p| {
                        (
                            p.resolved(),
                            [log(p.work_per_sim_s), log(p.judged_error().0)],
                        )
                    })
                    .collect();
                mine.sort_by(|a, b| a.1[0].total_cmp(&b.1[0]));
                if !mine.is_empty() {
                    let line: Vec<[f64; 2]> = mine.iter().map(|m| m.1).collect();
                    plot_ui.line(
                        Line::new(kind.name(), PlotPoints::from(line))
                            .color(color)
                            .width(2.0),
                    );
                    // Resolved errors filled, those lost in the floor hollow.
                    for resolved in [true, false] {
                        let some: Vec<[f64; 2]> = (mine.iter())
                            .filter(|m| m.0 == resolved)
                            .map(|m| m.1)
                            .collect();
                        plot_ui.points(
                            Points::new(kind.name(), PlotPoints::from(some))
                                .color(color)
                                .filled(resolved)
                                .radius(3.0),
                        );
                    }
                }
            }
        });
}

/// Each integrator's observed order of accuracy, beside the order its method has.
fn orders(ui: &mut egui::Ui, report: &AccuracyReport) {
    egui::CollapsingHeader::new("Orders of accuracy")
        .default_open(true)
        .show(ui, |ui| {
            egui::Grid::new("accuracy orders")
                .striped(true)
                .show(ui, |ui| {
                    for head in ["integrator", "order", "observed", "over"] {
                        ui.label(RichText::new(head).strong());
                    }
                    ui.end_row();
                    for limit in &report.limits {
                        ui.label(limit.integrator.label());
                        ui.label(limit.integrator.order().to_string());
                        match limit.observed_order {
                            Some(o) => {
                                ui.label(format!("{:.2}", o.order));
                                ui.label(format!("{} steps, {:.1} decades", o.points, o.decades));
                            }
                            None => {
                                ui.label("—");
                                ui.label("too few resolved errors");
                            }
                        }
                        ui.end_row();
                    }
                });
        });
}

fn table(ui: &mut egui::Ui, report: &AccuracyReport) {
    egui::ScrollArea::vertical()
        .max_height(200.0)
        .show(ui, |ui| {
            egui::Grid::new("accuracy table")
                .striped(true)
                .show(ui, |ui| {
                    for head in [
                        "integrator",
                        "dt (s)",
                        "max error",
                        "stable",
                        "work (evals/s)",
                        "wall (s/s)",
                        "evals/step",
                        "CG iters/step",
                        "sweeps/step",
                    ] {
                        ui.label(RichText::new(head).strong());
                    }
                    ui.end_row();
                    for p in &report.points {
                        ui.label(p.integrator.name());
                        ui.label(format!("{:.2e}", p.dt));
                        ui.label(if p.max_error.is_finite() {
                            format!("{:.2e}", p.max_error)
                        } else {
                            "—".into()
                        });
                        ui.label(if p.stable { "yes" } else { "no" });
                        ui.label(format!("{:.3e}", p.work_per_sim_s));
                        ui.label(format!("{:.2e}", p.wall_s_per_sim_s));
                        ui.label(format!("{:.1}", p.force_evals_per_step));
                        ui.label(format!("{:.1}", p.linear_iterations_per_step));
                        ui.label(format!("{:.1}", p.sweeps_per_step));
                        ui.end_row();
                    }
                });
        });
}
