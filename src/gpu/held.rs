//! A pinned particle the caller moved between frames (the held one of a grab): the state
//! has it where it was moved to, so the integrator steps the cloth with it there, and the
//! contacts of the frame's first substep see its path from where it was, as the CPU's do
//! (`CpuStepper::start_outside`): its start there is written over in the copies they read
//! the substep's start from, after the integrator has read them.

use glam::Vec3;

use super::contacts::Contacts;
use super::packing::Particle;
use super::substep_ends::Start;

/// The move ([`crate::sim::StepBackend::moved_outside`]), and where it started on the
/// device (one position, sent before each run).
pub(super) struct HeldMove {
    pub(super) moved: Option<(u32, Vec3)>,
    from: wgpu::Buffer,
}

impl HeldMove {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        let from = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("held particle's start"),
            size: 16,
            usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self { moved: None, from }
    }

    /// Before a run: where the move started, sent to the device when there is one.
    pub(super) fn send(&self, queue: &wgpu::Queue) {
        if let Some((_, from)) = self.moved {
            let bytes = from.extend(0.0).to_array();
            queue.write_buffer(&self.from, 0, bytemuck::cast_slice(&bytes));
        }
    }

    /// Whether the run's first substep has a move to start.
    pub(super) fn pending(&self) -> bool {
        self.moved.is_some()
    }

    /// After the first substep's integrator (between two compute passes: a copy cannot run
    /// inside one), where `start` says the contacts read its start from (`particles[i]`,
    /// or the copies `contacts` keep): the moved particle starts where the move started.
    pub(super) fn start(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        (particles, contacts): (&[wgpu::Buffer; 2], &Contacts),
        start: Start,
    ) {
        let Some((p, _)) = self.moved else {
            return;
        };
        let at = u64::from(p) * std::mem::size_of::<Particle>() as u64;
        let (live, kept) = match start {
            Start::In(i) => (Some(&particles[i]), None),
            Start::Kept(_) => (None, Some(contacts.kept_starts())),
        };
        for copy in live.into_iter().chain(kept.into_iter().flatten()) {
            // The position's three components; its fourth (the inverse mass) stays.
            encoder.copy_buffer_to_buffer(&self.from, 0, copy, at, Some(12));
        }
    }
}
