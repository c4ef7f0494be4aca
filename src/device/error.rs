//! What can go wrong with the device itself.

/// An adapter, device or read-back failure.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DeviceError {
    /// No graphics adapter at all.
    #[error(
        "no graphics adapter found ({detail}). On Linux without a GPU install Mesa's software \
         rasteriser (Debian: `apt-get install libegl1 libgl1-mesa-dri`), or pick a backend with \
         WGPU_BACKEND=vulkan|gl"
    )]
    NoAdapter { detail: String },
    #[error("the graphics device could not be created: {0}")]
    Open(String),
    /// Mapping a buffer for reading failed, or the device was lost meanwhile.
    #[error("reading back from the device failed: {0}")]
    Readback(String),
}
