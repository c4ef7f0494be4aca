//! The stability guard's measure of a frame on the device (`shaders/health.wgsl`): one
//! reduction over the particles and their spring ends gives what the CPU guard measures in
//! its pass over the state, and 32 bytes come back per frame instead of the whole state.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::device::map_read;
use crate::sim::Motion;

use super::error::GpuError;
use super::kernel::{LAYOUT, Slot, WORKGROUP, bind, layout, pipelines};

/// The shader's source.
const SOURCE: &str = include_str!("../../shaders/health.wgsl");

/// One record of the reduction (the shader's `Health`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
struct Record {
    /// Fastest speed² (m²/s²), largest strain, lowest height (m), kinetic energy (J).
    motion: [f32; 4],
    /// 1 in the first when a position or velocity is not finite.
    flags: [u32; 4],
}

/// The shader's `Params`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
struct Params {
    up: [f32; 4],
    counts: [u32; 4],
}

/// What the device measured of a state: the guard's [`Motion`] and the largest relative
/// extension of a spring it steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Health {
    pub motion: Motion,
    pub strain: f32,
}

/// What a submission does beside its substeps, for the guard.
#[derive(Clone, Copy)]
pub(super) struct Watch {
    /// Copy the state the substeps start from into the frame's start snapshot.
    pub(super) keep_start: bool,
    /// Measure the state they end at (see [`HealthKernel`]).
    pub(super) measure: bool,
}

impl Watch {
    /// Neither: a frame without the guard, a bare substep.
    pub(super) const OFF: Self = Self {
        keep_start: false,
        measure: false,
    };
}

/// The reduction's pipelines, buffers and bind groups (one per particle buffer).
pub(super) struct HealthKernel {
    partial: wgpu::ComputePipeline,
    total: wgpu::ComputePipeline,
    groups: [wgpu::BindGroup; 2],
    uniform: wgpu::Buffer,
    records: wgpu::Buffer,
    readback: wgpu::Buffer,
    params: Params,
}

/// Bytes of one record.
const RECORD: u64 = size_of::<Record>() as u64;

impl HealthKernel {
    /// The reduction over `count` particles in either of `particles`, with the spring ends
    /// `offsets` and `neighbours` the substep gathers.
    pub(super) fn new(
        device: &wgpu::Device,
        particles: &[wgpu::Buffer; 2],
        (offsets, neighbours): (&wgpu::Buffer, &wgpu::Buffer),
        count: u32,
    ) -> Self {
        use Slot::{Read, Uniform, Write};
        let layout = layout(device, "cloth health", &[Uniform, Read, Read, Read, Write]);
        let one: &[&wgpu::BindGroupLayout] = &[&layout];
        let [partial, total] = pipelines(
            device,
            "cloth health",
            &format!("{LAYOUT}{SOURCE}"),
            [("partial", one), ("total", one)],
        );
        let first = count.div_ceil(WORKGROUP).max(1);
        let buffer = |label, size, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        use wgpu::BufferUsages as U;
        let uniform = buffer(
            "cloth health params",
            size_of::<Params>() as u64,
            U::UNIFORM | U::COPY_DST,
        );
        let records = buffer(
            "cloth health records",
            (first as u64 + 1) * RECORD,
            U::STORAGE | U::COPY_SRC,
        );
        let readback = buffer("cloth health readback", RECORD, U::MAP_READ | U::COPY_DST);
        let group = |p: &wgpu::Buffer| {
            let buffers = [&uniform, p, offsets, neighbours, &records];
            bind(device, "cloth health", &layout, &buffers)
        };
        let groups = [group(&particles[0]), group(&particles[1])];
        Self {
            partial,
            total,
            groups,
            uniform,
            records,
            readback,
            params: Params {
                up: [0.0, 1.0, 0.0, 0.0],
                counts: [count, first, 0, 0],
            },
        }
    }

    /// Sets the guard's unit `up` (heights are measured along it).
    pub(super) fn set_up(&mut self, queue: &wgpu::Queue, up: Vec3) {
        self.params.up = [up.x, up.y, up.z, 0.0];
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&self.params));
    }

    /// Encodes the reduction over particle buffer `current` and the copy of its result
    /// where [`HealthKernel::read`] finds it.
    pub(super) fn encode(&self, encoder: &mut wgpu::CommandEncoder, current: usize) {
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("cloth health"),
                timestamp_writes: None,
            });
            pass.set_bind_group(0, &self.groups[current], &[]);
            pass.set_pipeline(&self.partial);
            pass.dispatch_workgroups(self.params.counts[1], 1, 1);
            pass.set_pipeline(&self.total);
            pass.dispatch_workgroups(1, 1, 1);
        }
        let last = self.params.counts[1] as u64 * RECORD;
        encoder.copy_buffer_to_buffer(&self.records, last, &self.readback, 0, RECORD);
    }

    /// The result of the last submitted [`HealthKernel::encode`] (waits for the device).
    ///
    /// # Errors
    /// [`GpuError::Readback`] when the device fails or the mapping is refused.
    pub(super) fn read(&self, device: &wgpu::Device) -> Result<Health, GpuError> {
        let slice = self.readback.slice(..);
        map_read(device, &slice).map_err(|e| GpuError::Readback(e.to_string()))?;
        let record = {
            let view = slice
                .get_mapped_range()
                .map_err(|e| GpuError::Readback(e.to_string()))?;
            *bytemuck::from_bytes::<Record>(&view)
        };
        self.readback.unmap();
        let [speed2, strain, lowest, joules] = record.motion;
        Ok(Health {
            motion: Motion {
                finite: record.flags[0] == 0,
                speed: speed2.sqrt(),
                joules: joules as f64,
                lowest,
            },
            strain,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reduction's shader sizes its workgroups as the host dispatches them (the spring
    /// ends it decodes are the layout's, compared in `kernel`).
    #[test]
    fn the_health_shader_and_the_host_agree_on_their_constants() {
        assert!(SOURCE.contains(&format!("const GROUP: u32 = {WORKGROUP}u;")));
        assert_eq!(SOURCE.matches("@workgroup_size(64)").count(), 2);
        assert_eq!(WORKGROUP, 64);
    }
}
