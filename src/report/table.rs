//! The report as CSV and Markdown.

use std::fmt::Write;

use super::order::RESOLVED;
use super::point::Point;
use super::shape::Judged;
use super::sweep::AccuracyReport;

/// CSV columns, in order.
pub const CSV_COLUMNS: [&str; 19] = [
    "integrator",
    "dt",
    "steps",
    "rms_error",
    "max_error",
    "energy_drift",
    "stable",
    "resolved",
    "work_per_sim_s",
    "wall_s_per_sim_s",
    "force_evals_per_step",
    "linear_iterations_per_step",
    "sweeps_per_step",
    "substeps_per_frame",
    "on_frontier",
    "deepest_penetration_m",
    "intersections",
    "shape_error",
    "strain_error",
];

fn sci(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.4e}")
    } else {
        "inf".into()
    }
}

/// One row per integrator × step.
pub fn csv(report: &AccuracyReport) -> String {
    let mut out = CSV_COLUMNS.join(",") + "\n";
    for (i, p) in report.points.iter().enumerate() {
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{:.3},{:.3},{:.3},{:.2},{},{},{},{},{}",
            p.integrator,
            sci(p.dt),
            p.steps,
            sci(p.rms_error),
            sci(p.max_error),
            sci(p.energy_drift),
            p.stable,
            p.resolved(),
            sci(p.work_per_sim_s),
            sci(p.wall_s_per_sim_s),
            p.force_evals_per_step,
            p.linear_iterations_per_step,
            p.sweeps_per_step,
            p.substeps_per_frame,
            report.frontier.contains(&i),
            p.contact
                .map_or("n/a".into(), |c| sci(c.deepest_penetration)),
            p.contact
                .map_or("n/a".into(), |c| c.intersections.to_string()),
            sci(p.shape_error),
            sci(p.strain_error),
        );
    }
    out
}

fn percent(x: f64) -> String {
    if !x.is_finite() {
        "—".into()
    } else if x >= 0.01 {
        format!("{:.2} %", 100.0 * x)
    } else {
        format!("{:.1e} %", 100.0 * x)
    }
}

/// The choice in one sentence.
pub fn choice_sentence(report: &AccuracyReport) -> String {
    match report.recommended() {
        Some(p) => format!(
            "{} at dt = {:.3e} s ({:.0} substeps per 1/60 s frame): {} {} of the cloth's \
             size for {:.3e} force evaluations' work per simulated second ({:.2e} s of wall \
             time per simulated second here)",
            p.integrator,
            p.dt,
            p.substeps_per_frame,
            match p.judged {
                Judged::Trajectory => "max error",
                Judged::Shape => "shape error",
            },
            percent(p.judged_error().0),
            p.work_per_sim_s,
            p.wall_s_per_sim_s
        ),
        None => format!(
            "no swept run stayed within {} of the cloth's size; sweep smaller steps (--dts)",
            percent(report.tolerance)
        ),
    }
}

/// An error as a percentage, in parentheses where it is the one judged and unresolved.
fn judged(p: &Point, by: Judged, error: f64) -> String {
    if p.judged == by && !p.resolved() && error.is_finite() {
        format!("({})", percent(error))
    } else {
        percent(error)
    }
}

/// Substeps per frame: whole, or to two decimals (√2).
fn substeps(p: &Point) -> String {
    match p.whole_substeps() {
        Some(n) => n.to_string(),
        None => format!("{:.2}", p.substeps_per_frame),
    }
}

fn point_row(out: &mut String, p: &Point, frontier: bool, contact: bool) {
    let _ = write!(
        out,
        "| {} | {:.3e} | {} | {} | {} | {} | {} | {} | {} | {:.3e} | {:.3e} | {:.1} | {:.1} | {:.1} |",
        if frontier {
            format!("**{}**", p.integrator)
        } else {
            p.integrator.to_string()
        },
        p.dt,
        substeps(p),
        percent(p.rms_error),
        judged(p, Judged::Trajectory, p.max_error),
        judged(p, Judged::Shape, p.shape_error),
        if p.strain_error.is_finite() {
            format!("{:.1e}", p.strain_error)
        } else {
            "—".into()
        },
        if p.energy_drift.is_finite() {
            format!("{:.2e}", p.energy_drift)
        } else {
            "—".into()
        },
        if p.stable { "yes" } else { "**no**" },
        p.work_per_sim_s,
        p.wall_s_per_sim_s,
        p.force_evals_per_step,
        p.linear_iterations_per_step,
        p.sweeps_per_step,
    );
    if contact {
        let _ = write!(
            out,
            " {} | {} |",
            p.contact
                .map_or("—".into(), |c| format!("{:.1e}", c.deepest_penetration)),
            p.contact
                .map_or("—".into(), |c| c.intersections.to_string())
        );
    }
    out.push('\n');
}

/// Readable tables: the choice, the reference, the largest stable steps, every run and the
/// frontier.
pub fn markdown(report: &AccuracyReport) -> String {
    let mut out = String::new();
    let r = &report.reference;
    let _ = writeln!(out, "# What accuracy costs — scene `{}`\n", report.scene);
    let _ = writeln!(
        out,
        "{} particles, cloth size {:.3} m (bounding-box diagonal), {} s simulated in {}. Errors are \
         the largest deviation from the reference along the trajectory, as a fraction of the \
         cloth's size. Cost is the work counted per simulated second (force evaluations, \
         conjugate-gradient iterations, constraint and descent sweeps) weighed by fixed unit \
         costs, in force evaluations of this cloth, so the choice is the same on every run; \
         wall-clock seconds per simulated second on this machine are reported beside it.\n",
        report.particles, report.size, report.seconds, report.precision
    );
    let u = &report.unit_costs;
    let _ = writeln!(
        out,
        "Unit costs ({}): a force evaluation 1, implicit Euler's assembly {:.2} per \
         evaluation, a conjugate-gradient iteration {:.2}, an XPBD sweep {:.2}, a VBD sweep \
         {:.2}; `clothsim accuracy --calibrate` measures them on this machine.\n",
        u.source, u.assembly, u.linear_iteration, u.xpbd_sweep, u.vbd_sweep
    );
    if r.judged == Judged::Shape {
        let _ = writeln!(
            out,
            "**Judged by shape.** The trajectory is chaotic over this horizon: the reference \
             is unsure of its own positions by {} of the cloth's size, so position errors \
             below ten times that ({}) cannot be told from its own, and the tolerance is \
             below. Runs are judged instead by the shape in aggregate, which chaos leaves \
             alone: the largest distance over the samples between their centre of mass and \
             the reference's, or between their spreads (radius of gyration), as a fraction of \
             the cloth's size (the reference is unsure of it by {}). Energy drift and the \
             mean structural strain's difference are reported beside.\n",
            percent(r.check_max),
            percent(RESOLVED * r.check_max),
            percent(r.check_shape)
        );
    }
    let _ = writeln!(out, "## The choice\n");
    let _ = writeln!(
        out,
        "For a tolerance of {} of the cloth's size: **{}**.\n",
        percent(report.tolerance),
        choice_sentence(report)
    );
    let _ = writeln!(out, "## Reference\n");
    let _ = writeln!(
        out,
        "{} at dt = {:.3e} s: of RK4 at steps doubling from a quarter of the smallest swept \
         one, the one that differs least from the run at twice its step (a smaller step is \
         not always surer: rounding grows with the steps taken). That difference, {} \
         (RMS) / {} (max) of the cloth's size, is its uncertainty, {:.0}× below the \
         tolerance. A run's error counts as resolved from ten times the larger of it and \
         the rounding RK4 itself shows at that step (for steps finer than the reference's: \
         {}); unresolved errors are in parentheses, and hollow in the plot.\n",
        r.integrator,
        r.dt,
        percent(r.check_rms),
        percent(r.check_max),
        report.tolerance / r.check_max.max(1e-300),
        if r.rounding.is_empty() {
            "none".to_string()
        } else {
            (r.rounding.iter())
                .map(|(h, e)| format!("{} at {h:.2e} s", percent(*e)))
                .collect::<Vec<_>>()
                .join(", ")
        }
    );
    let _ = writeln!(out, "## Largest stable step\n");
    let _ = writeln!(
        out,
        "Stable: finite; on the undamped scene the energy never gains more than the \
         reference's peak kinetic energy (losing it, as the damping methods do, is no \
         instability); error below the cloth's size. Observed order: the least-squares slope \
         of log error over log step through the stable runs whose error is resolved and at \
         most 10 % of the cloth's size (beyond, a method is not yet in its asymptotic range), \
         with how many steps and decades of error it spans (— where fewer than two \
         qualify).\n"
    );
    let _ = writeln!(
        out,
        "| integrator | largest stable dt (s) | substeps per 1/60 s frame | observed order |"
    );
    let _ = writeln!(out, "|---|---|---|---|");
    for l in &report.limits {
        let (dt, substeps) = match l.dt {
            Some(dt) => (
                format!("{}{dt:.3e}", if l.at_upper_bound { "≥ " } else { "" }),
                format!("{:.1}", 1.0 / (60.0 * dt)),
            ),
            None => ("none found".into(), "—".into()),
        };
        let order = l.observed_order.map_or("—".into(), |o| {
            format!(
                "{:.2} ({} steps, {:.1} decades)",
                o.order, o.points, o.decades
            )
        });
        let _ = writeln!(out, "| {} | {dt} | {substeps} | {order} |", l.integrator);
    }
    let _ = writeln!(out, "\n## Every run\n");
    let _ = writeln!(
        out,
        "Frontier points (no other run is both cheaper and more accurate) in bold.\n"
    );
    let contact = report.points.iter().any(|p| p.contact.is_some());
    if contact {
        let _ = writeln!(
            out,
            "On this scene's solids and self-contact each run also reports the deepest any \
             particle got inside a sphere or plane (m) and the most intersecting triangle \
             pairs at a sample time.\n"
        );
    }
    let _ = writeln!(
        out,
        "| integrator | dt (s) | substeps/frame | RMS error | max error | shape error | strain error | energy drift | stable | work / sim s | wall s / sim s | force evals / step | CG iterations / step | sweeps / step |{}",
        if contact {
            " deepest penetration (m) | intersections |"
        } else {
            ""
        }
    );
    let _ = writeln!(
        out,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|{}",
        if contact { "---|---|" } else { "" }
    );
    for (i, p) in report.points.iter().enumerate() {
        point_row(&mut out, p, report.frontier.contains(&i), contact);
    }
    let _ = writeln!(out, "\n## Frontier, cheapest first\n");
    for &i in &report.frontier {
        let p = &report.points[i];
        let _ = writeln!(
            out,
            "- {} at dt = {:.3e} s: max error {}, {:.3e} force evaluations' work ({:.3e} s) per \
             simulated second",
            p.integrator,
            p.dt,
            percent(p.max_error),
            p.work_per_sim_s,
            p.wall_s_per_sim_s
        );
    }
    let _ = writeln!(out, "\n![error against cost](accuracy.png)");
    out
}
