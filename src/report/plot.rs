//! The report's picture: maximum error against cost on log–log axes, drawn with plotters.

use plotters::prelude::*;

use super::sweep::AccuracyReport;
use crate::sim::IntegratorKind;

/// Picture size, pixels.
pub const PLOT_SIZE: (u32, u32) = (1200, 800);

/// A colour per integrator, in `IntegratorKind::ALL` order.
pub fn integrator_color(kind: IntegratorKind) -> (u8, u8, u8) {
    const COLORS: [(u8, u8, u8); 8] = [
        (214, 39, 40),
        (31, 119, 180),
        (44, 160, 44),
        (255, 127, 14),
        (148, 103, 189),
        (140, 86, 75),
        (23, 190, 207),
        (188, 189, 34),
    ];
    let i = IntegratorKind::ALL
        .iter()
        .position(|&k| k == kind)
        .unwrap_or(0);
    COLORS[i % COLORS.len()]
}

/// Registers the font the plots' text uses (once).
fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The font egui ships with: no system font lookup, the same text on every machine.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        );
    });
}

/// Draws the plot into an RGB buffer of [`PLOT_SIZE`].
///
/// # Errors
/// A message from plotters.
pub fn draw(report: &AccuracyReport) -> Result<Vec<u8>, String> {
    render(|root| chart(root, report))
}

/// The area a plot draws its chart on.
pub(super) type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// An RGB buffer of [`PLOT_SIZE`], white, with what `chart` draws on it.
pub(super) fn render(
    chart: impl FnOnce(&Area<'_>) -> Result<(), String>,
) -> Result<Vec<u8>, String> {
    register_font();
    let (w, h) = PLOT_SIZE;
    let mut buffer = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        chart(&root)?;
        root.present().map_err(err)?;
    }
    Ok(buffer)
}

pub(super) fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// A chart on log–log axes, as both plots draw.
pub(super) type LogChart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// `line` drawn in `kind`'s colour, 3 px wide, with its legend entry; returns the colour.
pub(super) fn integrator_line(
    chart: &mut LogChart<'_, '_>,
    kind: IntegratorKind,
    line: Vec<(f64, f64)>,
) -> Result<RGBColor, String> {
    let (r, g, b) = integrator_color(kind);
    let color = RGBColor(r, g, b);
    chart
        .draw_series(LineSeries::new(line, color.stroke_width(3)))
        .map_err(err)?
        .label(kind.name())
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], color.stroke_width(3)));
    Ok(color)
}

/// The axes' descriptions, in both plots' label style.
pub(super) fn label_axes(chart: &mut LogChart<'_, '_>, x: &str, y: &str) -> Result<(), String> {
    chart
        .configure_mesh()
        .x_desc(x)
        .y_desc(y)
        .x_label_formatter(&|x| format!("{x:.0e}"))
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .label_style(("sans-serif", 18))
        .axis_desc_style(("sans-serif", 22))
        .draw()
        .map_err(err)
}

/// A dashed level across the chart at `y` (from `x.0` to `x.1`), `dash` and `gap` pixels,
/// in the legend as `label`.
pub(super) fn dashed_level(
    chart: &mut LogChart<'_, '_>,
    x: (f64, f64),
    y: f64,
    (dash, gap): (u32, u32),
    color: RGBColor,
    label: &str,
) -> Result<(), String> {
    chart
        .draw_series(DashedLineSeries::new(
            [(x.0, y), (x.1, y)],
            dash,
            gap,
            color.stroke_width(2),
        ))
        .map_err(err)?
        .label(label)
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2)));
    Ok(())
}

/// The legend, at `position`.
pub(super) fn legend<'a, 'b: 'a>(
    chart: &mut LogChart<'a, 'b>,
    position: SeriesLabelPosition,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font(("sans-serif", 20))
        .position(position)
        .draw()
        .map_err(err)
}

fn chart(root: &Area<'_>, report: &AccuracyReport) -> Result<(), String> {
    let finite = |x: f64| x.is_finite() && x > 0.0;
    let costs: Vec<f64> = report
        .points
        .iter()
        .map(|p| p.work_per_sim_s)
        .filter(|&c| finite(c))
        .collect();
    let floor = match report.reference.judged {
        crate::report::Judged::Trajectory => report.reference.check_max,
        crate::report::Judged::Shape => report.reference.check_shape,
    };
    let errors: Vec<f64> = report
        .points
        .iter()
        .filter(|p| p.stable)
        .map(|p| p.judged_error().0)
        .chain([report.tolerance, floor])
        .filter(|&e| finite(e))
        .collect();
    let (x_lo, x_hi) = range(&costs, 0.5, 2.0);
    // Room above the data for the legend, in the upper right.
    let (y_lo, y_hi) = range(&errors, 0.3, 300.0);
    let mut chart = ChartBuilder::on(root)
        .caption(
            format!(
                "What accuracy costs — {} ({} particles, {} s)",
                report.scene, report.particles, report.seconds
            ),
            ("sans-serif", 30),
        )
        .margin(20)
        .x_label_area_size(60)
        .y_label_area_size(90)
        .build_cartesian_2d((x_lo..x_hi).log_scale(), (y_lo..y_hi).log_scale())
        .map_err(err)?;
    let y_desc = match report.reference.judged {
        crate::report::Judged::Trajectory => "max position error / cloth size",
        crate::report::Judged::Shape => "shape error (centre of mass, spread) / cloth size",
    };
    let x_desc = "cost: work per simulated second, in force evaluations of this cloth";
    label_axes(&mut chart, x_desc, y_desc)?;
    // The tolerance, and the reference's own uncertainty: errors below it are not resolved.
    let tolerance = report.tolerance;
    let x = (x_lo, x_hi);
    let label = format!("tolerance {tolerance:.1e}");
    dashed_level(
        &mut chart,
        x,
        tolerance,
        (14, 8),
        RGBColor(170, 20, 20),
        &label,
    )?;
    if finite(floor) {
        let label = "reference uncertainty (hollow: not resolved)";
        dashed_level(&mut chart, x, floor, (4, 6), RGBColor(90, 90, 90), label)?;
    }
    // The frontier, under the integrators' lines.
    let frontier: Vec<(f64, f64)> = report
        .frontier
        .iter()
        .map(|&i| {
            (
                report.points[i].work_per_sim_s,
                report.points[i].judged_error().0,
            )
        })
        .collect();
    let shade = BLACK.mix(0.3);
    chart
        .draw_series(LineSeries::new(frontier, shade.stroke_width(10)))
        .map_err(err)?
        .label("frontier")
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], shade.stroke_width(10)));
    for kind in IntegratorKind::ALL {
        let mine = |stable: bool| {
            report.points.iter().filter(move |p| {
                p.integrator == kind && p.stable == stable && finite(p.work_per_sim_s)
            })
        };
        let mut line: Vec<(f64, f64)> = mine(true)
            .filter(|p| finite(p.judged_error().0))
            .map(|p| (p.work_per_sim_s, p.judged_error().0))
            .collect();
        let unstable: Vec<f64> = mine(false).map(|p| p.work_per_sim_s).collect();
        if line.is_empty() && unstable.is_empty() {
            continue;
        }
        line.sort_by(|a, b| a.0.total_cmp(&b.0));
        let color = integrator_line(&mut chart, kind, line.clone())?;
        // Resolved errors filled, unresolved ones (within ten times the floor) hollow.
        let resolved: Vec<bool> = {
            let mut mine: Vec<&crate::report::Point> =
                mine(true).filter(|p| finite(p.judged_error().0)).collect();
            mine.sort_by(|a, b| a.work_per_sim_s.total_cmp(&b.work_per_sim_s));
            mine.iter().map(|p| p.resolved()).collect()
        };
        chart
            .draw_series(line.iter().zip(&resolved).map(|(&p, &filled)| {
                let style = if filled {
                    color.filled()
                } else {
                    color.stroke_width(2)
                };
                Circle::new(p, 6, style)
            }))
            .map_err(err)?;
        // Unstable runs have no meaningful error: a cross along the top edge, at their cost.
        chart
            .draw_series(
                unstable
                    .iter()
                    .map(|&c| Cross::new((c, y_hi / 1.6), 8, color.stroke_width(3))),
            )
            .map_err(err)?;
    }
    chart
        .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
        .map_err(err)?
        .label("× unstable, at its cost")
        .legend(|(x, y)| Cross::new((x + 10, y), 6, BLACK.stroke_width(2)));
    legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    Ok(())
}

/// `(min · below, max · above)` of positive values, or a unit decade without any.
/// The positive values' range, widened by `below` and `above` (factors).
pub(super) fn range(values: &[f64], below: f64, above: f64) -> (f64, f64) {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(0.0, f64::max);
    if lo.is_finite() && hi > 0.0 {
        (lo * below, hi * above)
    } else {
        (1e-3, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::super::UnitCosts;
    use super::*;
    use crate::report::Reference;
    use crate::report::point::Point;

    fn pixels_of(buffer: &[u8], kind: IntegratorKind) -> usize {
        let (r, g, b) = integrator_color(kind);
        buffer.chunks_exact(3).filter(|p| *p == [r, g, b]).count()
    }

    /// Every integrator in its own decade of cost and error, three stable steps each (and
    /// one unstable run for Verlet): nothing overlaps, so each colour's area is its own.
    fn separated() -> AccuracyReport {
        let mut points = Vec::new();
        for (i, kind) in IntegratorKind::ALL.into_iter().enumerate() {
            for (j, step) in [1.0, 2.0, 4.0].into_iter().enumerate() {
                let decade = 10f64.powi(i as i32);
                let cost = decade * (1.0 + 2.0 * j as f64);
                points.push(Point {
                    integrator: kind,
                    dt: 1e-3 / step,
                    substeps_per_frame: step,
                    ..Point::at(cost, 1e-2 / decade / step, true)
                });
            }
        }
        let mut unstable = points[6].clone();
        unstable.stable = false;
        unstable.work_per_sim_s = 0.5;
        points.push(unstable);
        AccuracyReport {
            scene: "test".into(),
            particles: 81,
            size: 1.0,
            seconds: 0.2,
            tolerance: 1e-4,
            reference: Reference {
                integrator: IntegratorKind::Rk4,
                dt: 1e-5,
                check_rms: 1e-10,
                check_max: 1e-10,
                check_shape: 1e-10,
                judged: crate::report::Judged::Trajectory,
                peak_kinetic: 1.0,
                ladder: Vec::new(),
                rounding: Vec::new(),
            },
            points,
            limits: Vec::new(),
            frontier: Vec::new(),
            recommendation: None,
            unit_costs: UnitCosts::default(),
            precision: crate::sim::Precision::F64,
        }
    }

    #[test]
    fn every_integrator_is_drawn_in_its_own_colour_with_a_marker_per_step() {
        let report = separated();
        let buffer = draw(&report).unwrap();
        let (w, h) = PLOT_SIZE;
        assert_eq!(buffer.len(), (w * h * 3) as usize);
        // A 6-pixel filled circle covers about 110 pixels, a legend line 60: three markers,
        // their line and the legend are well above 300 in every colour.
        for kind in IntegratorKind::ALL {
            let n = pixels_of(&buffer, kind);
            assert!(n > 300, "{kind}: only {n} pixels of its colour");
        }
        // The markers are there, not only the lines: dropping a point loses about a marker.
        let mut fewer = report.clone();
        fewer
            .points
            .retain(|p| !(p.integrator == IntegratorKind::Rk4 && p.substeps_per_frame == 2.0));
        let lost = pixels_of(&buffer, IntegratorKind::Rk4) as f64
            - pixels_of(&draw(&fewer).unwrap(), IntegratorKind::Rk4) as f64;
        assert!(lost > 60.0, "dropping a point lost only {lost} pixels");
    }
}
