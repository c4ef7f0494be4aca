//! Writing a report's three files.

use std::path::{Path, PathBuf};

use crate::output::{OutputError, write_atomically, write_bytes};

use super::error::ReportError;
use super::map::StabilityMap;
use super::map_plot::draw_map;
use super::plot::{PLOT_SIZE, draw};
use super::small_steps::SmallSteps;
use super::sweep::AccuracyReport;
use super::table::{csv, markdown};

fn write_err(e: OutputError) -> ReportError {
    match e {
        OutputError::MissingDirectory { path, dir } => ReportError::Write {
            path,
            detail: format!("the directory {} does not exist", dir.display()),
        },
        OutputError::Write { path, detail } => ReportError::Write { path, detail },
    }
}

fn create_dir(dir: &Path) -> Result<(), ReportError> {
    std::fs::create_dir_all(dir).map_err(|e| ReportError::Write {
        path: dir.to_path_buf(),
        detail: format!("cannot create the directory: {e}"),
    })
}

/// Writes `text` to `dir/name` and returns the path.
fn write_text(dir: &Path, name: &str, text: &str) -> Result<PathBuf, ReportError> {
    let path = dir.join(name);
    write_bytes(&path, text.as_bytes()).map_err(write_err)?;
    Ok(path)
}

/// Writes `accuracy.csv`, `accuracy.md` and `accuracy.png` into `dir` (created if
/// missing) and returns their paths.
///
/// # Errors
/// [`ReportError::Write`] naming the file that could not be written.
pub fn write_report(report: &AccuracyReport, dir: &Path) -> Result<Vec<PathBuf>, ReportError> {
    create_dir(dir)?;
    let csv_path = write_text(dir, "accuracy.csv", &csv(report))?;
    let md_path = write_text(dir, "accuracy.md", &markdown(report))?;
    let png_path = write_png(dir, "accuracy.png", draw(report))?;
    Ok(vec![csv_path, md_path, png_path])
}

/// Writes `stability-map.csv`, `stability-map.md` and `stability-map.png` into `dir`
/// (created if missing) and returns their paths.
///
/// # Errors
/// [`ReportError::Write`] naming the file that could not be written.
pub fn write_map(map: &StabilityMap, dir: &Path) -> Result<Vec<PathBuf>, ReportError> {
    create_dir(dir)?;
    let mut table = String::from("integrator,scale,stiffness,largest_stable_dt,at_upper_bound\n");
    for p in &map.points {
        let dt = p.dt.map_or("none".into(), |dt| format!("{dt:.4e}"));
        table += &format!(
            "{},{},{:.4e},{dt},{}\n",
            p.integrator, p.scale, p.stiffness, p.at_upper_bound
        );
    }
    let csv_path = write_text(dir, "stability-map.csv", &table)?;
    let md_path = write_text(dir, "stability-map.md", &map.markdown())?;
    let png_path = write_png(dir, "stability-map.png", draw_map(map))?;
    Ok(vec![csv_path, md_path, png_path])
}

/// Writes `small-steps.csv` and `small-steps.md` into `dir` (created if missing) and
/// returns their paths.
///
/// # Errors
/// [`ReportError::Write`] naming the file that could not be written.
pub fn write_small_steps(grid: &SmallSteps, dir: &Path) -> Result<Vec<PathBuf>, ReportError> {
    create_dir(dir)?;
    let mut table =
        String::from("integrator,substeps_per_frame,iterations,max_error,stable,work_per_sim_s\n");
    for r in &grid.runs {
        table += &format!(
            "{},{},{},{:.4e},{},{:.4e}\n",
            r.point.integrator,
            r.substeps,
            r.iterations,
            r.point.max_error,
            r.point.stable,
            r.point.work_per_sim_s
        );
    }
    let csv_path = write_text(dir, "small-steps.csv", &table)?;
    let md_path = write_text(dir, "small-steps.md", &grid.markdown())?;
    Ok(vec![csv_path, md_path])
}

/// Writes a plot's RGB buffer (or the message it failed with) as `dir/name`.
fn write_png(
    dir: &Path,
    name: &str,
    drawn: Result<Vec<u8>, String>,
) -> Result<PathBuf, ReportError> {
    let png_path = dir.join(name);
    let rgb = drawn.map_err(|detail| ReportError::Write {
        path: png_path.clone(),
        detail,
    })?;
    let image = image::RgbImage::from_raw(PLOT_SIZE.0, PLOT_SIZE.1, rgb).ok_or_else(|| {
        ReportError::Write {
            path: png_path.clone(),
            detail: "plot buffer has the wrong size".into(),
        }
    })?;
    write_atomically(&png_path, |out| {
        let mut png = std::io::Cursor::new(Vec::new());
        image
            .write_to(&mut png, image::ImageFormat::Png)
            .map_err(|e| e.to_string())?;
        out.write_all(png.get_ref()).map_err(|e| e.to_string())
    })
    .map_err(write_err)?;
    Ok(png_path)
}
