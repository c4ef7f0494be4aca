//! Writing a report's three files.

use std::path::{Path, PathBuf};

use crate::output::{OutputError, write_atomically, write_bytes};

use super::error::ReportError;
use super::plot::{PLOT_SIZE, draw};
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

/// Writes `accuracy.csv`, `accuracy.md` and `accuracy.png` into `dir` (created if
/// missing) and returns their paths.
///
/// # Errors
/// [`ReportError::Write`] naming the file that could not be written.
pub fn write_report(report: &AccuracyReport, dir: &Path) -> Result<Vec<PathBuf>, ReportError> {
    std::fs::create_dir_all(dir).map_err(|e| ReportError::Write {
        path: dir.to_path_buf(),
        detail: format!("cannot create the directory: {e}"),
    })?;
    let csv_path = dir.join("accuracy.csv");
    write_bytes(&csv_path, csv(report).as_bytes()).map_err(write_err)?;
    let md_path = dir.join("accuracy.md");
    write_bytes(&md_path, markdown(report).as_bytes()).map_err(write_err)?;
    let png_path = dir.join("accuracy.png");
    let rgb = draw(report).map_err(|detail| ReportError::Write {
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
    Ok(vec![csv_path, md_path, png_path])
}
