//! "Small steps" on the user's scene (after Macklin et al., *Small Steps in Physics
//! Simulation*, SCA 2019): for XPBD and VBD, substeps and iterations per substep as two axes,
//! and at each budget of sweeps per frame, `n` substeps of one sweep against one step of `n`
//! sweeps.

use std::time::Instant;

use crate::scene::Scene;
use crate::sim::IntegratorKind;

use super::config::SweepConfig;
use super::error::ReportError;
use super::point::Point;
use super::reference::reference;
use super::sweep::measure;

/// Substeps per frame and iterations per substep the grid takes, each: 1 to 32, doubling.
pub const SMALL_STEPS_AXIS: [u32; 6] = [1, 2, 4, 8, 16, 32];

/// One run of the grid.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct GridRun {
    pub substeps: u32,
    pub iterations: u32,
    pub point: Point,
}

/// The grid and its answer.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SmallSteps {
    pub scene: String,
    pub runs: Vec<GridRun>,
    /// Wall-clock seconds it took.
    pub seconds_taken: f64,
}

/// Runs XPBD and VBD over [`SMALL_STEPS_AXIS`]² (substeps per frame × iterations per
/// substep) on `scene` for `config.seconds`, against one reference. Calls
/// `progress(done, total)` after each run; it returns `false` to cancel.
///
/// # Errors
/// [`ReportError::Config`] for a bad configuration, [`ReportError::Cancelled`].
pub fn small_steps(
    scene: &Scene,
    config: &SweepConfig,
    progress: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<SmallSteps, ReportError> {
    let start = Instant::now();
    let scene = &config.in_precision(scene);
    let frame = scene.params.step.dt as f64;
    let most = *SMALL_STEPS_AXIS.iter().max().unwrap_or(&1) as f64;
    // The reference's candidates span the grid's steps.
    let config = SweepConfig {
        dts: vec![frame, frame / most],
        ..config.clone()
    };
    config.validate()?;
    let (trajectory, mut info) = reference(scene, &config);
    info.judge(config.tolerance);
    let kinds = [IntegratorKind::Xpbd, IntegratorKind::Vbd];
    let total = kinds.len() * SMALL_STEPS_AXIS.len() * SMALL_STEPS_AXIS.len();
    let mut runs = Vec::with_capacity(total);
    for integrator in kinds {
        for &substeps in &SMALL_STEPS_AXIS {
            for &iterations in &SMALL_STEPS_AXIS {
                let mut scene = scene.clone();
                scene.params.solver.xpbd_iterations = iterations;
                scene.params.solver.vbd_iterations = iterations;
                let dt = frame / substeps as f64;
                let point = measure(&scene, &config, (&trajectory, &info), integrator, dt);
                runs.push(GridRun {
                    substeps,
                    iterations,
                    point,
                });
                if !progress(runs.len(), total) {
                    return Err(ReportError::Cancelled);
                }
            }
        }
    }
    Ok(SmallSteps {
        scene: scene.scenario.clone(),
        runs,
        seconds_taken: start.elapsed().as_secs_f64(),
    })
}

/// At one budget of `n` sweeps per frame, `n` substeps of one sweep against one substep of
/// `n` sweeps.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Duel {
    pub integrator: IntegratorKind,
    pub sweeps_per_frame: u32,
    /// Maximum errors (fractions of the cloth's size; infinite where unstable).
    pub small_steps: f64,
    pub many_iterations: f64,
}

impl Duel {
    /// Whether the small steps won (a smaller error, or stable where the other was not).
    pub fn small_steps_win(&self) -> bool {
        self.small_steps < self.many_iterations
    }
}

impl SmallSteps {
    fn run(&self, integrator: IntegratorKind, substeps: u32, iterations: u32) -> Option<&Point> {
        (self.runs.iter())
            .find(|r| {
                r.point.integrator == integrator
                    && r.substeps == substeps
                    && r.iterations == iterations
            })
            .map(|r| &r.point)
    }

    /// Each integrator's duels, at every budget from 2 sweeps per frame.
    pub fn duels(&self) -> Vec<Duel> {
        let error = |p: Option<&Point>| match p {
            Some(p) if p.stable => p.max_error,
            _ => f64::INFINITY,
        };
        let mut out = Vec::new();
        for integrator in [IntegratorKind::Xpbd, IntegratorKind::Vbd] {
            for &n in SMALL_STEPS_AXIS.iter().filter(|&&n| n > 1) {
                out.push(Duel {
                    integrator,
                    sweeps_per_frame: n,
                    small_steps: error(self.run(integrator, n, 1)),
                    many_iterations: error(self.run(integrator, 1, n)),
                });
            }
        }
        out
    }

    /// The answer in a sentence per integrator.
    pub fn verdict(&self) -> Vec<String> {
        let duels = self.duels();
        [IntegratorKind::Xpbd, IntegratorKind::Vbd]
            .into_iter()
            .map(|kind| {
                let mine: Vec<&Duel> = duels.iter().filter(|d| d.integrator == kind).collect();
                let wins = mine.iter().filter(|d| d.small_steps_win()).count();
                let ratios: Vec<f64> = (mine.iter())
                    .filter(|d| d.small_steps.is_finite() && d.many_iterations.is_finite())
                    .map(|d| d.many_iterations / d.small_steps)
                    .collect();
                let range = match (
                    ratios.iter().copied().reduce(f64::min),
                    ratios.iter().copied().reduce(f64::max),
                ) {
                    (Some(lo), Some(hi)) => format!(
                        " (one step of n sweeps off by {lo:.1}–{hi:.1}× the error of n substeps)"
                    ),
                    _ => String::new(),
                };
                let who = if wins == mine.len() {
                    "small steps win at every budget".to_string()
                } else if wins == 0 {
                    "more iterations win at every budget".to_string()
                } else {
                    format!("small steps win at {wins} of {} budgets", mine.len())
                };
                format!("{}: {who}{range}", kind.label())
            })
            .collect()
    }

    /// The grid and the duels as Markdown.
    pub fn markdown(&self) -> String {
        use std::fmt::Write;
        let mut out = format!(
            "# Small steps — scene `{}`\n\nMaximum position error (fraction of the cloth's \
             size) of XPBD and VBD at each number of substeps per 1/60 s frame (rows) and \
             sweeps per substep (columns); \"—\" where unstable. {:.0} s of wall time.\n\n",
            self.scene, self.seconds_taken
        );
        for kind in [IntegratorKind::Xpbd, IntegratorKind::Vbd] {
            let _ = writeln!(out, "## {}\n", kind.label());
            let _ = write!(out, "| substeps \\ sweeps |");
            for m in SMALL_STEPS_AXIS {
                let _ = write!(out, " {m} |");
            }
            out.push_str("\n|---|");
            for _ in SMALL_STEPS_AXIS {
                out.push_str("---|");
            }
            out.push('\n');
            for n in SMALL_STEPS_AXIS {
                let _ = write!(out, "| {n} |");
                for m in SMALL_STEPS_AXIS {
                    let cell = match self.run(kind, n, m) {
                        Some(p) if p.stable => format!("{:.1e}", p.max_error),
                        _ => "—".into(),
                    };
                    let _ = write!(out, " {cell} |");
                }
                out.push('\n');
            }
            out.push('\n');
        }
        let _ = writeln!(
            out,
            "## n substeps of one sweep against one substep of n sweeps\n\n\
             | integrator | sweeps per frame | n × 1 | 1 × n | winner |\n|---|---|---|---|---|"
        );
        for d in self.duels() {
            let _ = writeln!(
                out,
                "| {} | {} | {:.1e} | {:.1e} | {} |",
                d.integrator.name(),
                d.sweeps_per_frame,
                d.small_steps,
                d.many_iterations,
                if d.small_steps_win() {
                    "small steps"
                } else {
                    "iterations"
                }
            );
        }
        out.push('\n');
        for line in self.verdict() {
            let _ = writeln!(out, "- {line}");
        }
        out
    }
}
