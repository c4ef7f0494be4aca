//! The device layer, below both the renderer and the GPU backend: adapters and devices
//! (headless, or the limits a window's device asks for), growable buffers, read-back.

mod buffer;
mod error;
mod headless;
mod limits;
mod readback;

pub use buffer::GrowBuffer;
pub use error::DeviceError;
pub use headless::{AdapterPreference, HeadlessDevice, describe_adapter};
pub use limits::{compute_limits, window_device_descriptor};
pub use readback::map_read;
#[cfg(test)]
pub use readback::read_buffer;
