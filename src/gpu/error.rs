//! Why the GPU backend cannot run a scene, or stopped.

/// Why the GPU backend cannot run a scene.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GpuError {
    #[error("the GPU backend {0}")]
    Unsupported(String),
    #[error("the GPU backend could not read its state back: {0}")]
    Readback(String),
    /// No adapter or device to step on (what the device layer said).
    #[error("no GPU device: {0}")]
    Device(String),
}

impl From<crate::device::DeviceError> for GpuError {
    fn from(e: crate::device::DeviceError) -> Self {
        GpuError::Device(e.to_string())
    }
}
