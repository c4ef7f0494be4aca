//! A GPU buffer that is written in place every frame and reallocated only when it must grow.

use wgpu::util::DeviceExt;

/// A device buffer written in place, grown (reallocated) only when the data outgrow it.
pub struct GrowBuffer {
    label: &'static str,
    usage: wgpu::BufferUsages,
    buffer: wgpu::Buffer,
    /// Bytes written by the last [`GrowBuffer::write`].
    len: u64,
}

impl GrowBuffer {
    pub fn new(
        device: &wgpu::Device,
        label: &'static str,
        usage: wgpu::BufferUsages,
        capacity: u64,
    ) -> Self {
        // COPY_SRC: what the device wrote can be read back (tests).
        let usage = usage | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: capacity.max(256),
            usage,
            mapped_at_creation: false,
        });
        Self {
            label,
            usage,
            buffer,
            len: 0,
        }
    }

    /// Uploads `data`; reallocates (to twice the need) only when it does not fit. Returns
    /// whether the buffer was reallocated.
    pub fn write(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, data: &[u8]) -> bool {
        let needed = data.len() as u64;
        let grew = needed > self.buffer.size();
        if grew {
            self.buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(self.label),
                contents: &[data, &vec![0u8; data.len()]].concat(),
                usage: self.usage,
            });
        } else if needed > 0 {
            queue.write_buffer(&self.buffer, 0, data);
        }
        self.len = needed;
        grew
    }

    /// Makes room for `bytes` that the device will write (a compute pass), reallocating (to
    /// twice the need) only when they do not fit.
    pub fn reserve(&mut self, device: &wgpu::Device, bytes: u64) {
        if bytes > self.buffer.size() {
            self.buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(self.label),
                size: bytes * 2,
                usage: self.usage,
                mapped_at_creation: false,
            });
        }
        self.len = bytes;
    }

    /// The whole buffer, to bind.
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// The written bytes.
    pub fn slice(&self) -> wgpu::BufferSlice<'_> {
        self.buffer.slice(..self.len.max(1).min(self.buffer.size()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::device::{AdapterPreference, HeadlessDevice};

    #[test]
    fn reallocates_only_to_grow() {
        let gpu = HeadlessDevice::open(AdapterPreference::Software).expect("software adapter");
        let (device, queue) = (&gpu.device, &gpu.queue);
        let mut buffer = GrowBuffer::new(device, "test", wgpu::BufferUsages::VERTEX, 1024);
        assert!(
            !buffer.write(device, queue, &[1u8; 1024]),
            "fits the initial allocation"
        );
        assert!(
            !buffer.write(device, queue, &[2u8; 16]),
            "shrinking never reallocates"
        );
        assert!(
            buffer.write(device, queue, &[3u8; 4096]),
            "growing reallocates"
        );
        let capacity = buffer.buffer.size();
        assert!(capacity >= 8192, "with room to spare: {capacity}");
        assert!(
            !buffer.write(device, queue, &[4u8; 6000]),
            "then fits again"
        );
        assert_eq!(buffer.buffer.size(), capacity);
    }
}
