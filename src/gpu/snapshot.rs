//! The GPU guard's rollback points: copies of the particle buffer kept on the device, so
//! a rollback moves no state across the bus.

use crate::sim::Snapshot;

/// A particle buffer's copy on the device, with the simulated time it holds.
#[derive(Clone, Debug, Default)]
pub(super) struct DeviceSnapshot {
    /// The device, its queue and the copy; `None` until something is copied in.
    copy: Option<(wgpu::Device, wgpu::Queue, wgpu::Buffer)>,
    /// Seconds.
    pub(super) time: f64,
    /// The pairs prescribed motion had forced together by then (self-contact's count).
    pub(super) forced: u64,
}

impl DeviceSnapshot {
    /// A snapshot of `size` bytes on `device`, holding nothing yet.
    pub(super) fn new(device: &wgpu::Device, queue: &wgpu::Queue, size: u64) -> Self {
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("particles snapshot"),
            size,
            usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            copy: Some((device.clone(), queue.clone(), buffer)),
            time: 0.0,
            forced: 0,
        }
    }

    /// Encodes the copy of `particles` into the snapshot, which then holds `time` and
    /// `forced` pairs forced.
    pub(super) fn take(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        particles: &wgpu::Buffer,
        (time, forced): (f64, u64),
    ) {
        if let Some((_, _, buffer)) = &self.copy {
            encoder.copy_buffer_to_buffer(particles, 0, buffer, 0, None);
        }
        (self.time, self.forced) = (time, forced);
    }

    /// Encodes the copy of the snapshot into `particles`; returns the time it holds (the
    /// caller sets the forced pairs' count back to [`DeviceSnapshot::forced`]).
    pub(super) fn restore(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        particles: &wgpu::Buffer,
    ) -> f64 {
        if let Some((_, _, buffer)) = &self.copy {
            encoder.copy_buffer_to_buffer(buffer, 0, particles, 0, None);
        }
        self.time
    }
}

impl Snapshot for DeviceSnapshot {
    /// Copies on the device, in a submission of its own (queued after the frames before it).
    fn copy_from(&mut self, from: &Self) {
        (self.time, self.forced) = (from.time, from.forced);
        let Some((device, queue, source)) = &from.copy else {
            self.copy = None;
            return;
        };
        let fits = matches!(&self.copy, Some((_, _, b)) if b.size() == source.size());
        if !fits {
            *self = Self::new(device, queue, source.size());
            (self.time, self.forced) = (from.time, from.forced);
        }
        let Some((_, _, buffer)) = &self.copy else {
            return;
        };
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("particles snapshot"),
        });
        encoder.copy_buffer_to_buffer(source, 0, buffer, 0, None);
        queue.submit([encoder.finish()]);
    }
}
