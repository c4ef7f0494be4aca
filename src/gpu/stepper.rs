//! Positions and velocities live in two storage buffers that swap roles every substep
//! (ping-pong); each particle gathers its own springs over a CSR adjacency, so there are
//! no atomics and the result does not depend on the order the GPU runs the particles in.
//! `vec3` arrays would get a 16-byte stride in WGSL, so every vector is stored as a `vec4`
//! (the position's fourth component carries the inverse mass, 0 for a pin).

use std::time::Instant;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::cloth::{ClothModel, ClothState};
use crate::mesh::SpringKind;
use crate::render::map_read;
use crate::sim::{
    BendingModel, Cause, Collider, Diverged, Effect, FrameOutcome, IntegratorKind, PhaseTimings,
    SimParams, StepBackend, StepError, StepReport, StepStats, colliders_of,
};

/// Particles per workgroup (the shader's `@workgroup_size`).
const WORKGROUP: u32 = 64;
/// Colliders the shader has room for.
const MAX_COLLIDERS: usize = 4;
/// What one GPU substep is: one force evaluation, no solve.
const SUBSTEP: StepReport = StepReport {
    force_evals: 1,
    solver_iterations: 0,
    residual: None,
    converged: true,
};

/// Why the GPU backend cannot run a scene.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GpuError {
    #[error("the GPU backend {0}")]
    Unsupported(String),
    #[error("the GPU backend could not read its state back: {0}")]
    Readback(String),
    /// No adapter or device to step on (what the device layer said).
    #[error("no GPU device: {0}")]
    Device(String),
}

impl From<crate::render::RenderError> for GpuError {
    fn from(e: crate::render::RenderError) -> Self {
        GpuError::Device(e.to_string())
    }
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Particle {
    x: [f32; 4],
    v: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Neighbour {
    /// The other end's index in the high bits, its strength class (an index into the
    /// class table) in the low [`CLASS_BITS`] (see [`end_bits`]).
    other: u32,
    rest: f32,
}

/// Low bits of [`Neighbour::other`] that hold the strength class; the other end's index
/// takes the 28 above, so a cloth has at most 2²⁸ particles on the GPU backend. The shader
/// is given this and [`MAX_CLASSES`] as constants.
const CLASS_BITS: u32 = 4;
/// Strength classes (distinct stiffness–damping pairs) the shader's table holds: a cloth
/// has at most one per spring kind (3), which leaves room for strengths set otherwise.
const MAX_CLASSES: usize = 1 << CLASS_BITS;
/// Particles a cloth may have on the GPU backend.
const MAX_PARTICLES: u64 = 1 << (32 - CLASS_BITS);

/// A spring end's [`Neighbour::other`]: the index shifted up, the class below it. The class
/// sits low so that a shader that decodes either half wrongly reads another particle or
/// another class for every end (with the index low, a dropped mask would be hidden by
/// 32-bit address arithmetic that wraps the class bits away).
fn end_bits(other: u32, class: u8) -> u32 {
    (other << CLASS_BITS) | u32::from(class)
}

/// Per strength class `[stiffness, damping, 0, 0]`: the shader's uniform `classes`.
type ClassTable = [[f32; 4]; MAX_CLASSES];

/// What decides the spring ends' bits besides the model: whether each spring term (the
/// structural and shear springs; the bend springs, the model's last) is sent, and each
/// spring kind's class. A spring's stiffness and damping are its kind's, so the classes
/// are the distinct pairs among the kinds, and a strength change is known to keep the ends
/// as they are from three numbers, without a pass over the springs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct EndsKey {
    terms: [bool; 2],
    of_kind: [u8; SpringKind::ALL.len()],
}

/// The class of a spring the shader does not get.
const NO_CLASS: u8 = u8::MAX;
const _: () = assert!(
    SpringKind::ALL.len() <= MAX_CLASSES,
    "every kind can have a class of its own"
);

impl EndsKey {
    /// The class of spring `e` of `model`, or [`NO_CLASS`] if its term is not sent.
    fn class_of(&self, model: &ClothModel, e: usize) -> u8 {
        if self.terms[usize::from(e >= model.bend_start())] {
            self.of_kind[model.springs.kind[e].index()]
        } else {
            NO_CLASS
        }
    }
}

/// Sorts the spring kinds into classes of equal stiffness and damping, numbered in kind
/// order, for the spring terms `effects` turn on: the ends' key and the class table.
fn classify(params: &SimParams, effects: &[Effect]) -> (EndsKey, ClassTable) {
    let terms = [
        effects.contains(&Effect::Springs),
        effects.contains(&Effect::Bending(BendingModel::Springs)),
    ];
    let mut table: ClassTable = [[0.0; 4]; MAX_CLASSES];
    let mut classes = 0;
    let mut of_kind = [NO_CLASS; SpringKind::ALL.len()];
    for kind in SpringKind::ALL.map(SpringKind::index) {
        let entry = [params.stiffness[kind], params.damping[kind], 0.0, 0.0];
        let same = |t: &[f32; 4]| t.map(f32::to_bits) == entry.map(f32::to_bits);
        let class = match table[..classes].iter().position(same) {
            Some(at) => at,
            None => {
                table[classes] = entry;
                classes += 1;
                classes - 1
            }
        };
        of_kind[kind] = class as u8;
    }
    (EndsKey { terms, of_kind }, table)
}

/// The springs as the shader reads them: per particle its range of `ends` (CSR offsets),
/// each end its other particle and class.
struct PackedSprings {
    offsets: Vec<u32>,
    ends: Vec<Neighbour>,
}

/// Packs the model's adjacency: each end of a spring that `key` gives a class, with the
/// class.
fn pack_springs(model: &ClothModel, key: &EndsKey) -> PackedSprings {
    let adj = &model.adjacency;
    let count = model.particle_count();
    let mut offsets = Vec::with_capacity(count + 1);
    let mut ends = Vec::with_capacity(adj.spring.len());
    offsets.push(0u32);
    for p in 0..count {
        for slot in adj.range(p) {
            let (e, other) = (adj.spring[slot] as usize, adj.other[slot]);
            let class = key.class_of(model, e);
            if class != NO_CLASS && other as usize != p {
                ends.push(Neighbour {
                    other: end_bits(other, class),
                    rest: model.springs.rest[e],
                });
            }
        }
        offsets.push(ends.len() as u32);
    }
    PackedSprings { offsets, ends }
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuCollider {
    info: [f32; 4],
    a: [f32; 4],
    b: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Params {
    gravity: [f32; 4],
    drag: [f32; 4],
    counts: [u32; 4],
    colliders: [GpuCollider; MAX_COLLIDERS],
}

/// The one integrator the GPU backend runs.
pub const GPU_INTEGRATOR: IntegratorKind = IntegratorKind::SemiImplicitEuler;

/// What of `params` and `effects` the GPU backend cannot run, if anything: it runs
/// semi-implicit Euler with gravity, springs (and bend springs), air damping, pins and up
/// to four sphere and plane colliders.
pub fn gpu_support(params: &SimParams, effects: &[Effect]) -> Result<(), GpuError> {
    if params.integrator != GPU_INTEGRATOR {
        return Err(GpuError::Unsupported(format!(
            "runs {} only, not {}",
            GPU_INTEGRATOR.label(),
            params.integrator.label()
        )));
    }
    for e in effects {
        let missing = match e {
            Effect::Wind(_) => Some("wind"),
            Effect::SelfCollision(_) => Some("self-collision"),
            Effect::Bending(BendingModel::Dihedral { .. }) => Some("dihedral bending"),
            _ => None,
        };
        if let Some(what) = missing {
            return Err(GpuError::Unsupported(format!(
                "has no {what}; run this scene on the CPU backend"
            )));
        }
    }
    if colliders_of(effects).len() > MAX_COLLIDERS {
        return Err(GpuError::Unsupported(format!(
            "takes at most {MAX_COLLIDERS} colliders"
        )));
    }
    Ok(())
}

/// Steps a cloth with semi-implicit Euler on a wgpu device (see the module documentation).
pub struct GpuStepper {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipeline: wgpu::ComputePipeline,
    uniform: wgpu::Buffer,
    /// The two particle buffers; `current` holds the latest state.
    particles: [wgpu::Buffer; 2],
    offsets: wgpu::Buffer,
    neighbours: wgpu::Buffer,
    classes: wgpu::Buffer,
    /// `groups[i]` reads `particles[i]` and writes the other.
    groups: [wgpu::BindGroup; 2],
    readback: wgpu::Buffer,
    /// A copy of the state at the end of the last frame, for a renderer on the same device;
    /// made on the first [`GpuStepper::display_buffer`], then kept current.
    display: Option<wgpu::Buffer>,
    current: usize,
    count: u32,
    params: Params,
    dt: f32,
    substeps: u32,
    /// The GPU copy must be replaced by the caller's state before the next step.
    upload: bool,
    /// The GPU copy stepped since the caller's state was last brought up to date.
    behind: bool,
    /// Copy the state back into the caller's after every frame (else only on `sync`).
    read_every_frame: bool,
    /// Why the current configuration cannot run, if it cannot.
    unsupported: Option<String>,
    /// Why the state could not be read back, if it could not: every later frame fails with
    /// it (the GPU copy and the caller's state can no longer be brought together).
    lost: Option<String>,
    timings: PhaseTimings,
    stats: StepStats,
    /// The key the device's spring ends were packed with (`None` before the first
    /// upload), and how many times the ends were sent.
    sent: Option<EndsKey>,
    ends_sent: u32,
}

/// Whether the stepper's largest storage buffers (the particles' state, and a record per
/// spring end) fit what one binding and one buffer of a device with `limits` may hold: a
/// cloth too big for the device is refused with the sizes, not left to a validation panic.
fn fits_buffers(limits: &wgpu::Limits, particles: u64, spring_ends: u64) -> Result<(), GpuError> {
    let most = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size);
    if particles > MAX_PARTICLES {
        return Err(GpuError::Unsupported(format!(
            "takes at most {MAX_PARTICLES} particles, not {particles}"
        )));
    }
    let need = [
        (particles * size_of::<Particle>() as u64, "particles' state"),
        (spring_ends * size_of::<Neighbour>() as u64, "spring ends"),
    ];
    let mib = |bytes: u64| bytes as f64 / (1u64 << 20) as f64;
    match need.into_iter().find(|&(bytes, _)| bytes > most) {
        Some((bytes, what)) => Err(GpuError::Unsupported(format!(
            "needs {:.1} MiB ({bytes} bytes) in one storage buffer for this cloth's {what} \
             ({particles} particles, {spring_ends} spring ends); this device binds at most \
             {:.1} MiB ({most} bytes)",
            mib(bytes),
            mib(most)
        ))),
        None => Ok(()),
    }
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
        gpu_support(params, effects)?;
        let limits = device.limits();
        let storage = limits.max_storage_buffers_per_shader_stage;
        if storage < 4 {
            return Err(GpuError::Unsupported(format!(
                "needs 4 storage buffers in a compute shader; this device offers {storage}"
            )));
        }
        let count = model.particle_count() as u32;
        let groups = limits.max_compute_workgroups_per_dimension as u64 * WORKGROUP as u64;
        if limits.max_compute_workgroup_size_x < WORKGROUP
            || limits.max_compute_invocations_per_workgroup < WORKGROUP
            || (count as u64) > groups
        {
            return Err(GpuError::Unsupported(format!(
                "needs compute workgroups of {WORKGROUP} for {count} particles, which this \
                 device does not offer"
            )));
        }
        let spring_ends = model.springs.len() as u64 * 2;
        fits_buffers(&limits, count as u64, spring_ends)?;
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("cloth substep"),
            source: wgpu::ShaderSource::Wgsl(
                format!(
                    "const CLASS_BITS: u32 = {CLASS_BITS}u;\n\
                     const CLASSES: u32 = {MAX_CLASSES}u;\n{}",
                    include_str!("cloth.wgsl")
                )
                .into(),
            ),
        });
        let storage = |binding, read_only| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let uniform_entry = wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("cloth substep"),
            entries: &[
                uniform_entry,
                storage(1, true),
                storage(2, false),
                storage(3, true),
                storage(4, true),
                wgpu::BindGroupLayoutEntry {
                    binding: 5,
                    ..uniform_entry
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("cloth substep"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("cloth substep"),
            layout: Some(&pipeline_layout),
            module: &shader,
            entry_point: Some("substep"),
            compilation_options: Default::default(),
            cache: None,
        });
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
        let group = |from: usize| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("cloth substep"),
                layout: &layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: uniform.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: particles[from].as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: particles[1 - from].as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: offsets.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 4,
                        resource: neighbours.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 5,
                        resource: classes.as_entire_binding(),
                    },
                ],
            })
        };
        let groups = [group(0), group(1)];
        let mut stepper = Self {
            device: device.clone(),
            queue: queue.clone(),
            pipeline,
            uniform,
            particles,
            offsets,
            neighbours,
            classes,
            groups,
            readback,
            display: None,
            current: 0,
            count,
            params: Params::zeroed(),
            dt: params.dt,
            substeps: params.substeps.max(1),
            upload: true,
            behind: false,
            read_every_frame,
            unsupported: None,
            lost: None,
            timings: PhaseTimings::default(),
            stats: StepStats::default(),
            sent: None,
            ends_sent: 0,
        };
        stepper.configure(model, params, effects);
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
    fn upload_springs(&mut self, model: &ClothModel, params: &SimParams, effects: &[Effect]) {
        let (key, table) = classify(params, effects);
        self.queue
            .write_buffer(&self.classes, 0, bytemuck::cast_slice(&table));
        if self.sent != Some(key) {
            let packed = pack_springs(model, &key);
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

    fn upload_state(&mut self, model: &ClothModel, state: &ClothState) {
        let data: Vec<Particle> = (state.pos.iter().zip(&state.vel))
            .zip(&model.inv_mass)
            .map(|((x, v), &w)| Particle {
                x: [x.x, x.y, x.z, w],
                v: [v.x, v.y, v.z, 0.0],
            })
            .collect();
        if !data.is_empty() {
            for buffer in std::iter::once(&self.particles[self.current]).chain(&self.display) {
                self.queue
                    .write_buffer(buffer, 0, bytemuck::cast_slice(&data));
            }
        }
        self.upload = false;
        self.behind = false;
    }

    /// Encodes and submits `substeps` substeps.
    fn run(
        &mut self,
        model: &ClothModel,
        state: &ClothState,
        substeps: u32,
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
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("cloth substeps"),
            });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("cloth substeps"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            for _ in 0..substeps {
                pass.set_bind_group(0, &self.groups[self.current], &[]);
                pass.dispatch_workgroups(self.count.div_ceil(WORKGROUP), 1, 1);
                self.current = 1 - self.current;
            }
        }
        if let Some(display) = &self.display {
            encoder.copy_buffer_to_buffer(&self.particles[self.current], 0, display, 0, None);
        }
        self.queue.submit([encoder.finish()]);
        self.behind = true;
        for _ in 0..substeps {
            self.stats.record(&SUBSTEP);
        }
        Ok(())
    }

    /// Copies the latest state back into `state` (waits for the GPU).
    fn read_back(&mut self, state: &mut ClothState) -> Result<(), GpuError> {
        let bytes = self.count as u64 * std::mem::size_of::<Particle>() as u64;
        if bytes == 0 {
            return Ok(());
        }
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("particles readback"),
            });
        encoder.copy_buffer_to_buffer(&self.particles[self.current], 0, &self.readback, 0, bytes);
        self.queue.submit([encoder.finish()]);
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

    fn timed_run(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
        substeps: u32,
    ) -> Result<(), StepError> {
        let start = Instant::now();
        self.run(model, state, substeps)?;
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

    fn configure(&mut self, model: &ClothModel, params: &SimParams, effects: &[Effect]) {
        self.unsupported = gpu_support(params, effects).err().map(|e| e.to_string());
        if self.unsupported.is_none() {
            self.upload_springs(model, params, effects);
        }
        let g = if effects.contains(&Effect::Gravity) {
            params.gravity
        } else {
            Vec3::ZERO
        };
        let drag = if effects.contains(&Effect::AirDamping) {
            params.air_damping
        } else {
            0.0
        };
        let mut out = [GpuCollider::zeroed(); MAX_COLLIDERS];
        let colliders = colliders_of(effects);
        for (slot, c) in out.iter_mut().zip(&colliders) {
            *slot = match *c {
                Collider::Sphere {
                    center,
                    radius,
                    spin,
                    friction,
                } => GpuCollider {
                    info: [1.0, radius, friction, 0.0],
                    a: center.extend(0.0).to_array(),
                    b: spin.extend(0.0).to_array(),
                },
                Collider::Plane {
                    point,
                    normal,
                    friction,
                } => GpuCollider {
                    info: [2.0, 0.0, friction, 0.0],
                    a: point.extend(0.0).to_array(),
                    b: normal.extend(0.0).to_array(),
                },
            };
        }
        self.params = Params {
            gravity: [g.x, g.y, g.z, 0.0],
            drag: [drag, params.collision_offset, 0.0, 0.0],
            counts: [self.count, colliders.len().min(MAX_COLLIDERS) as u32, 0, 0],
            colliders: out,
        };
        self.dt = params.dt;
        self.substeps = params.substeps.max(1);
        self.params.gravity[3] = self.substep_length();
        self.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&self.params));
        // The state on the device stays as it is: masses and pins change through the
        // caller's state, which then calls `invalidate`.
    }

    fn invalidate(&mut self) {
        self.upload = true;
    }

    /// One frame of substeps in one submission. The GPU path has no rollback guard (that
    /// would need a read-back per frame to check); a diverged state shows as non-finite.
    fn frame(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
    ) -> Result<FrameOutcome, Diverged> {
        let end = state.time + self.dt as f64;
        self.timed_run(model, state, self.substeps)
            .map_err(|e| Diverged {
                time: state.time,
                reason: e.to_string(),
                substeps: self.substeps,
                fallback: String::new(),
                cause: Cause::Backend,
            })?;
        state.time = end;
        Ok(FrameOutcome::Stepped)
    }

    fn substep(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
    ) -> Result<StepReport, StepError> {
        self.timed_run(model, state, 1)?;
        state.time += self.substep_length() as f64;
        Ok(SUBSTEP)
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

    fn integrator(&self) -> IntegratorKind {
        GPU_INTEGRATOR
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

    fn state_behind(&self) -> bool {
        // After a failed read-back there is nothing more to read.
        self.behind && self.lost.is_none()
    }

    /// The calling thread records and submits the device's work.
    fn cpu_threads(&self) -> usize {
        1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// llvmpipe's 128 MiB binding holds a 1 000 × 1 000 bench cloth's spring ends (8 bytes
    /// each, 91.4 MiB); a 1 200 × 1 200 one's do not fit and are refused with both sizes;
    /// the most that fits does.
    #[test]
    fn a_cloth_bigger_than_the_devices_buffers_is_refused_with_the_sizes() {
        let limits = wgpu::Limits {
            max_storage_buffer_binding_size: 128 << 20,
            max_buffer_size: 256 << 20,
            ..wgpu::Limits::default()
        };
        assert!(fits_buffers(&limits, 1_000_000, 11_980_004).is_ok());
        let (particles, ends) = (1_440_000, 17_256_004);
        let err = fits_buffers(&limits, particles, ends).expect_err("too big");
        let text = err.to_string();
        assert!(
            text.contains("131.7 MiB") && text.contains("128.0 MiB") && text.contains("spring"),
            "{text}"
        );
        let most = (128u64 << 20) / size_of::<Neighbour>() as u64;
        assert!(fits_buffers(&limits, particles, most).is_ok());
        assert!(fits_buffers(&limits, particles, most + 1).is_err());
        // The smaller of the two limits counts.
        let small_buffers = wgpu::Limits {
            max_buffer_size: 64 << 20,
            ..limits
        };
        assert!(fits_buffers(&small_buffers, particles, most).is_err());
        assert!(fits_buffers(&small_buffers, 3 << 20, 0).is_err());
        // An index needs its 28 bits, whatever the buffers hold.
        let huge = wgpu::Limits {
            max_storage_buffer_binding_size: u64::MAX,
            max_buffer_size: u64::MAX,
            ..limits
        };
        assert!(fits_buffers(&huge, MAX_PARTICLES, 0).is_ok());
        let err = fits_buffers(&huge, MAX_PARTICLES + 1, 0).expect_err("too many");
        assert!(err.to_string().contains("268435456 particles"), "{err}");
    }

    /// `effects` without bending.
    fn unbent(effects: &[Effect]) -> Vec<Effect> {
        (effects.iter())
            .filter(|e| !matches!(e, Effect::Bending(_)))
            .cloned()
            .collect()
    }

    /// Every spring end the CPU's force set has carries its other particle, its rest length
    /// and the class whose table entry is that spring's stiffness and damping there, in the
    /// adjacency's order; with the bend springs switched off, their ends are not sent.
    #[test]
    fn each_spring_end_points_at_the_strengths_the_cpu_gives_its_spring() {
        use crate::sim::ForceSet;
        let scene = crate::scene::Scene::builtin("sphere-drop").expect("scene");
        let (model, params) = (&scene.model, &scene.params);
        let unbent = unbent(&scene.effects);
        for (effects, classes) in [(&scene.effects, 3), (&unbent, 2)] {
            let forces = ForceSet::new(model, params, effects);
            let strengths: std::collections::HashMap<usize, (f32, f32)> = (forces.springs())
                .flat_map(|t| t.each())
                .map(|(e, k, c)| (e, (k, c)))
                .collect();
            let (key, table) = classify(params, effects);
            let packed = pack_springs(model, &key);
            let adj = &model.adjacency;
            let mut used = std::collections::BTreeSet::new();
            for p in 0..model.particle_count() {
                let range = packed.offsets[p] as usize..packed.offsets[p + 1] as usize;
                let slots: Vec<usize> = (adj.range(p))
                    .filter(|&slot| strengths.contains_key(&(adj.spring[slot] as usize)))
                    .collect();
                assert_eq!(range.len(), slots.len(), "particle {p}");
                for (end, slot) in packed.ends[range].iter().zip(slots) {
                    let e = adj.spring[slot] as usize;
                    let class = (end.other % MAX_CLASSES as u32) as usize;
                    used.insert(class);
                    assert_eq!(end.other >> CLASS_BITS, adj.other[slot]);
                    assert_eq!(end.rest, model.springs.rest[e]);
                    let [k, c, ..] = table[class];
                    assert_eq!((k, c), strengths[&e], "spring {e}");
                }
            }
            assert_eq!(used.len(), classes, "one class per kind sent: {used:?}");
        }
    }

    /// A strength change that keeps which springs share a class (every kind scaled alike,
    /// or the damping of a kind that has a class of its own) sends only the class table;
    /// one that splits or merges classes sends the ends again, once.
    #[test]
    fn the_spring_ends_are_sent_again_only_when_their_classes_change() {
        use crate::render::{AdapterPreference, Gpu};
        let gpu = Gpu::headless(AdapterPreference::Any).expect("an adapter");
        // The bench scene: one stiffness and damping for every kind of spring.
        let scene = crate::scene::Scene::builtin("hanging-bench").expect("scene");
        let (model, effects) = (&scene.model, &scene.effects);
        let mut params = scene.params.clone();
        let mut stepper = GpuStepper::new(&gpu.device, &gpu.queue, model, &params, effects, true)
            .expect("stepper");
        let mut change = |edit: &dyn Fn(&mut SimParams), sends: u32| {
            edit(&mut params);
            stepper.configure(model, &params, effects);
            assert_eq!(stepper.ends_sent, sends, "after {:?}", params.stiffness);
        };
        change(&|_| (), 1);
        change(&|p| p.stiffness = p.stiffness.map(|k| 3.0 * k), 1);
        // The shear springs leave the one class all kinds shared: a class of their own,
        // whose damping then moves alone.
        change(&|p| p.stiffness[1] *= 0.5, 2);
        change(&|p| p.damping[1] *= 2.0, 2);
        // The structural springs leave the bend springs' class.
        change(&|p| p.stiffness[0] *= 2.0, 3);
        // Back to one stiffness (shear still damped apart), then one strength: merges.
        change(&|p| p.stiffness = [p.stiffness[0]; 3], 4);
        change(&|p| p.damping = [p.damping[0]; 3], 5);
        change(&|_| (), 5);
        // The bend springs switched off: their ends go.
        let unbent = unbent(effects);
        stepper.configure(model, &params, &unbent);
        assert_eq!(stepper.ends_sent, 6);
    }
}
