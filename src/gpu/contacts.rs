//! The contacts that run after each substep on the GPU, in order: the spheres' faces
//! where self-contact does not keep them out (`self_contact/faces.rs`), the mesh
//! obstacles (`obstacles.rs`), then the cloth against itself (`self_contact.rs`), whose
//! cuts come last so that nothing after them can undo its guarantee.

use glam::Vec3;

use crate::cloth::ClothModel;
use crate::sim::{ContactConfig, Effect, Reach, SimParams};

use super::error::GpuError;
use super::kernel::SubstepKernel;
use super::obstacles::ObstaclePass;
use super::packing::Params;
use super::self_contact::{Counters, FacePass, SelfPass};
use super::substep_ends::{Memory, Start};

/// The scene's mesh obstacles and self-contact on the device, where it has them.
#[derive(Default)]
pub(super) struct Contacts {
    pub(super) obstacles: Option<ObstaclePass>,
    pub(super) own: Option<SelfPass>,
    /// The spheres' face pass, in a scene with a sphere and no self-contact (whose pushes
    /// keep the faces out themselves).
    faces: Option<FacePass>,
    /// What the mesh obstacles were last fitted to, and the contacts' settings they were
    /// packed with.
    reach: Reach,
    contact: ContactConfig,
}

impl Contacts {
    /// The passes for `model` under `effects` and `params`, over the particles in
    /// `particles`: each mesh obstacle as this cloth meets it at rest, as on the CPU
    /// ([`Reach::fit`]), until the cloth outgrows that ([`Contacts::refit`]).
    ///
    /// # Errors
    /// As [`ObstaclePass::new`] and [`SelfPass::new`].
    pub(super) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        kernel: &SubstepKernel,
        particles: &[wgpu::Buffer; 2],
        (model, effects, params): (&ClothModel, &[Effect], &SimParams),
    ) -> Result<Self, GpuError> {
        let mut reach = Reach::default();
        let fitted = reach.fit(effects, model, params.contact.offset);
        let scene = (model, &fitted[..], &params.contact);
        let obstacles = ObstaclePass::new(device, queue, kernel, particles, scene)?;
        let own = effects.iter().find_map(|e| match e {
            Effect::SelfCollision(own) => Some(own),
            _ => None,
        });
        let sphere = (effects.iter()).any(|e| matches!(e, Effect::Sphere(_)));
        let (own, faces) = match own {
            Some(own) => (SelfPass::new(device, queue, particles, model, own)?, None),
            None if sphere => (
                None,
                FacePass::new((device, queue, kernel), particles, model),
            ),
            None => (None, None),
        };
        let contact = params.contact;
        let mut contacts = Self {
            obstacles,
            own,
            faces,
            reach,
            contact,
        };
        contacts.tell_pushes(device);
        Ok(contacts)
    }

    /// Whether a frame's end must show the cloth to [`Contacts::refit`]: some mesh
    /// obstacle has gentle parts that a grown cloth could reach.
    pub(super) fn watch_growth(&self) -> bool {
        self.reach.watches()
    }

    /// The mesh obstacles of `effects` fitted again where the cloth of `model` at `pos`
    /// has outgrown their last fit, as on the CPU ([`Reach::outgrown`]): their pass built
    /// anew over `particles`, binding the solver's words `solve`. Whether it was.
    ///
    /// # Errors
    /// As [`ObstaclePass::new`].
    pub(super) fn refit(
        &mut self,
        (device, queue, kernel): (&wgpu::Device, &wgpu::Queue, &SubstepKernel),
        particles: &[wgpu::Buffer; 2],
        (model, effects, pos): (&ClothModel, &[Effect], &[Vec3]),
        solve: Option<&wgpu::Buffer>,
    ) -> Result<bool, GpuError> {
        let Some(fitted) = self.reach.outgrown(effects, pos) else {
            return Ok(false);
        };
        let scene = (model, &fitted[..], &self.contact);
        self.obstacles = ObstaclePass::new(device, queue, kernel, particles, scene)?;
        if let Some(obstacles) = self.obstacles.as_mut() {
            obstacles.attach_solve(device, particles, solve);
        }
        self.tell_pushes(device);
        Ok(true)
    }

    /// Binds to the obstacles' second run where self-contact says whether its pushes
    /// moved anything (its counters, which a grown room replaces).
    fn tell_pushes(&mut self, device: &wgpu::Device) {
        if let (Some(obstacles), Some(own)) = (self.obstacles.as_mut(), self.own.as_ref()) {
            obstacles.attach_pushed(device, own.counters());
        }
    }

    /// These passes, with self-contact's settings for tests as in `old`: how often its
    /// pushes sweep and in how many rounds, whether one workgroup runs it whatever the
    /// size, and its room; and its count of forced pairs.
    pub(super) fn tuned_as(mut self, old: &Contacts) -> Self {
        if let (Some(own), Some(old)) = (self.own.as_mut(), old.own.as_ref()) {
            (own.sweeps, own.push_rounds) = (old.sweeps, old.push_rounds);
            (own.forced, own.room) = (old.forced, old.room);
            own.forced_pairs = old.forced_pairs;
        }
        self
    }

    /// Before a submission of `substeps` substeps of `substep` seconds from `time`: the
    /// obstacles' poses, self-contact's room, its uniform and the face pass's (with the
    /// step's colliders, from `cloth`, its uniform), and what the integrator keeps that the
    /// contacts change (`memory`).
    ///
    /// # Errors
    /// As [`ObstaclePass::write_poses`] and [`SelfPass::prepare`].
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (substeps, time, substep): (u32, f64, f32),
        memory: Memory,
        cloth: &Params,
    ) -> Result<(), GpuError> {
        if let Some(obstacles) = self.obstacles.as_mut() {
            obstacles.write_poses(device, queue, (substeps, time, substep), memory)?;
        }
        if let Some(own) = self.own.as_mut() {
            own.prepare(device, queue, substep, memory, cloth)?;
        }
        if let Some(faces) = self.faces.as_mut() {
            faces.prepare(queue, substep, memory, cloth);
        }
        self.tell_pushes(device);
        Ok(())
    }

    /// Binds the solver's words the contacts tell of what they moved.
    pub(super) fn attach_solve(
        &mut self,
        device: &wgpu::Device,
        particles: &[wgpu::Buffer; 2],
        solve: Option<&wgpu::Buffer>,
    ) {
        if let Some(obstacles) = self.obstacles.as_mut() {
            obstacles.attach_solve(device, particles, solve);
        }
        if let Some(own) = self.own.as_mut() {
            own.attach_solve(device, particles, solve);
        }
        if let Some(faces) = self.faces.as_mut() {
            faces.attach_solve(device, particles, solve);
        }
    }

    /// Records copies of the substep's start, `particles[at]`, for an integrator that
    /// writes its end over it.
    pub(super) fn keep_start(&self, pass: &mut wgpu::ComputePass<'_>, at: usize) {
        if let Some(obstacles) = &self.obstacles {
            obstacles.keep_start(pass, at);
        }
        if let Some(own) = &self.own {
            own.keep_start(pass, at);
        }
    }

    /// The copies of the substep's start that [`Contacts::keep_start`] makes.
    pub(super) fn kept_starts(&self) -> impl Iterator<Item = &wgpu::Buffer> {
        let obstacles = self.obstacles.as_ref().map(ObstaclePass::kept);
        obstacles
            .into_iter()
            .chain(self.own.as_ref().map(SelfPass::kept))
    }

    /// Records substep `k`'s contacts, where `start` says its start and end are.
    pub(super) fn encode(&self, pass: &mut wgpu::ComputePass<'_>, k: u32, start: Start) {
        if let Some(faces) = &self.faces {
            faces.encode(pass, start);
        }
        if let Some(obstacles) = &self.obstacles {
            if let Some(own) = &self.own {
                own.before_obstacles(pass, start);
            }
            obstacles.encode(pass, (k, false), start);
        }
        if let Some(own) = &self.own {
            own.encode_pushes(pass, start, self.obstacles.is_some());
            // What the pushes pressed into a mesh obstacle goes back out, before the cuts
            // (where they moved something, as on the CPU).
            if let Some(obstacles) = &self.obstacles {
                obstacles.encode(pass, (k, true), start);
            }
            own.encode_cuts(pass, start);
        }
    }

    /// Records what is read back after the submission (self-contact's counters).
    pub(super) fn after_submission(&mut self, encoder: &mut wgpu::CommandEncoder) {
        if let Some(own) = self.own.as_mut() {
            own.copy_counters(encoder);
        }
    }

    /// The pairs prescribed motion forced together over the submissions read, where the
    /// scene has self-contact.
    pub(super) fn forced_pairs(&self) -> Option<u64> {
        self.own.as_ref().map(|own| own.forced_pairs)
    }

    /// The state went back to a rollback point where `forced` pairs had been forced.
    pub(super) fn roll_back_forced(&mut self, forced: u64) {
        if let Some(own) = self.own.as_mut() {
            own.roll_back_forced(forced);
        }
    }

    /// What self-contact's last submission asked for and measured, read once (`None`
    /// where there is nothing to read).
    ///
    /// # Errors
    /// [`GpuError::Readback`] when the counters cannot be read.
    pub(super) fn read_counters(
        &mut self,
        device: &wgpu::Device,
    ) -> Result<Option<Counters>, GpuError> {
        match self.own.as_mut() {
            Some(own) => own.read_counters(device),
            None => Ok(None),
        }
    }

    /// Whether self-contact's room for pairs or grid entries ran out in a submission that
    /// `asked` for so many, the room left as it is.
    pub(super) fn runs_out(&self, asked: [u32; 2]) -> bool {
        self.own.as_ref().is_some_and(|own| own.runs_out(asked))
    }

    /// Whether self-contact's room for pairs or grid entries ran out in a submission that
    /// `asked` for so many; the room is grown then.
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] when the room needed exceeds one binding.
    pub(super) fn make_room(
        &mut self,
        device: &wgpu::Device,
        asked: [u32; 2],
    ) -> Result<bool, GpuError> {
        let grown = match self.own.as_mut() {
            Some(own) => own.make_room(device, asked)?,
            None => false,
        };
        self.tell_pushes(device);
        Ok(grown)
    }
}
