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

/// `count` values of `buffer` (which `COPY_SRC` allows) from byte `at`, copied to a
/// staging buffer and read back after everything submitted before (tests).
#[cfg(test)]
pub fn read_buffer<T: bytemuck::Pod>(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    at: u64,
    count: usize,
) -> Vec<T> {
    let bytes = (count * size_of::<T>()) as u64;
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("test read-back"),
        size: bytes.max(4),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.copy_buffer_to_buffer(buffer, at, &staging, 0, bytes);
    queue.submit([encoder.finish()]);
    let slice = staging.slice(..);
    map_read(device, &slice).expect("mapped");
    let values = bytemuck::cast_slice(&slice.get_mapped_range().expect("a view")).to_vec();
    staging.unmap();
    values
}
