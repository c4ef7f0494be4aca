//! Errors of rendering and capture.

use std::path::PathBuf;

use crate::device::DeviceError;

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The device layer failed: no adapter, no device, a failed read-back.
    #[error(transparent)]
    Device(#[from] DeviceError),
    #[error("reading the rendered image back failed: {0}")]
    Readback(String),
    /// The directory of an output file does not exist.
    #[error("{path}: the directory {dir} does not exist")]
    MissingDirectory { path: PathBuf, dir: PathBuf },
    /// Writing or encoding an output file failed; nothing was left behind.
    #[error("{path}: cannot write: {detail}")]
    Write { path: PathBuf, detail: String },
    #[error("invalid image size {width}×{height}: {why}")]
    BadSize {
        width: u32,
        height: u32,
        why: String,
    },
}

impl From<crate::output::OutputError> for RenderError {
    fn from(e: crate::output::OutputError) -> Self {
        match e {
            crate::output::OutputError::MissingDirectory { path, dir } => {
                RenderError::MissingDirectory { path, dir }
            }
            crate::output::OutputError::Write { path, detail } => {
                RenderError::Write { path, detail }
            }
        }
    }
}
