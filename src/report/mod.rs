//! What accuracy costs in time: sweeps of every integrator over step sizes against a
//! reference, their tables (CSV, Markdown) and plot (PNG).

mod config;
mod cost;
mod error;
mod files;
mod frontier;
mod map;
mod map_plot;
mod measure;
mod order;
mod plot;
mod point;
mod reference;
mod shape;
mod small_steps;
mod sweep;
mod table;

pub use config::{DEFAULT_SUBSTEPS, DEFAULT_TOLERANCE, ORDERS_SCENE, ORDERS_SUBSTEPS, SweepConfig};
pub use cost::{UnitCosts, Work, calibrate};
pub use error::ReportError;
pub use files::{write_map, write_report, write_small_steps};
pub use frontier::{COST_RESOLUTION, frontier, recommend};
pub use map::{MAP_SCALES, MapPoint, StabilityMap, stability_map};
pub use map_plot::draw_map;
pub use measure::{
    BLOW_UP_SPEED, ContactMeasures, Record, Trajectory, position_error, run, undamped,
};
pub use order::{ASYMPTOTIC_ERROR, ObservedOrder, RESOLVED, observed_order};
pub use plot::{PLOT_SIZE, draw, integrator_color};
pub use point::Point;
pub use reference::{REFERENCE_REFINEMENT, Reference, reference};
pub use shape::{Judged, ShapeStats, shape_error};
pub use small_steps::{Duel, GridRun, SMALL_STEPS_AXIS, SmallSteps, small_steps};
pub use sweep::{AccuracyReport, Progress, StableLimit, measure, sweep};
pub use table::{CSV_COLUMNS, choice_sentence, csv, markdown};
