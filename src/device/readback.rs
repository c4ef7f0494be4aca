//! Reading buffers back from the device.

use super::error::DeviceError;

/// Maps `slice` of a `MAP_READ` buffer for reading and waits until it is (after the
/// commands that fill it were submitted).
///
/// # Errors
/// [`DeviceError::Readback`] when the device fails or the mapping is refused.
pub fn map_read(device: &wgpu::Device, slice: &wgpu::BufferSlice<'_>) -> Result<(), DeviceError> {
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| DeviceError::Readback(e.to_string()))?;
    rx.recv()
        .map_err(|e| DeviceError::Readback(e.to_string()))?
        .map_err(|e| DeviceError::Readback(e.to_string()))
}
