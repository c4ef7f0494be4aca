//! The stability map: for each integrator, the largest stable step against the cloth's
//! stiffness, what a user needs to pick a step for a stiff fabric.

use std::time::Instant;

use crate::scene::Scene;
use crate::sim::IntegratorKind;

use super::config::SweepConfig;
use super::error::ReportError;
use super::measure::{Record, run, undamped};
use super::order::slope;
use super::sweep::stable_at;

/// The default stiffness scales: the scene's springs from a tenth to a hundred times as
/// stiff, three decades in steps of about √10.
pub const MAP_SCALES: [f64; 7] = [0.1, 0.316, 1.0, 3.16, 10.0, 31.6, 100.0];

/// Geometric bisections of each largest stable step (each narrows it by √ of the last
/// ratio: from a factor 2 to within 1.1 %).
const MAP_BISECTIONS: u32 = 6;

/// One integrator at one stiffness.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct MapPoint {
    pub integrator: IntegratorKind,
    /// The springs' stiffness over the scene's.
    pub scale: f64,
    /// The structural springs' stiffness at that scale, N/m.
    pub stiffness: f64,
    /// Largest stable step found, seconds; `None` when even the smallest probed was not.
    pub dt: Option<f64>,
    /// Stable up to the largest step probed (a sample interval): no limit found.
    pub at_upper_bound: bool,
}

impl MapPoint {
    /// The largest stable step as substeps per 1/60 s frame.
    pub fn substeps(&self) -> Option<f64> {
        self.dt.map(|dt| 1.0 / (60.0 * dt))
    }
}

/// The whole map.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct StabilityMap {
    pub scene: String,
    /// The largest step probed, seconds (one sample interval).
    pub upper_bound: f64,
    pub points: Vec<MapPoint>,
    /// Wall-clock seconds the map took.
    pub seconds_taken: f64,
}

/// The largest step at which `integrator` keeps `scene` stable: from the upper bound down
/// by halves to a stable step (at most 40), then [`MAP_BISECTIONS`] geometric bisections.
/// Stable as the sweep says: finite, and on the undamped scene the energy never gaining more
/// than `scale` (joules).
fn largest_stable_step(
    scene: &Scene,
    config: &SweepConfig,
    integrator: IntegratorKind,
    scale: f64,
    upper_bound: f64,
) -> (Option<f64>, bool) {
    let stable = |dt: f64| stable_at(scene, config, scale, integrator, dt);
    if stable(upper_bound) {
        return (Some(upper_bound), true);
    }
    let (mut ok, mut bad) = (upper_bound / 2.0, upper_bound);
    let mut halvings = 0;
    while !stable(ok) {
        bad = ok;
        ok /= 2.0;
        halvings += 1;
        if halvings >= 40 {
            return (None, false);
        }
    }
    for _ in 0..MAP_BISECTIONS {
        let mid = (ok * bad).sqrt();
        if stable(mid) {
            ok = mid;
        } else {
            bad = mid;
        }
    }
    (Some(ok), false)
}

/// Maps the largest stable step of each of `config.integrators` on `scene` with its springs'
/// stiffness (all three kinds) scaled by each of `scales`, over `config.seconds` undamped;
/// the energy scale of stability is the peak kinetic energy of RK4 at the smallest swept
/// step on the unscaled scene. Calls `progress(done, total)` after each point; it returns
/// `false` to cancel.
///
/// # Errors
/// [`ReportError::Config`] for a bad configuration or scale, [`ReportError::Cancelled`].
pub fn stability_map(
    scene: &Scene,
    config: &SweepConfig,
    scales: &[f64],
    progress: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<StabilityMap, ReportError> {
    config.validate()?;
    let scene = &config.in_precision(scene);
    if let Some(s) = scales.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
        return Err(ReportError::Config(format!(
            "stiffness scale {s} must be a positive number"
        )));
    }
    let start = Instant::now();
    let base = undamped(scene);
    let smallest = config.dts.iter().copied().fold(f64::INFINITY, f64::min);
    let reference = run(
        &base,
        IntegratorKind::Rk4,
        smallest,
        config.seconds,
        config.samples * 2,
        Record::Energy,
    );
    let energy_scale = reference.peak_kinetic().max(1e-12);
    let upper_bound = config.seconds / config.samples as f64;
    let total = scales.len() * config.integrators.len();
    let mut points = Vec::with_capacity(total);
    for &scale in scales {
        let mut stiff = base.clone();
        let k = stiff
            .params
            .material
            .stiffness
            .map(|k| (k as f64 * scale) as f32);
        stiff.params.material.stiffness = k;
        for &integrator in &config.integrators {
            let (dt, at_upper_bound) =
                largest_stable_step(&stiff, config, integrator, energy_scale, upper_bound);
            points.push(MapPoint {
                integrator,
                scale,
                stiffness: k[0] as f64,
                dt,
                at_upper_bound,
            });
            if !progress(points.len(), total) {
                return Err(ReportError::Cancelled);
            }
        }
    }
    Ok(StabilityMap {
        scene: scene.scenario.clone(),
        upper_bound,
        points,
        seconds_taken: start.elapsed().as_secs_f64(),
    })
}

impl StabilityMap {
    /// The map as a Markdown table: a row per stiffness, a column per integrator, the
    /// largest stable step in substeps per 1/60 s frame.
    pub fn markdown(&self) -> String {
        use std::fmt::Write;
        let mut out = format!(
            "# Stability map — scene `{}`\n\nThe largest stable step of each integrator \
             against the springs' stiffness (all kinds scaled together), as the fewest \
             substeps per 1/60 s frame that keep the undamped scene stable (finite, its \
             energy never gaining more than the reference's peak kinetic energy); \"≤ {:.1}\" \
             where every step up to one sample interval was stable. {:.0} s of wall time.\n\n",
            self.scene,
            1.0 / (60.0 * self.upper_bound),
            self.seconds_taken
        );
        let _ = write!(out, "| stiffness × | structural k (N/m) |");
        for p in self.rows().first().copied().unwrap_or_default() {
            let _ = write!(out, " {} |", p.integrator.name());
        }
        let _ = write!(out, "\n|---|---|");
        for _ in self.rows().first().copied().unwrap_or_default() {
            out.push_str("---|");
        }
        out.push('\n');
        for row in self.rows() {
            let _ = write!(out, "| {} | {:.3} |", row[0].scale, row[0].stiffness);
            for p in row {
                let cell = match p.substeps() {
                    Some(n) if p.at_upper_bound => format!("≤ {n:.1}"),
                    Some(n) => format!("{n:.1}"),
                    None => "none found".into(),
                };
                let _ = write!(out, " {cell} |");
            }
            out.push('\n');
        }
        out
    }

    /// The points a row per stiffness, each in the integrators' order (as they were mapped).
    pub fn rows(&self) -> Vec<&[MapPoint]> {
        self.points.chunk_by(|a, b| a.scale == b.scale).collect()
    }

    /// The slope of log largest-stable-step over log stiffness for `integrator`, over the
    /// stiffnesses where it has a limit below the upper bound (−½ for a method limited by
    /// `ωh`, since `ω ∝ √k`).
    pub fn slope(&self, integrator: IntegratorKind) -> Option<f64> {
        let pts: Vec<(f64, f64)> = (self.points.iter())
            .filter(|p| p.integrator == integrator && !p.at_upper_bound)
            .filter_map(|p| p.dt.map(|dt| (p.stiffness.ln(), dt.ln())))
            .collect();
        slope(&pts)
    }
}
