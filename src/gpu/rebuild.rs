//! What the GPU stepper sends or builds anew when the state or its parameters change: the
//! state, XPBD's constraints or VBD's stencil, the element pass's buffers, the handles'
//! stamps on the device's state, and the substep's bind groups over them.

use crate::cloth::{ClothModel, ClothState};
use crate::sim::{Effect, IntegratorKind, StepError};

use super::elements::{elements_wanted, pack_elements};
use super::error::GpuError;
use super::implicit::{ImplicitPass, MOVED_FLAG};
use super::packing::Particle;
use super::stepper::GpuStepper;
use super::substep_ends::Memory;
use super::support::fits_elements;
use super::vbd::VbdPass;
use super::xpbd::XpbdPass;

impl GpuStepper {
    /// Sends `state` to the device, each particle stamped with its handle's slot.
    pub(super) fn upload_state(&mut self, model: &ClothModel, state: &ClothState) {
        let stamps = self.carried.stamps(state.pos.len());
        let data: Vec<Particle> = (state.pos.iter().zip(&state.vel))
            .zip(model.inv_mass.iter().zip(stamps))
            .map(|((x, v), (&w, slot))| Particle {
                x: [x.x, x.y, x.z, w],
                v: [v.x, v.y, v.z, slot],
            })
            .collect();
        if !data.is_empty() {
            for buffer in std::iter::once(&self.particles[self.current]).chain(&self.display) {
                self.queue
                    .write_buffer(buffer, 0, bytemuck::cast_slice(&data));
            }
        }
        self.upload = false;
        self.restamp = false;
        self.forget_guesses();
        self.behind = false;
    }

    /// Stamps the device's state with the handles' slots anew (the handles changed): the
    /// latest state read back and sent again.
    pub(super) fn restamp(
        &mut self,
        model: &ClothModel,
        state: &ClothState,
    ) -> Result<(), StepError> {
        let latest = self.latest(state)?;
        self.upload_state(model, &latest);
        // The caller's state is still the older one.
        self.behind = true;
        Ok(())
    }

    /// A copy of the latest state: the device's when it stepped past `state` (read back
    /// without bringing `state` up to date), else `state`.
    fn latest(&mut self, state: &ClothState) -> Result<ClothState, StepError> {
        let mut latest = state.clone();
        if self.behind {
            self.read_back(&mut latest)
                .map_err(|e| StepError::Device(e.to_string()))?;
            self.behind = true;
        }
        Ok(latest)
    }

    /// The solver's data from the forces' springs, and the substep's bind groups that read
    /// it: XPBD's constraints coloured as the CPU colours them from the positions the next
    /// step starts from (the caller's state, or the device's when that is ahead); VBD's
    /// stencil, coloured by particle number.
    pub(super) fn rebuild_solver(
        &mut self,
        model: &ClothModel,
        state: &ClothState,
    ) -> Result<(), StepError> {
        let refused = |e: GpuError| StepError::Unsupported(e.to_string());
        if self.integrator == IntegratorKind::ImplicitEuler {
            if self.implicit.is_none() {
                let pass = ImplicitPass::new(&self.device, &self.kernel.layout, self.count);
                self.implicit = Some(self.refuse_unless(pass)?);
            }
            if let Some(pass) = &mut self.implicit {
                pass.fresh = true;
                self.params.solver = pass.words(&self.solver);
            }
            self.queue
                .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&self.params));
            self.regroup();
            self.solver_stale = false;
            return Ok(());
        }
        if self.integrator == IntegratorKind::Vbd {
            let springs = Some((model, &self.forces));
            self.vbd =
                VbdPass::new(&self.device, &self.queue, &self.kernel, springs).map_err(refused)?;
            let [spans, links, memory] = self.vbd.starts;
            self.params.solver = [spans, links, memory, 1];
            self.vbd_fresh = true;
            self.regroup();
            self.solver_stale = false;
            return Ok(());
        }
        let positions = self.latest(state)?.pos;
        let halves = self.forces.constraints(model).halves(&positions);
        let pass = XpbdPass::new(&self.device, &self.queue, &self.kernel, Some(&halves));
        self.xpbd = self.refuse_unless(pass)?;
        self.params.counts[2] = self.xpbd.count;
        self.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&self.params));
        self.regroup();
        self.solver_stale = false;
        Ok(())
    }

    /// The substep's bind groups for the buffers in place.
    pub(super) fn regroup(&mut self) {
        let fixed = [
            &self.uniform,
            &self.offsets,
            &self.neighbours,
            &self.classes,
        ];
        let extra = [
            &self.elements.forces,
            &self.elements.incidence,
            match (self.integrator, &self.implicit) {
                (IntegratorKind::Vbd, _) => &self.vbd.stencil,
                (IntegratorKind::ImplicitEuler, Some(pass)) => &pass.solve,
                _ => &self.xpbd.constraints,
            },
        ];
        self.groups = self
            .kernel
            .groups(&self.device, &self.particles, fixed, extra);
        let words = self.contact_memory().1.cloned();
        (self.contacts).attach_solve(&self.device, &self.particles, words.as_ref());
    }

    /// What the integrator in effect keeps that a contact changes (see [`Memory`]), and
    /// the buffer it keeps it in: implicit Euler's solve, VBD's stencil.
    pub(super) fn contact_memory(&self) -> (Memory, Option<&wgpu::Buffer>) {
        match (self.integrator, &self.implicit) {
            (IntegratorKind::ImplicitEuler, Some(pass)) => {
                (Memory::Guess(MOVED_FLAG), Some(&pass.solve))
            }
            (IntegratorKind::Vbd, _) => (
                Memory::Accelerations(self.params.solver[2]),
                Some(&self.vbd.stencil),
            ),
            _ => (Memory::None, None),
        }
    }

    /// The element pass for `effects` (the forces' terms already theirs): packed anew, with
    /// the substep's bind groups that read its slots, only when wind or dihedral bending
    /// came or went; retuned otherwise.
    pub(super) fn rebuild_elements(&mut self, model: &ClothModel, effects: &[Effect]) {
        let wanted = elements_wanted(effects, &self.forces);
        if wanted != self.elements_for {
            let packed = pack_elements(model, &self.forces, wanted.0);
            if let Err(e) = fits_elements(&self.device.limits(), &packed) {
                self.unsupported = Some(e.to_string());
                return;
            }
            let (device, queue) = (&self.device, &self.queue);
            self.elements.pack(device, queue, &self.particles, &packed);
            self.elements_for = wanted;
            self.regroup();
        }
        self.elements.tune(effects);
    }

    /// After a frame that stood: the mesh obstacles fitted again where the cloth of
    /// `model` has outgrown their fit ([`Contacts::refit`](super::contacts::Contacts::refit)),
    /// the cloth read back into `state` for it where the frame left it behind.
    ///
    /// # Errors
    /// [`GpuError::Readback`] when the cloth cannot be read; as
    /// [`ObstaclePass::new`](super::obstacles::ObstaclePass::new).
    pub(super) fn refit_obstacles(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
    ) -> Result<(), GpuError> {
        if !self.contacts.watch_growth() || self.unsupported.is_some() {
            return Ok(());
        }
        if self.behind {
            self.read_back(state)?;
        }
        let solve = self.contact_memory().1.cloned();
        let gpu = (&self.device, &self.queue, &self.kernel);
        let cloth = (model, &self.effects[..], &state.pos[..]);
        (self.contacts).refit(gpu, &self.particles, cloth, solve.as_ref())?;
        Ok(())
    }

    /// `built`, or the reason it could not be, kept (every later frame fails with it).
    fn refuse_unless<T>(&mut self, built: Result<T, GpuError>) -> Result<T, StepError> {
        built.map_err(|e| {
            let why = e.to_string();
            self.unsupported = Some(why.clone());
            StepError::Unsupported(why)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::GpuStepper;
    use crate::device::{AdapterPreference, HeadlessDevice};
    use crate::sim::effects::{growing_cloth, rail, rising_roof};
    use crate::sim::{Effect, StepBackend};

    /// How many sharp edges the device keeps a cloth of 10 cm quads off `obstacle` (the
    /// cloth 2 m up, `thickness` off solids): at rest, and after a frame that ends with the
    /// cloth grown to 1.8 times its rest size (`growing_cloth`), the state read back every
    /// frame or not.
    fn kept_off_at_rest_and_grown(
        obstacle: Effect,
        thickness: f32,
        read_every_frame: bool,
    ) -> (u32, u32) {
        let gpu = HeadlessDevice::open(AdapterPreference::Software).expect("an adapter");
        let (model, params, mut state) = growing_cloth(thickness);
        let (device, queue) = (&gpu.device, &gpu.queue);
        let effects = [obstacle];
        let mut stepper =
            GpuStepper::new(device, queue, &model, &params, &effects, read_every_frame)
                .expect("stepper");
        let kept_off = |stepper: &GpuStepper| {
            let obstacles = stepper
                .contacts
                .obstacles
                .as_ref()
                .expect("a mesh obstacle");
            obstacles.sharp_edges()[0]
        };
        let at_rest = kept_off(&stepper);
        stepper.frame(&model, &mut state).expect("a frame");
        (at_rest, kept_off(&stepper))
    }

    /// The device fits its mesh obstacles again as the CPU does
    /// (`a_frame_that_ends_with_the_cloth_grown_fits_the_obstacles_again` and
    /// `a_sequence_flat_at_first_is_fitted_again_as_the_cloth_grows`): the rail's 40
    /// ridges kept off beside its 80 end creases once the cloth has grown past its fit,
    /// with the state left on the device (read back for the fit); the rising roof's 4
    /// ridges beside the block's 12 creases, with the state read back every frame.
    #[test]
    fn a_frame_that_ends_with_the_cloth_grown_fits_the_obstacles_again_on_the_device() {
        assert_eq!(kept_off_at_rest_and_grown(rail(), 0.04, false), (80, 120));
        let dir = tempfile::tempdir().expect("a temporary folder");
        let roof = rising_roof(dir.path());
        assert_eq!(kept_off_at_rest_and_grown(roof, 0.02, true), (12, 16));
    }
}
