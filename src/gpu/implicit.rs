//! Implicit Euler on the GPU (`shaders/implicit.wgsl`): the CPU's linearised backward-Euler
//! step solved by conjugate gradients on the device, matrix-free. The solve's vectors,
//! scalars and partial sums live in one storage buffer (bound where XPBD binds its
//! constraints); the one-workgroup kernels that turn partial sums into the solve's scalars
//! also write how many workgroups the particle kernels dispatch next (indirect dispatch), so
//! iterations past convergence dispatch nothing. The iterations go in chunks: as many as the
//! last solve took (at least [`FIRST_CHUNK`]), then, while a read of the solve's 16 bytes of
//! state says it goes on, twice as many again, up to the cap: the CPU's stopping rule and
//! iteration count, with one wait a substep where the last solve's count was enough.

use crate::device::map_read;
use crate::sim::SolverConfig;

use super::error::GpuError;
use super::kernel::{COMMON, IMPLICIT, LAYOUT, WORKGROUP, pipelines};
use super::support::{fits, offers_storage};

/// Storage buffers the solve's kernels bind: the substep's seven and the workgroup counts.
pub(super) const STORAGE_BUFFERS: u32 = 8;

/// The word of the solve's buffer that holds its "a contact moved a particle" flag (the
/// bits of `cg[2].w` in `shaders/implicit.wgsl`): the next first guess then has no history.
pub(super) const MOVED_FLAG: u32 = 2 * 4 + 3;

/// Iterations the first chunk of a solve has at least.
pub(super) const FIRST_CHUNK: u32 = 8;

/// `vec4`s before the vectors: four of scalars, then a partial sum per workgroup.
const HEADER: u32 = 4;
/// `vec4`s per particle: eight vectors and three columns of the preconditioner.
const PER_PARTICLE: u64 = 11;

/// The pipelines, in the order a substep dispatches them.
struct Pipelines {
    begin: wgpu::ComputePipeline,
    norm: wgpu::ComputePipeline,
    residual: wgpu::ComputePipeline,
    start: wgpu::ComputePipeline,
    product: wgpu::ComputePipeline,
    alpha: wgpu::ComputePipeline,
    update: wgpu::ComputePipeline,
    beta: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
}

/// The solve's buffers and pipelines for one cloth.
pub(super) struct ImplicitPass {
    /// Bound in the substep's group 0 (binding 8).
    pub(super) solve: wgpu::Buffer,
    /// The particle kernels' workgroup counts, and its bind group (group 1).
    args: wgpu::Buffer,
    /// Where the solve's iteration count and whether it is done are read.
    state: wgpu::Buffer,
    /// Iterations the last solve took.
    pub(super) last: u32,
    args_group: wgpu::BindGroup,
    pipelines: Pipelines,
    /// Workgroups a particle dispatch has, and where the vectors start (in `vec4`s).
    groups: u32,
    vectors: u32,
    /// The history of the first guess is stale (the state changed outside, was rolled
    /// back, or the substep changed length).
    pub(super) fresh: bool,
}

impl ImplicitPass {
    /// The pass for `count` particles, its pipelines on the substep's group-0 `layout`.
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] when the device has fewer than [`STORAGE_BUFFERS`] storage
    /// buffers a stage or the solve's buffer exceeds one binding.
    pub(super) fn new(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        count: u32,
    ) -> Result<Self, GpuError> {
        offers_storage(&device.limits(), STORAGE_BUFFERS, "implicit Euler")?;
        let groups = count.div_ceil(WORKGROUP).max(1);
        let vectors = HEADER + groups;
        let bytes = (vectors as u64 + PER_PARTICLE * count as u64) * 16;
        let size = format!("{count} particles");
        fits(
            &device.limits(),
            &[(bytes, "implicit Euler's solve")],
            &size,
        )?;
        let solve = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("implicit solve"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let state = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("implicit solve state"),
            size: 16,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let args = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("implicit dispatches"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
            mapped_at_creation: false,
        });
        let args_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("implicit dispatches"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: false },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let args_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("implicit dispatches"),
            layout: &args_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 1,
                resource: args.as_entire_binding(),
            }],
        });
        let one: &[&wgpu::BindGroupLayout] = &[layout];
        let two: &[&wgpu::BindGroupLayout] = &[layout, &args_layout];
        let [
            begin,
            norm,
            residual,
            start,
            product,
            alpha,
            update,
            beta,
            finish,
        ] = pipelines(
            device,
            "cloth implicit",
            &format!("{LAYOUT}{COMMON}{IMPLICIT}"),
            [
                ("ie_begin", one),
                ("ie_norm", two),
                ("ie_residual", one),
                ("ie_start", two),
                ("ie_product", one),
                ("ie_alpha", two),
                ("ie_update", one),
                ("ie_beta", two),
                ("ie_finish", one),
            ],
        );
        Ok(Self {
            solve,
            args,
            state,
            last: 0,
            args_group,
            pipelines: Pipelines {
                begin,
                norm,
                residual,
                start,
                product,
                alpha,
                update,
                beta,
                finish,
            },
            groups,
            vectors,
            fresh: true,
        })
    }

    /// The uniform's solver words for `config`: where the vectors start, the tolerance's
    /// bits, the workgroups of a particle dispatch.
    pub(super) fn words(&self, config: &SolverConfig) -> [u32; 4] {
        [self.vectors, 0, config.tolerance.to_bits(), self.groups]
    }

    /// Clears the first guess's history before the next submission when it is stale.
    pub(super) fn prepare(&mut self, queue: &wgpu::Queue) {
        if self.fresh {
            queue.write_buffer(&self.solve, 2 * 16, bytemuck::bytes_of(&[0.0f32; 4]));
            self.fresh = false;
        }
    }

    /// Records a solve's start with the substep's `group` (reading the state): forces,
    /// right-hand side, preconditioner, first guess, residual.
    pub(super) fn start(&self, pass: &mut wgpu::ComputePass<'_>, group: &wgpu::BindGroup) {
        let p = &self.pipelines;
        self.bind(pass, group);
        self.direct(pass, &p.begin, self.groups);
        self.direct(pass, &p.norm, 1);
        self.indirect(pass, &p.residual);
        self.direct(pass, &p.start, 1);
    }

    /// Records `iterations` iterations, those past convergence empty.
    pub(super) fn iterate(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        group: &wgpu::BindGroup,
        iterations: u32,
    ) {
        let p = &self.pipelines;
        self.bind(pass, group);
        for _ in 0..iterations {
            self.indirect(pass, &p.product);
            self.direct(pass, &p.alpha, 1);
            self.indirect(pass, &p.update);
            self.direct(pass, &p.beta, 1);
        }
    }

    /// Records the step's end: the state into the other buffer.
    pub(super) fn finish(&self, pass: &mut wgpu::ComputePass<'_>, group: &wgpu::BindGroup) {
        self.bind(pass, group);
        self.direct(pass, &self.pipelines.finish, self.groups);
    }

    fn bind(&self, pass: &mut wgpu::ComputePass<'_>, group: &wgpu::BindGroup) {
        pass.set_bind_group(0, group, &[]);
        pass.set_bind_group(1, &self.args_group, &[]);
    }

    fn direct(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        pipeline: &wgpu::ComputePipeline,
        groups: u32,
    ) {
        pass.set_pipeline(pipeline);
        pass.dispatch_workgroups(groups, 1, 1);
    }

    fn indirect(&self, pass: &mut wgpu::ComputePass<'_>, pipeline: &wgpu::ComputePipeline) {
        pass.set_pipeline(pipeline);
        pass.dispatch_workgroups_indirect(&self.args, 0);
    }

    /// Submits `encoder` with a copy of the solve's state, and reads it: whether the solve
    /// is done, and its iterations so far.
    pub(super) fn submit_and_read(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mut encoder: wgpu::CommandEncoder,
    ) -> Result<(bool, u32), GpuError> {
        encoder.copy_buffer_to_buffer(&self.solve, 2 * 16, &self.state, 0, 16);
        queue.submit([encoder.finish()]);
        let slice = self.state.slice(..);
        map_read(device, &slice).map_err(|e| GpuError::Readback(e.to_string()))?;
        let words: [f32; 4] = {
            let view = slice
                .get_mapped_range()
                .map_err(|e| GpuError::Readback(e.to_string()))?;
            bytemuck::pod_read_unaligned(&view[..16])
        };
        self.state.unmap();
        Ok((words[1] > 0.5, words[0] as u32))
    }
}
