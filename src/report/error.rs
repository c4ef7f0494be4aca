//! Errors of the accuracy report.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// The sweep's settings cannot run.
    #[error("accuracy sweep: {0}")]
    Config(String),
    /// The caller asked the sweep to stop.
    #[error("the accuracy sweep was cancelled")]
    Cancelled,
    /// An output file could not be written; nothing was left half-written.
    #[error("{path}: cannot write: {detail}")]
    Write { path: PathBuf, detail: String },
}
