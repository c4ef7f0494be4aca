//! The stability map's picture: the largest stable step against stiffness, log–log.

use plotters::prelude::*;

use super::map::StabilityMap;
use super::plot::{Area, dashed_level, err, integrator_line, label_axes, legend, range, render};
use crate::sim::IntegratorKind;

/// Draws the map into an RGB buffer of [`PLOT_SIZE`](super::PLOT_SIZE): one line per integrator of its
/// largest stable step (as substeps per 1/60 s frame) against the structural springs'
/// stiffness; a method stable at every step probed sits on the dashed upper bound.
///
/// # Errors
/// A message from plotters.
pub fn draw_map(map: &StabilityMap) -> Result<Vec<u8>, String> {
    render(|root| chart(root, map))
}

fn chart(root: &Area<'_>, map: &StabilityMap) -> Result<(), String> {
    let substeps = |dt: f64| 1.0 / (60.0 * dt);
    let ks: Vec<f64> = map.points.iter().map(|p| p.stiffness).collect();
    let ns: Vec<f64> = (map.points.iter())
        .filter_map(|p| p.dt.map(substeps))
        .collect();
    let (x_lo, x_hi) = range(&ks, 0.7, 1.4);
    let (y_lo, y_hi) = range(&ns, 0.5, 4.0);
    let mut chart = ChartBuilder::on(root)
        .caption(format!("Stability map — {}", map.scene), ("sans-serif", 30))
        .margin(20)
        .x_label_area_size(60)
        .y_label_area_size(90)
        .build_cartesian_2d((x_lo..x_hi).log_scale(), (y_lo..y_hi).log_scale())
        .map_err(err)?;
    label_axes(
        &mut chart,
        "structural spring stiffness, N/m (shear and bend scaled alike)",
        "fewest stable substeps per 1/60 s frame",
    )?;
    let bound = substeps(map.upper_bound);
    let label = "largest step probed (stable at every step)";
    dashed_level(
        &mut chart,
        (x_lo, x_hi),
        bound,
        (4, 6),
        RGBColor(90, 90, 90),
        label,
    )?;
    for kind in IntegratorKind::ALL {
        let line: Vec<(f64, f64)> = (map.points.iter())
            .filter(|p| p.integrator == kind)
            .filter_map(|p| p.dt.map(|dt| (p.stiffness, substeps(dt))))
            .collect();
        if line.is_empty() {
            continue;
        }
        let color = integrator_line(&mut chart, kind, line.clone())?;
        chart
            .draw_series(line.iter().map(|&p| Circle::new(p, 6, color.filled())))
            .map_err(err)?;
    }
    legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
    Ok(())
}
