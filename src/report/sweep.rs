//! The accuracy-versus-cost sweep: every integrator at every step size against a reference
//! trajectory, the largest stable step of each, and the cheapest choice within a tolerance.

use crate::scene::Scene;
use crate::sim::{IntegratorKind, Precision};

use super::config::SweepConfig;
use super::cost::{UnitCosts, Work};
use super::error::ReportError;
use super::frontier::{frontier, recommend};
use super::measure::{Record, Trajectory, position_error, run};
use super::order::{ObservedOrder, observed_order};
use super::point::Point;
use super::reference::{Reference, reference, scene_size};
use super::shape::shape_error;

/// The largest step at which an integrator stayed stable.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct StableLimit {
    pub integrator: IntegratorKind,
    /// Largest stable step found, seconds; `None` when even the smallest probe was unstable.
    pub dt: Option<f64>,
    /// True when the search stopped at its upper bound (a sample interval) still stable.
    pub at_upper_bound: bool,
    /// The order its stable runs showed (see [`observed_order`]).
    pub observed_order: Option<ObservedOrder>,
}

/// Everything the sweep measured.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct AccuracyReport {
    pub scene: String,
    pub particles: usize,
    /// The cloth's size (bounding-box diagonal), metres: errors are fractions of it.
    pub size: f64,
    pub seconds: f64,
    pub tolerance: f64,
    pub reference: Reference,
    pub points: Vec<Point>,
    pub limits: Vec<StableLimit>,
    /// Indices into `points`, cheapest first.
    pub frontier: Vec<usize>,
    /// Index into `points` of the cheapest one within the tolerance.
    pub recommendation: Option<usize>,
    /// The unit costs the counted work was weighed by.
    pub unit_costs: UnitCosts,
    /// What every run computed in.
    pub precision: Precision,
}

impl AccuracyReport {
    /// The recommended point, if any.
    pub fn recommended(&self) -> Option<&Point> {
        self.recommendation.map(|i| &self.points[i])
    }
}

/// How far the sweep has got, for a progress bar. Return `false` from the callback to stop.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    pub done: usize,
    pub total: usize,
    pub what: String,
}

/// Counts work against a total and asks the caller whether to go on.
struct Tracker<'a> {
    done: usize,
    total: usize,
    callback: &'a mut dyn FnMut(&Progress) -> bool,
}

impl Tracker<'_> {
    fn report(&mut self, what: String) -> Result<(), ReportError> {
        let progress = Progress {
            done: self.done.min(self.total),
            total: self.total,
            what,
        };
        if (self.callback)(&progress) {
            Ok(())
        } else {
            Err(ReportError::Cancelled)
        }
    }

    /// Says what is about to run (so a long unit does not look stuck).
    fn begin(&mut self, what: String) -> Result<(), ReportError> {
        self.report(what)
    }

    /// Counts a unit as done.
    fn step(&mut self, what: String) -> Result<(), ReportError> {
        self.done += 1;
        self.report(what)
    }
}

/// Measures one integrator at one step against `reference`.
pub fn measure(
    scene: &Scene,
    config: &SweepConfig,
    reference: (&Trajectory, &Reference),
    integrator: IntegratorKind,
    dt: f64,
) -> Point {
    let size = scene_size(scene);
    let damped = run(
        scene,
        integrator,
        dt,
        config.seconds,
        config.samples,
        Record::Positions,
    );
    let energy = run(
        &super::measure::undamped(scene),
        integrator,
        dt,
        config.seconds,
        config.samples * 2,
        Record::Energy,
    );
    let (rms, max) = position_error(&damped, reference.0);
    let info = reference.1;
    let (shape_error, strain_error) = shape_error(&scene.model, &damped, reference.0, size);
    let scale = reference.1.peak_kinetic.max(1e-12);
    let energy_drift = energy.energy_deviation() / scale;
    let bounded = energy.energy_growth() <= scale;
    let (rms_error, max_error) = (rms / size, max / size);
    let work = Work::per_step(integrator, &damped.stats);
    let steps_per_sim_s = 1.0 / damped.h;
    Point {
        integrator,
        dt: damped.h,
        steps: damped.steps,
        substeps_per_frame: scene.params.step.dt as f64 / damped.h,
        rms_error,
        max_error,
        energy_drift,
        stable: damped.finite && energy.finite && bounded && max_error < 1.0,
        floor: info.floor(damped.h),
        shape_error,
        strain_error,
        shape_floor: info.check_shape,
        judged: info.judged,
        wall_s_per_sim_s: damped.wall / config.seconds,
        work_per_sim_s: steps_per_sim_s * config.unit_costs.step(integrator, &work),
        force_evals_per_step: work.force_evals,
        linear_iterations_per_step: work.linear_iterations,
        sweeps_per_step: work.sweeps,
        contact: damped.contact,
    }
}

/// Whether `integrator` keeps `scene` (the undamped one) stable at `dt`: finite, and its
/// energy never gaining more than `peak_kinetic` (joules).
pub(super) fn stable_at(
    scene: &Scene,
    config: &SweepConfig,
    peak_kinetic: f64,
    integrator: IntegratorKind,
    dt: f64,
) -> bool {
    let energy = run(
        scene,
        integrator,
        dt,
        config.seconds,
        config.samples * 2,
        Record::Energy,
    );
    energy.finite && energy.energy_growth() <= peak_kinetic.max(1e-12)
}

/// Brackets the largest stable step from the swept points, widening the bracket by
/// doubling or halving if needed, then bisects it geometrically.
fn stable_limit(
    scene: &Scene,
    config: &SweepConfig,
    peak_kinetic: f64,
    integrator: IntegratorKind,
    swept: &[&Point],
    tracker: &mut Tracker<'_>,
) -> Result<StableLimit, ReportError> {
    let upper_bound = config.seconds / config.samples as f64;
    let undamped = super::measure::undamped(scene);
    let probe = |dt: f64, tracker: &mut Tracker<'_>| -> Result<bool, ReportError> {
        tracker.begin(format!("{integrator}: stability at {dt:.2e} s"))?;
        let ok = stable_at(&undamped, config, peak_kinetic, integrator, dt);
        tracker.step(format!("{integrator}: stability at {dt:.2e} s: done"))?;
        Ok(ok)
    };
    let mut lo = swept
        .iter()
        .filter(|p| p.stable)
        .map(|p| p.dt)
        .fold(None, |m: Option<f64>, d| Some(m.map_or(d, |m| m.max(d))));
    let mut hi = swept
        .iter()
        .filter(|p| !p.stable && lo.is_none_or(|l| p.dt > l))
        .map(|p| p.dt)
        .fold(None, |m: Option<f64>, d| Some(m.map_or(d, |m| m.min(d))));
    let mut budget = config.bisection_steps;
    // Widen: upwards while stable, downwards while unstable.
    while budget > 0 && hi.is_none() {
        let Some(l) = lo else { break };
        if l >= upper_bound {
            break;
        }
        budget -= 1;
        let next = (2.0 * l).min(upper_bound);
        if probe(next, tracker)? {
            lo = Some(next)
        } else {
            hi = Some(next)
        }
    }
    while budget > 0 && lo.is_none() {
        let Some(h) = hi else { break };
        budget -= 1;
        let next = h / 2.0;
        if probe(next, tracker)? {
            lo = Some(next)
        } else {
            hi = Some(next)
        }
    }
    while budget > 0 {
        let (Some(l), Some(h)) = (lo, hi) else { break };
        budget -= 1;
        let mid = (l * h).sqrt();
        if probe(mid, tracker)? {
            lo = Some(mid)
        } else {
            hi = Some(mid)
        }
    }
    // Work not done because the bracket closed early still counts towards the total.
    for _ in 0..budget {
        tracker.step(format!("{integrator}: stability search done"))?;
    }
    Ok(StableLimit {
        integrator,
        dt: lo,
        at_upper_bound: hi.is_none() && lo.is_some_and(|l| l >= upper_bound * 0.999),
        observed_order: None,
    })
}

/// Runs the whole sweep on `scene`, calling `progress` after every unit of work; it
/// returns `false` to cancel.
///
/// # Errors
/// [`ReportError::Config`] for a bad configuration, [`ReportError::Cancelled`].
pub fn sweep(
    scene: &Scene,
    config: &SweepConfig,
    progress: &mut dyn FnMut(&Progress) -> bool,
) -> Result<AccuracyReport, ReportError> {
    config.validate()?;
    let scene = &config.in_precision(scene);
    let per_integrator = config.dts.len() + config.bisection_steps as usize;
    let mut tracker = Tracker {
        done: 0,
        total: 1 + config.integrators.len() * per_integrator,
        callback: progress,
    };
    let (reference_run, mut reference) = reference(scene, config);
    reference.judge(config.tolerance);
    tracker.step(format!("reference: RK4 at {:.2e} s", reference.dt))?;
    let mut points = Vec::new();
    for &integrator in &config.integrators {
        for &dt in &config.dts {
            points.push(measure(
                scene,
                config,
                (&reference_run, &reference),
                integrator,
                dt,
            ));
            tracker.step(format!("{integrator} at {dt:.2e} s"))?;
        }
    }
    let mut limits = Vec::new();
    for &integrator in &config.integrators {
        let mine: Vec<&Point> = points
            .iter()
            .filter(|p| p.integrator == integrator)
            .collect();
        let mut limit = stable_limit(
            scene,
            config,
            reference.peak_kinetic,
            integrator,
            &mine,
            &mut tracker,
        )?;
        let runs: Vec<(f64, f64)> = (mine.iter())
            .filter(|p| p.stable && p.resolved())
            .map(|p| (p.dt, p.judged_error().0))
            .collect();
        limit.observed_order = observed_order(&runs);
        limits.push(limit);
    }
    let frontier = frontier(&points);
    let recommendation = recommend(&points, config.tolerance);
    Ok(AccuracyReport {
        scene: scene.scenario.clone(),
        particles: scene.model.particle_count(),
        size: scene_size(scene),
        seconds: config.seconds,
        tolerance: config.tolerance,
        reference,
        points,
        limits,
        frontier,
        recommendation,
        unit_costs: config.unit_costs.clone(),
        precision: config.precision,
    })
}
