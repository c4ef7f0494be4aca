//! The Accuracy window's two questions beside the sweep, each on its own thread when asked:
//! the stability map (largest stable step against stiffness) and small steps (XPBD's and
//! VBD's substeps against sweeps).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, channel};

use egui::RichText;

use crate::report::{
    MAP_SCALES, ReportError, SmallSteps, StabilityMap, SweepConfig, small_steps, stability_map,
};
use crate::scene::Scene;

/// What a finished question answered.
enum Answer {
    Map(StabilityMap),
    SmallSteps(SmallSteps),
}

/// A question running on its own thread.
struct Job {
    done: Arc<AtomicUsize>,
    total: Arc<AtomicUsize>,
    cancel: Arc<AtomicBool>,
    result: Receiver<Result<Answer, ReportError>>,
}

/// Which question to ask.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Question {
    Map,
    SmallSteps,
}

/// The answers so far, and the question running.
#[derive(Default)]
pub struct Extras {
    pub map: Option<StabilityMap>,
    pub small_steps: Option<SmallSteps>,
    pub error: Option<String>,
    job: Option<Job>,
}

impl Extras {
    /// Asks `question` about `scene` with `config`'s integrators and horizon, on a thread.
    pub fn start(&mut self, question: Question, scene: Scene, config: SweepConfig) {
        let done = Arc::new(AtomicUsize::new(0));
        let total = Arc::new(AtomicUsize::new(1));
        let cancel = Arc::new(AtomicBool::new(false));
        let (tx, rx) = channel();
        let (d, t, c) = (done.clone(), total.clone(), cancel.clone());
        std::thread::spawn(move || {
            let mut progress = |now: usize, all: usize| {
                d.store(now, Ordering::Relaxed);
                t.store(all, Ordering::Relaxed);
                !c.load(Ordering::Relaxed)
            };
            let answer = match question {
                Question::Map => {
                    stability_map(&scene, &config, &MAP_SCALES, &mut progress).map(Answer::Map)
                }
                Question::SmallSteps => {
                    small_steps(&scene, &config, &mut progress).map(Answer::SmallSteps)
                }
            };
            let _ = tx.send(answer);
        });
        self.error = None;
        self.job = Some(Job {
            done,
            total,
            cancel,
            result: rx,
        });
    }

    pub fn is_running(&self) -> bool {
        self.job.is_some()
    }

    fn take(&mut self, result: Result<Answer, ReportError>) {
        match result {
            Ok(Answer::Map(map)) => self.map = Some(map),
            Ok(Answer::SmallSteps(grid)) => self.small_steps = Some(grid),
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    /// Collects a finished question.
    pub fn poll(&mut self) {
        let received = match &self.job {
            Some(job) => job.result.try_recv().ok(),
            None => return,
        };
        if let Some(result) = received {
            self.job = None;
            self.take(result);
        }
    }

    /// Waits for a running question (tests).
    pub fn wait(&mut self) {
        if let Some(job) = self.job.take() {
            match job.result.recv() {
                Ok(result) => self.take(result),
                Err(_) => self.error = Some("the question's thread ended without an answer".into()),
            }
        }
    }

    /// The buttons, the progress and the answers; returns the question to start.
    pub fn ui(&mut self, ui: &mut egui::Ui) -> Option<Question> {
        let mut ask = None;
        ui.horizontal(|ui| match &self.job {
            Some(job) => {
                let (done, total) = (
                    job.done.load(Ordering::Relaxed),
                    job.total.load(Ordering::Relaxed).max(1),
                );
                ui.add(
                    egui::ProgressBar::new(done as f32 / total as f32)
                        .text(format!("{done}/{total}"))
                        .desired_width(240.0),
                );
                if ui.button("Cancel question").clicked() {
                    job.cancel.store(true, Ordering::Relaxed);
                }
            }
            None => {
                if ui
                    .button("Stability map")
                    .on_hover_text(
                        "each integrator's largest stable step, 0.1 to 100 × the stiffness",
                    )
                    .clicked()
                {
                    ask = Some(Question::Map);
                }
                if ui
                    .button("Small steps")
                    .on_hover_text("XPBD and VBD: n substeps of one sweep against one of n sweeps")
                    .clicked()
                {
                    ask = Some(Question::SmallSteps);
                }
            }
        });
        if let Some(e) = &self.error {
            ui.label(RichText::new(e).color(egui::Color32::from_rgb(240, 80, 70)));
        }
        if let Some(grid) = &self.small_steps {
            egui::CollapsingHeader::new("Small steps")
                .default_open(true)
                .show(ui, |ui| {
                    for line in grid.verdict() {
                        ui.label(line);
                    }
                });
        }
        if let Some(map) = &self.map {
            egui::CollapsingHeader::new("Stability map (fewest stable substeps per frame)")
                .default_open(true)
                .show(ui, |ui| map_grid(ui, map));
        }
        ask
    }
}

/// The map as a grid: a row per stiffness, a column per integrator.
fn map_grid(ui: &mut egui::Ui, map: &StabilityMap) {
    egui::Grid::new("stability map")
        .striped(true)
        .show(ui, |ui| {
            ui.label(RichText::new("k (N/m)").strong());
            for p in map.rows().first().copied().unwrap_or_default() {
                ui.label(RichText::new(p.integrator.name()).strong());
            }
            ui.end_row();
            for row in map.rows() {
                ui.label(format!("{:.3}", row[0].stiffness));
                for p in row {
                    ui.label(match p.substeps() {
                        _ if p.at_upper_bound => "any".to_string(),
                        Some(n) => format!("{n:.1}"),
                        None => "none".into(),
                    });
                }
                ui.end_row();
            }
        });
}
