//! Implicit Euler's substeps on the GPU: each solve's iterations encoded in chunks, with a
//! read of the solve's state between them (see `implicit`).

use crate::sim::{StepError, StepReport};

use super::error::GpuError;
use super::implicit::FIRST_CHUNK;
use super::stepper::GpuStepper;
use super::substep_ends::Start;

impl GpuStepper {
    /// Encodes `substeps` implicit-Euler substeps into `encoder`, submitting it (and going
    /// on in a new one) after each chunk of a solve's iterations, to read whether it goes on
    /// and, at its end, how many it took.
    /// `counting`: each substep is counted for what reads the count.
    ///
    /// # Errors
    /// [`StepError::Device`] when the solve's state cannot be read.
    pub(super) fn implicit_substeps(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        substeps: u32,
        counting: bool,
    ) -> Result<(), StepError> {
        let Some(solve) = self.implicit.as_mut() else {
            return Ok(());
        };
        let cap = self.solver.max_iterations;
        let new_encoder = |device: &wgpu::Device| {
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("cloth implicit substeps"),
            })
        };
        let lost = |e: GpuError| StepError::Device(e.to_string());
        let contacts = &self.contacts;
        for k in 0..substeps {
            let this = &self.groups[self.current];
            let mut encoded = solve.last.max(FIRST_CHUNK).min(cap);
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                self.elements.dispatch(&mut pass, self.current);
                solve.start(&mut pass, this);
                solve.iterate(&mut pass, this, encoded);
            }
            let (done, taken) = loop {
                let full = std::mem::replace(encoder, new_encoder(&self.device));
                let (device, queue) = (&self.device, &self.queue);
                let (done, taken) = solve.submit_and_read(device, queue, full).map_err(lost)?;
                if done || encoded == cap {
                    break (done, taken);
                }
                let more = encoded.min(cap - encoded);
                let mut pass = encoder.begin_compute_pass(&Default::default());
                solve.iterate(&mut pass, this, more);
                encoded += more;
            };
            solve.last = taken;
            self.stats.record(&StepReport {
                force_evals: 1,
                solver_iterations: taken,
                residual: None,
                converged: done,
            });
            let mut pass = encoder.begin_compute_pass(&Default::default());
            solve.finish(&mut pass, this);
            let start = Start::In(self.current);
            if k == 0 && self.held.pending() {
                drop(pass);
                (self.held).start(encoder, (&self.particles, contacts), start);
                pass = encoder.begin_compute_pass(&Default::default());
            }
            contacts.encode(&mut pass, k, start);
            if counting {
                self.kernel.count_substep(&mut pass, this);
            }
            drop(pass);
            self.current = 1 - self.current;
        }
        Ok(())
    }
}
