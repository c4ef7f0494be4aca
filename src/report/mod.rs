//! What accuracy costs in time: sweeps of every integrator over step sizes against a
//! reference, their tables (CSV, Markdown) and plot (PNG).

mod cost;
mod error;
mod files;
mod frontier;
mod measure;
mod plot;
mod point;
mod sweep;
mod table;

pub use cost::{UnitCosts, Work, calibrate};
pub use error::ReportError;
pub use files::write_report;
pub use frontier::{COST_RESOLUTION, frontier, recommend};
pub use measure::{BLOW_UP_SPEED, Record, Trajectory, position_error, run, undamped};
pub use plot::{PLOT_SIZE, draw, integrator_color};
pub use point::Point;
pub use sweep::{
    AccuracyReport, DEFAULT_SUBSTEPS, DEFAULT_TOLERANCE, Progress, REFERENCE_REFINEMENT, Reference,
    StableLimit, SweepConfig, measure, sweep,
};
pub use table::{CSV_COLUMNS, choice_sentence, csv, markdown};
