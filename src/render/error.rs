//! Errors of rendering and capture.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// No graphics adapter at all.
    #[error(
        "no graphics adapter found ({detail}). On Linux without a GPU install Mesa's software \
         rasteriser (Debian: `apt-get install libegl1 libgl1-mesa-dri`), or pick a backend with \
         WGPU_BACKEND=vulkan|gl"
    )]
    NoAdapter { detail: String },
    #[error("the graphics device could not be created: {0}")]
    Device(String),
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
