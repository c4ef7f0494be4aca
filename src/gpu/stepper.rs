//! Positions and velocities live in two storage buffers that swap roles every substep
//! (ping-pong); each particle gathers its own springs over a CSR adjacency, so there are
//! no atomics and the result does not depend on the order the GPU runs the particles in.
//! `vec3` arrays would get a 16-byte stride in WGSL, so every vector is stored as a `vec4`
//! (the position's fourth component carries the inverse mass, 0 for a pin).

use std::time::Instant;

use bytemuck::Zeroable;
use glam::Vec3;

use crate::cloth::{ClothModel, ClothState};
use crate::device::map_read;
use crate::sim::{
    Changes, Diverged, Effect, ForceSet, FrameOutcome, GuardEvent, GuardState, IntegratorKind,
    Material, PhaseTimings, SimParams, SolverConfig, StepBackend, StepError, StepReport, StepStats,
    air_damping_of, gravity_of,
};

use super::contacts::Contacts;
use super::elements::{ElementKernel, pack_elements};
use super::error::GpuError;
use super::handles::Carried;
use super::health::{HealthKernel, Watch};
use super::held::HeldMove;
use super::implicit::ImplicitPass;
use super::kernel::{SubstepKernel, WORKGROUP};
use super::packing::{
    ClassTable, EndsKey, Neighbour, Params, Particle, classify, grid_of, pack_solids, pack_springs,
};
use super::snapshot::DeviceSnapshot;
use super::substep_ends::Start;
use super::support::{check_device, fits_buffers, gpu_support};
use super::vbd::VbdPass;
use super::xpbd::XpbdPass;

/// What one GPU substep is: one force evaluation, and `sweeps` sweeps (XPBD, VBD).
fn substep_report(sweeps: u32) -> StepReport {
    StepReport {
        force_evals: 1,
        solver_iterations: sweeps,
        residual: None,
        converged: true,
    }
}

/// Steps a cloth on a wgpu device (see the module documentation).
pub struct GpuStepper {
    pub(super) device: wgpu::Device,
    pub(super) queue: wgpu::Queue,
    pub(super) kernel: SubstepKernel,
    /// Wind and dihedral bending, computed per element before each substep (their buffer
    /// also holds the handles' targets), and what its buffers were packed for: whether
    /// wind blows and whether bending is dihedral (a new strength only retunes it).
    pub(super) elements: ElementKernel,
    pub(super) elements_for: (bool, bool),
    /// The particles the handles carry, and whether the device's state must be stamped
    /// with their slots anew.
    pub(super) carried: Carried,
    pub(super) restamp: bool,
    /// A pinned particle the caller moved before the frame being stepped, and where from
    /// ([`StepBackend::moved_outside`]): its path in the first substep's contacts.
    pub(super) held: HeldMove,
    /// The handles' targets of the last submission (kept for its storage).
    targets: Vec<[f32; 4]>,
    /// The integrator in effect (one of those the GPU runs).
    pub(super) integrator: IntegratorKind,
    /// The integrator the parameters ask for (the guard may have fallen back from it).
    asked: IntegratorKind,
    /// XPBD's constraints in colour order and VBD's stencil, and whether the one in effect
    /// must be built again (XPBD's from the positions of the next step's start, as the CPU
    /// builds its own).
    pub(super) xpbd: XpbdPass,
    pub(super) vbd: VbdPass,
    /// Implicit Euler's solve, built the first time it steps.
    pub(super) implicit: Option<ImplicitPass>,
    /// The scene's mesh obstacles and self-contact, where it has them.
    pub(super) contacts: Contacts,
    /// The solvers' settings: XPBD's and VBD's sweeps a substep, implicit Euler's
    /// tolerance and cap.
    pub(super) solver: SolverConfig,
    pub(super) solver_stale: bool,
    /// VBD's memory of each particle's last acceleration is stale (the state changed
    /// outside, was rolled back, or VBD has not stepped it yet).
    pub(super) vbd_fresh: bool,
    pub(super) uniform: wgpu::Buffer,
    /// The two particle buffers; `current` holds the latest state.
    pub(super) particles: [wgpu::Buffer; 2],
    pub(super) offsets: wgpu::Buffer,
    pub(super) neighbours: wgpu::Buffer,
    pub(super) classes: wgpu::Buffer,
    /// `groups[i]` reads `particles[i]` and writes the other.
    pub(super) groups: [wgpu::BindGroup; 2],
    /// The guard's measure of a frame.
    pub(super) health: HealthKernel,
    /// The guard's memory, with its rollback points on the device.
    pub(super) guard: GuardState<DeviceSnapshot>,
    /// The state the frame being stepped started from.
    pub(super) frame_start: DeviceSnapshot,
    /// The scene's forces on the CPU, for the guard's limits and diagnosis.
    pub(super) forces: ForceSet,
    /// The scene's effects, for the guard's limits.
    pub(super) effects: Vec<Effect>,
    /// Gravity (m/s²) and air damping (1/s) in effect.
    pub(super) gravity: Vec3,
    pub(super) air_damping: f32,
    readback: wgpu::Buffer,
    /// A copy of the state at the end of the last frame, for a renderer on the same device;
    /// made on the first [`GpuStepper::display_buffer`], then kept current.
    pub(super) display: Option<wgpu::Buffer>,
    pub(super) current: usize,
    pub(super) count: u32,
    pub(super) params: Params,
    pub(super) dt: f32,
    /// Substeps per frame in effect (the guard may have raised them), and as requested.
    pub(super) substeps: u32,
    pub(super) requested: u32,
    /// The GPU copy must be replaced by the caller's state before the next step.
    pub(super) upload: bool,
    /// The GPU copy stepped since the caller's state was last brought up to date.
    pub(super) behind: bool,
    /// Copy the state back into the caller's after every frame (else only on `sync`).
    pub(super) read_every_frame: bool,
    /// Why the current configuration cannot run, if it cannot.
    pub(super) unsupported: Option<String>,
    /// Why the state could not be read back, if it could not: every later frame fails with
    /// it (the GPU copy and the caller's state can no longer be brought together).
    pub(super) lost: Option<String>,
    pub(super) timings: PhaseTimings,
    pub(super) stats: StepStats,
    /// The key the device's spring ends were packed with (`None` before the first
    /// upload), and how many times the ends were sent.
    pub(super) sent: Option<EndsKey>,
    pub(super) ends_sent: u32,
    /// A grid cloth's substep gathers its springs from the index (else from the ends).
    pub(super) grid_path: bool,
    /// Tries left in the frame under way at redoing it where self-contact's room ran out.
    pub(super) room_tries: u32,
    /// The device runs through GL, whose submissions hold the window's context.
    gl: bool,
}

impl GpuStepper {
    /// A stepper on `device` for `model` with `params` and `effects`. With
    /// `read_every_frame`, [`StepBackend::frame`] leaves the new state in the caller's
    /// [`ClothState`]; without, only [`StepBackend::sync`] does (benchmarks).
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] for an integrator or effect the shader does not have, or a
    /// cloth bigger than the device's buffers.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        model: &ClothModel,
        params: &SimParams,
        effects: &[Effect],
        read_every_frame: bool,
    ) -> Result<Self, GpuError> {
        gpu_support(&params.step, params.solver.precision, effects)?;
        let limits = device.limits();
        let count = model.particle_count() as u32;
        check_device(&limits, count)?;
        let spring_ends = model.springs.len() as u64 * 2;
        fits_buffers(&limits, count as u64, spring_ends)?;
        let kernel = SubstepKernel::new(device);
        let bytes = (count.max(1) as u64) * std::mem::size_of::<Particle>() as u64;
        let particle_buffer = |label| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        };
        let particles = [
            particle_buffer("particles A"),
            particle_buffer("particles B"),
        ];
        let small = |label, size: u64, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(16),
                usage,
                mapped_at_creation: false,
            })
        };
        let uniform = small(
            "cloth params",
            std::mem::size_of::<Params>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let classes = small(
            "spring classes",
            size_of::<ClassTable>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let storage_dst = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let offsets = small("spring offsets", (count as u64 + 1) * 4, storage_dst);
        let neighbours = small(
            "spring neighbours",
            spring_ends * std::mem::size_of::<Neighbour>() as u64,
            storage_dst,
        );
        let readback = small(
            "particles readback",
            bytes,
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        );
        let none = pack_elements(model, &ForceSet::default(), false);
        let elements = ElementKernel::new(device, queue, &particles, &none, &[]);
        let xpbd = XpbdPass::new(device, queue, &kernel, None)?;
        let vbd = VbdPass::new(device, queue, &kernel, None)?;
        let fixed = [&uniform, &offsets, &neighbours, &classes];
        let extra = [&elements.forces, &elements.incidence, &xpbd.constraints];
        let groups = kernel.groups(device, &particles, fixed, extra);
        let health = HealthKernel::new(device, &particles, (&offsets, &neighbours), count);
        let frame_start = DeviceSnapshot::new(device, queue, bytes);
        let mut stepper = Self {
            device: device.clone(),
            queue: queue.clone(),
            kernel,
            elements,
            elements_for: (false, false),
            carried: Carried::default(),
            held: HeldMove::new(device),
            restamp: false,
            targets: Vec::new(),
            integrator: params.step.integrator,
            asked: params.step.integrator,
            xpbd,
            vbd,
            implicit: None,
            solver: params.solver,
            solver_stale: true,
            vbd_fresh: true,
            uniform,
            particles,
            offsets,
            neighbours,
            classes,
            groups,
            health,
            guard: GuardState::new(params.guard.clone()),
            frame_start,
            forces: ForceSet::default(),
            effects: Vec::new(),
            gravity: Vec3::ZERO,
            air_damping: 0.0,
            readback,
            display: None,
            current: 0,
            count,
            params: Params {
                // The particles, and the invocations a particle dispatch has.
                counts: [count, 0, 0, count.div_ceil(WORKGROUP) * WORKGROUP],
                ..Params::zeroed()
            },
            dt: params.step.dt,
            substeps: params.step.substeps.max(1),
            requested: params.step.substeps.max(1),
            upload: true,
            behind: false,
            read_every_frame,
            unsupported: None,
            lost: None,
            timings: PhaseTimings::default(),
            stats: StepStats::default(),
            sent: None,
            ends_sent: 0,
            grid_path: true,
            room_tries: 0,
            gl: device.adapter_info().backend == wgpu::Backend::Gl,
            contacts: Contacts::default(),
        };
        stepper.configure(model, params, effects, Changes::all());
        match stepper.unsupported.take() {
            Some(why) => Err(GpuError::Unsupported(why)),
            None => Ok(stepper),
        }
    }

    /// Stride of [`GpuStepper::display_buffer`], in `vec4`s per particle.
    pub const DISPLAY_STRIDE: u32 = 2;

    /// A buffer that holds the state at the end of the latest frame (or upload), for a
    /// renderer on the same device to draw from without reading anything back: per particle
    /// a `vec4` whose xyz is the position in metres, then one with the velocity
    /// ([`GpuStepper::DISPLAY_STRIDE`]). Every frame's submission ends with the copy into it,
    /// so work submitted to the queue later sees a whole frame. Made on the first call (a
    /// stepper nobody draws, the benchmark's, copies nothing).
    pub fn display_buffer(&mut self) -> wgpu::Buffer {
        if let Some(display) = &self.display {
            return display.clone();
        }
        let display = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("particles display"),
            size: self.particles[0].size(),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("particles display"),
            });
        encoder.copy_buffer_to_buffer(&self.particles[self.current], 0, &display, 0, None);
        self.queue.submit([encoder.finish()]);
        self.display = Some(display.clone());
        display
    }

    /// Sends the springs' class table, and their ends (see [`pack_springs`]) when which
    /// springs share a class changed since the last upload: a strength change that keeps
    /// them (a slider moving one kind's stiffness) sends 256 bytes, not every end again,
    /// and costs no pass over the springs.
    fn upload_springs(&mut self, model: &ClothModel, material: &Material, effects: &[Effect]) {
        let (key, table) = classify(material, effects);
        self.queue
            .write_buffer(&self.classes, 0, bytemuck::cast_slice(&table));
        if self.sent != Some(key) {
            let packed = pack_springs(model, &key);
            let grid = grid_of(&packed, model.particle_count()).filter(|_| self.grid_path);
            self.params.grid = [0; 4];
            if let Some(g) = grid {
                self.params.grid = [g.width, g.height, g.links.len() as u32, 0];
                self.params.links[..g.links.len()].copy_from_slice(&g.links);
            }
            self.queue
                .write_buffer(&self.offsets, 0, bytemuck::cast_slice(&packed.offsets));
            if !packed.ends.is_empty() {
                self.queue
                    .write_buffer(&self.neighbours, 0, bytemuck::cast_slice(&packed.ends));
            }
            self.ends_sent += 1;
            self.sent = Some(key);
        }
    }

    /// Encodes and submits `substeps` substeps, with what `watch` asks for.
    /// The first substep starts at `time` seconds.
    pub(super) fn run(
        &mut self,
        model: &ClothModel,
        state: &ClothState,
        (substeps, time): (u32, f64),
        watch: Watch,
    ) -> Result<(), StepError> {
        if let Some(why) = &self.unsupported {
            return Err(StepError::Unsupported(why.clone()));
        }
        if let Some(why) = &self.lost {
            return Err(StepError::Device(why.clone()));
        }
        if self.upload {
            self.upload_state(model, state);
        }
        let vbd = self.integrator == IntegratorKind::Vbd;
        let implicit = self.integrator == IntegratorKind::ImplicitEuler;
        if self.integrator != IntegratorKind::SemiImplicitEuler && self.solver_stale {
            self.rebuild_solver(model, state)?;
        }
        if self.restamp {
            self.restamp(model, state)?;
        }
        let carried = self.carried.len() as u32;
        if carried > 0 {
            let mut targets = std::mem::take(&mut self.targets);
            (self.carried).targets((time, self.substep_length(), substeps), &mut targets);
            let (device, queue) = (&self.device, &self.queue);
            let grew = (self.elements).write_targets(device, queue, &self.particles, &targets);
            self.targets = targets;
            if grew {
                self.regroup();
            }
            self.params.handles = [self.elements.targets_at(), carried, 0, 0];
        }
        if vbd {
            self.params.solver[3] = u32::from(self.vbd_fresh);
        }
        if let Some(pass) = self.implicit.as_mut().filter(|_| implicit) {
            pass.prepare(&self.queue);
        }
        if vbd || carried > 0 {
            self.queue
                .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&self.params));
        }
        let when = (substeps, time, self.substep_length());
        let memory = self.contact_memory().0;
        let prepared =
            (self.contacts).prepare(&self.device, &self.queue, when, memory, &self.params);
        prepared.map_err(|e| StepError::Unsupported(e.to_string()))?;
        self.held.send(&self.queue);
        if vbd {
            self.kernel.vbd(&self.device);
        }
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("cloth substeps"),
            });
        if watch.keep_start {
            let live = &self.particles[self.current];
            let forced = self.contacts.forced_pairs().unwrap_or(0);
            self.frame_start.take(&mut encoder, live, (time, forced));
        }
        self.elements.start(&self.queue, time);
        // The substep counted, when something reads the count: the element pass's clock, the
        // handles' targets, VBD's first guess.
        let counting = vbd || carried > 0 || self.elements.elements() > 0;
        if implicit {
            self.implicit_substeps(&mut encoder, substeps, counting)?;
        }
        // XPBD's and VBD's passes: predict, sweep the colours, finish.
        let k = &self.kernel;
        let solver = match (self.integrator, &k.vbd) {
            (IntegratorKind::Xpbd, _) => {
                Some((&k.predict, &k.project, &self.xpbd.colours, &k.finish))
            }
            (IntegratorKind::Vbd, Some(v)) => {
                Some((&v.predict, &v.descend, &self.vbd.colours, &v.finish))
            }
            _ => None,
        };
        if !implicit {
            let groups = self.count.div_ceil(WORKGROUP);
            // On GL, self-contact's substeps go one submission each: a frame of them is a
            // long run of dispatches, which a GL device (the software adapter) executes
            // within one submission while the window waits for its context. Elsewhere a
            // frame is one submission.
            let each_alone = self.contacts.own.is_some() && self.gl;
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("cloth substeps"),
                timestamp_writes: None,
            });
            for k in 0..substeps {
                if k > 0 && each_alone {
                    drop(pass);
                    let next = self.device.create_command_encoder(&Default::default());
                    let full = std::mem::replace(&mut encoder, next);
                    self.queue.submit([full.finish()]);
                    pass = encoder.begin_compute_pass(&Default::default());
                }
                self.elements.dispatch(&mut pass, self.current);
                let (this, other) = (&self.groups[self.current], &self.groups[1 - self.current]);
                let start = if let Some((predict, sweep, colours, finish)) = solver {
                    self.contacts.keep_start(&mut pass, self.current);
                    // The state stays where it is; the other buffer holds the predictions
                    // (XPBD) or the displacements (VBD).
                    pass.set_pipeline(predict);
                    pass.set_bind_group(0, this, &[]);
                    pass.dispatch_workgroups(groups, 1, 1);
                    for _ in 0..self.sweeps() {
                        colours.sweep(&mut pass, sweep, this);
                    }
                    pass.set_pipeline(finish);
                    pass.set_bind_group(0, other, &[]);
                    pass.dispatch_workgroups(groups, 1, 1);
                    Start::Kept(self.current)
                } else {
                    pass.set_pipeline(&self.kernel.pipeline);
                    pass.set_bind_group(0, this, &[]);
                    pass.dispatch_workgroups(groups, 1, 1);
                    Start::In(self.current)
                };
                if k == 0 && self.held.pending() {
                    drop(pass);
                    (self.held).start(&mut encoder, (&self.particles, &self.contacts), start);
                    pass = encoder.begin_compute_pass(&Default::default());
                }
                (self.contacts).encode(&mut pass, k, start);
                if let Start::In(i) = start {
                    self.current = 1 - i;
                }
                if counting {
                    (self.kernel).count_substep(&mut pass, &self.groups[self.current]);
                }
            }
        }
        if watch.measure {
            self.health.encode(&mut encoder, self.current);
            // Read with the measure if the frame passes: one wait for both.
            if self.read_every_frame {
                self.copy_out(&mut encoder);
            }
        }
        if let Some(display) = &self.display {
            encoder.copy_buffer_to_buffer(&self.particles[self.current], 0, display, 0, None);
        }
        self.contacts.after_submission(&mut encoder);
        self.queue.submit([encoder.finish()]);
        self.behind = true;
        if vbd && substeps > 0 {
            self.vbd_fresh = false;
        }
        // Implicit Euler's substeps recorded their iterations themselves.
        let report = substep_report(if solver.is_some() { self.sweeps() } else { 0 });
        for _ in 0..substeps * u32::from(!implicit) {
            self.stats.record(&report);
        }
        Ok(())
    }

    /// Sweeps a substep of the integrator in effect (XPBD's or VBD's).
    fn sweeps(&self) -> u32 {
        match self.integrator {
            IntegratorKind::Vbd => self.solver.vbd_iterations,
            _ => self.solver.xpbd_iterations,
        }
        .max(1)
    }

    /// Makes `kind` (one the GPU runs) the integrator in effect, its data built before the
    /// next step (the guard's fallback).
    pub(super) fn switch_integrator(&mut self, kind: IntegratorKind) {
        self.integrator = kind;
        self.solver_stale = true;
    }

    /// The state changed outside: VBD's last accelerations and implicit Euler's last Δv
    /// are no first guess for the next step.
    pub(super) fn forget_guesses(&mut self) {
        self.vbd_fresh = true;
        if let Some(pass) = &mut self.implicit {
            pass.fresh = true;
        }
    }

    /// Makes `substeps` per frame the count in effect (implicit Euler's last Δv, of
    /// another step length, is then no first guess, as on the CPU).
    pub(super) fn set_substeps(&mut self, substeps: u32) {
        if substeps != self.substeps
            && let Some(pass) = &mut self.implicit
        {
            pass.fresh = true;
        }
        self.substeps = substeps;
        self.params.gravity[3] = self.substep_length();
        self.elements.set_step(self.substep_length());
        self.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&self.params));
    }

    /// Copies the latest state back into `state` (waits for the GPU).
    pub(super) fn read_back(&mut self, state: &mut ClothState) -> Result<(), GpuError> {
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("particles readback"),
            });
        self.copy_out(&mut encoder);
        self.queue.submit([encoder.finish()]);
        self.read_copied(state)
    }

    /// Encodes the copy of the latest state where [`GpuStepper::read_copied`] reads it.
    pub(super) fn copy_out(&self, encoder: &mut wgpu::CommandEncoder) {
        let bytes = self.count as u64 * std::mem::size_of::<Particle>() as u64;
        if bytes > 0 {
            let live = &self.particles[self.current];
            encoder.copy_buffer_to_buffer(live, 0, &self.readback, 0, bytes);
        }
    }

    /// Copies into `state` what the last submitted [`GpuStepper::copy_out`] copied (waits
    /// for the GPU).
    pub(super) fn read_copied(&mut self, state: &mut ClothState) -> Result<(), GpuError> {
        let bytes = self.count as u64 * std::mem::size_of::<Particle>() as u64;
        if bytes == 0 {
            return Ok(());
        }
        let slice = self.readback.slice(..bytes);
        map_read(&self.device, &slice).map_err(|e| GpuError::Readback(e.to_string()))?;
        {
            let view = slice
                .get_mapped_range()
                .map_err(|e| GpuError::Readback(e.to_string()))?;
            let data: &[Particle] = bytemuck::cast_slice(&view);
            for ((p, x), v) in data.iter().zip(&mut state.pos).zip(&mut state.vel) {
                *x = Vec3::new(p.x[0], p.x[1], p.x[2]);
                *v = Vec3::new(p.v[0], p.v[1], p.v[2]);
            }
        }
        self.readback.unmap();
        self.behind = false;
        Ok(())
    }

    pub(super) fn timed_run(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
        substeps: u32,
    ) -> Result<(), StepError> {
        let start = Instant::now();
        self.run(model, state, (substeps, state.time), Watch::OFF)?;
        if self.read_every_frame {
            self.read_back(state)
                .map_err(|e| StepError::Device(e.to_string()))?;
        }
        self.timings.add("gpu", start.elapsed());
        Ok(())
    }
}

impl StepBackend for GpuStepper {
    fn name(&self) -> &'static str {
        "gpu"
    }

    fn configure(
        &mut self,
        model: &ClothModel,
        params: &SimParams,
        effects: &[Effect],
        changes: Changes,
    ) {
        if changes.intersects(Changes::INTEGRATOR | Changes::EFFECTS | Changes::PRECISION) {
            let (step, precision) = (&params.step, params.solver.precision);
            self.unsupported = gpu_support(step, precision, effects)
                .err()
                .map(|e| e.to_string());
        }
        if changes.intersects(Changes::EFFECTS | Changes::STRENGTHS) && self.unsupported.is_none() {
            self.upload_springs(model, &params.material, effects);
            (self.forces).apply(model, &params.material, effects, changes);
        }
        // The integrator the guard fell back to stays until another is asked for.
        if self.unsupported.is_none() && changes.contains(Changes::INTEGRATOR) {
            self.integrator = params.step.integrator;
        }
        self.asked = params.step.integrator;
        self.solver = params.solver;
        if let Some(pass) =
            (self.implicit.as_ref()).filter(|_| self.integrator == IntegratorKind::ImplicitEuler)
        {
            // A new tolerance reaches the solve with the uniform written below.
            self.params.solver = pass.words(&self.solver);
        }
        if self.integrator == IntegratorKind::ImplicitEuler && params.solver.newton_iterations > 1 {
            self.unsupported = Some(format!(
                "runs implicit Euler as one linearised step, not {} Newton iterations; run \
                 them on the CPU backend",
                params.solver.newton_iterations
            ));
        }
        // New springs or strengths, or XPBD newly in effect: its constraints are built
        // again before the next step, as the CPU's are.
        if changes.intersects(Changes::INTEGRATOR | Changes::EFFECTS | Changes::STRENGTHS) {
            self.solver_stale = true;
        }
        if changes.contains(Changes::EFFECTS) {
            let (g, drag) = (gravity_of(effects), air_damping_of(effects));
            let (solids, count) = pack_solids(effects);
            self.params.gravity = [g.x, g.y, g.z, 0.0];
            self.params.drag[0] = drag;
            self.params.counts[1] = count;
            self.params.colliders = solids;
            self.effects = effects.to_vec();
            (self.gravity, self.air_damping) = (g, drag);
            let carried = Carried::of(effects);
            if carried != self.carried {
                self.carried = carried;
                self.restamp = true;
                self.params.handles = [0; 4];
            }
            if self.unsupported.is_none() {
                self.rebuild_elements(model, effects);
            }
        }
        if changes.intersects(Changes::EFFECTS | Changes::CONTACT) && self.unsupported.is_none() {
            let scene = (model, effects, params);
            let (device, queue) = (&self.device, &self.queue);
            match Contacts::new(device, queue, &self.kernel, &self.particles, scene) {
                Ok(contacts) => self.contacts = contacts.tuned_as(&self.contacts),
                Err(e) => self.unsupported = Some(e.to_string()),
            }
        }
        self.params.drag[1] = params.contact.offset;
        self.dt = params.step.dt;
        self.guard.reconfigure(&params.guard);
        // Substeps the guard raised stay unless the request changed.
        let requested = params.step.substeps.max(1);
        if requested != self.requested {
            self.requested = requested;
            self.substeps = requested;
        }
        self.params.gravity[3] = self.substep_length();
        self.elements.set_step(self.substep_length());
        self.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&self.params));
        // The state on the device stays as it is: masses and pins change through the
        // caller's state, which then calls `invalidate`.
    }

    fn invalidate(&mut self) {
        self.upload = true;
        self.guard.forget_history();
    }

    fn restart(&mut self) {
        self.invalidate();
        self.set_substeps(self.requested);
        if self.integrator != self.asked && self.unsupported.is_none() {
            self.switch_integrator(self.asked);
        }
        self.guard.restart();
    }

    /// One frame of substeps in one submission, under the stability guard: a reduction on
    /// the device measures the frame's end and only its 32 bytes come back; a frame that
    /// breaks a limit rolls back to a checkpoint kept on the device and is redone with
    /// twice the substeps, as on the CPU (see `guarded`).
    fn frame(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
    ) -> Result<FrameOutcome, Diverged> {
        let stepped = self.guarded_frame(model, state);
        self.held.moved = None;
        stepped
    }

    /// The contacts of the next run's first substep see the particle's path from `from`
    /// (`held.rs`).
    fn moved_outside(&mut self, particle: u32, from: Vec3) {
        self.held.moved = Some((particle, from));
    }

    fn substep(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
    ) -> Result<StepReport, StepError> {
        let ran = self.timed_run(model, state, 1);
        self.held.moved = None;
        ran?;
        state.time += self.substep_length() as f64;
        let sweeps = match self.integrator {
            IntegratorKind::Xpbd | IntegratorKind::Vbd => self.sweeps(),
            _ => 0,
        };
        Ok(substep_report(sweeps))
    }

    fn substeps(&self) -> u32 {
        self.substeps
    }

    fn substep_length(&self) -> f32 {
        self.dt / self.substeps as f32
    }

    fn take_timings(&mut self) -> PhaseTimings {
        self.timings.take()
    }

    fn take_stats(&mut self) -> StepStats {
        std::mem::take(&mut self.stats)
    }

    fn take_guard_events(&mut self) -> Vec<GuardEvent> {
        std::mem::take(&mut self.guard.events)
    }

    fn integrator(&self) -> IntegratorKind {
        self.integrator
    }

    fn sync(&mut self, model: &ClothModel, state: &mut ClothState) -> Result<(), StepError> {
        if self.upload {
            // After `invalidate` or `configure` the caller's state is the newer one.
            self.upload_state(model, state);
            return Ok(());
        }
        if !self.behind {
            return Ok(());
        }
        self.read_back(state).map_err(|e| {
            let why = e.to_string();
            self.lost = Some(why.clone());
            StepError::Device(why)
        })
    }

    fn forced_pairs(&self) -> Option<u64> {
        self.contacts.forced_pairs()
    }

    fn state_behind(&self) -> bool {
        // After a failed read-back there is nothing more to read.
        self.behind && self.lost.is_none()
    }

    /// The calling thread records and submits the device's work.
    fn cpu_threads(&self) -> usize {
        1
    }
}
