//! The spheres' face pass on the GPU where the scene has no self-contact: the substep's
//! colliders keep out only the cloth's particles, and a coarse cloth's triangle dips into
//! a sphere between its corners however far out they are. The CPU's
//! `Sphere::keep_faces_out`, which runs in every stepper, in the same order: the
//! triangles colour after colour (`faces_coloured` in `shaders/self_pushes.wgsl`, a
//! dispatch a colour, whose triangles share no particle and move theirs at once), then
//! the planes again where a corner moved (`faces_settle`). Beside self-contact its pushes
//! keep the faces out instead (`SelfPass::encode_pushes`).

use bytemuck::Zeroable;

use crate::cloth::{ClothModel, colour_greedily};

use super::super::kernel::{Slot, WORKGROUP, bind, layout, pipelines};
use super::super::packing::{Params, SPHERE};
use super::super::substep_ends::{Memory, Start};
use super::{COUNTERS, PUSH_WORDS, ROUND_STRIDE, SelfParams, shader};

/// The triangles kept out of the spheres after each substep, without self-contact.
pub(in crate::gpu) struct FacePass {
    /// `faces_coloured` (a triangle of a colour each invocation), then `faces_settle` (a
    /// particle each).
    kernels: [wgpu::ComputePipeline; 2],
    /// `groups[j]` moves `particles[j]` (the start is bound to the other, which the
    /// kernels do not read).
    groups: [wgpu::BindGroup; 2],
    /// Each colour's first triangle, how many, and whether they may share a particle, at
    /// its own offset; and each colour's workgroups.
    colours: wgpu::BindGroup,
    workgroups: Vec<u32>,
    /// What the groups bind: the uniform, the triangles (colour after colour), each
    /// particle's count of pushes, two words for the bindings the kernels do not use, and
    /// a stand-in for the solver's words.
    buffers: [wgpu::Buffer; 6],
    solve: Option<wgpu::Buffer>,
    particles: [wgpu::Buffer; 2],
    layout: wgpu::BindGroupLayout,
    params: SelfParams,
}

impl FacePass {
    /// The pass over `model`'s triangles, or `None` where it has none.
    pub(in crate::gpu) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        particles: &[wgpu::Buffer; 2],
        model: &ClothModel,
    ) -> Option<Self> {
        if model.triangles.is_empty() {
            return None;
        }
        // Colour after colour, as the CPU's pass takes them (`FacePatches`).
        let (order, runs) =
            colour_greedily(model.particle_count(), model.triangles.iter().copied());
        let triangles: Vec<[u32; 4]> = (order.iter())
            .map(|&t| {
                let [a, b, c] = model.triangles[t as usize];
                [a, b, c, 0]
            })
            .collect();
        let count = model.particle_count() as u32;
        let n = triangles.len() as u32;
        // No buckets: each particle's count follows the counters and its (unused) cut.
        let params = SelfParams {
            counts: [count, n, 0, 0],
            ..SelfParams::zeroed()
        };
        use wgpu::BufferUsages as U;
        let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(32).next_multiple_of(16),
                usage: usage | U::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let size = std::mem::size_of::<SelfParams>() as u64;
        let uniform = buffer("sphere faces params", size, U::UNIFORM);
        let tris = buffer("sphere faces triangles", u64::from(n) * 16, U::STORAGE);
        queue.write_buffer(&tris, 0, bytemuck::cast_slice(&triangles));
        let words = u64::from(COUNTERS) + (1 + PUSH_WORDS) * u64::from(count);
        let counts = buffer("sphere faces pushes", 4 * words, U::STORAGE);
        let unused = [0, 1].map(|_| buffer("sphere faces unused", 32, U::STORAGE));
        let no_solve = buffer("no solver words", 48, U::STORAGE);
        let [boxes, lists] = unused;
        let buffers = [uniform, tris, counts, boxes, lists, no_solve];
        use Slot::{Dynamic, Read, Uniform, Write};
        let slots = [Uniform, Read, Write, Read, Write, Write, Write, Write];
        let main = layout(device, "sphere faces", &slots);
        let colour_layout = layout(device, "sphere faces colour", &[Dynamic]);
        let both: &[&wgpu::BindGroupLayout] = &[&main, &colour_layout];
        let kernels = pipelines(
            device,
            "sphere faces",
            &shader(),
            [("faces_coloured", both), ("faces_settle", both)],
        );
        let stride = ROUND_STRIDE as usize / 4;
        let mut words = vec![0u32; runs.len().max(1) * stride];
        for (k, (range, shared)) in runs.iter().enumerate() {
            let at = k * stride;
            words[at..at + 3].copy_from_slice(&[
                range.start as u32,
                range.len() as u32,
                u32::from(*shared),
            ]);
        }
        let records = buffer("sphere faces colours", 4 * words.len() as u64, U::UNIFORM);
        queue.write_buffer(&records, 0, bytemuck::cast_slice(&words));
        let colours = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sphere faces colours"),
            layout: &colour_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &records,
                    offset: 0,
                    size: wgpu::BufferSize::new(16),
                }),
            }],
        });
        let workgroups = (runs.iter())
            .map(|(range, shared)| {
                if *shared {
                    1
                } else {
                    (range.len() as u32).div_ceil(WORKGROUP)
                }
            })
            .collect();
        let groups = Self::groups_for(device, &main, particles, &buffers, None);
        Some(Self {
            kernels,
            groups,
            colours,
            workgroups,
            buffers,
            solve: None,
            particles: particles.clone(),
            layout: main,
            params,
        })
    }

    fn groups_for(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        particles: &[wgpu::Buffer; 2],
        [uniform, tris, sums, boxes, lists, no_solve]: &[wgpu::Buffer; 6],
        solve: Option<&wgpu::Buffer>,
    ) -> [wgpu::BindGroup; 2] {
        [0, 1].map(|j| {
            let (start, end) = (&particles[1 - j], &particles[j]);
            let solver = solve.unwrap_or(no_solve);
            let buffers = [uniform, start, end, tris, boxes, sums, lists, solver];
            bind(device, "sphere faces", layout, &buffers)
        })
    }

    /// Binds the solver's words the contacts tell of what they moved (see the obstacles').
    pub(in crate::gpu) fn attach_solve(
        &mut self,
        device: &wgpu::Device,
        particles: &[wgpu::Buffer; 2],
        solve: Option<&wgpu::Buffer>,
    ) {
        (self.particles, self.solve) = (particles.clone(), solve.cloned());
        let (particles, solve) = (&self.particles, self.solve.as_ref());
        self.groups = Self::groups_for(device, &self.layout, particles, &self.buffers, solve);
    }

    /// Before a submission of substeps `substep` seconds long: writes the uniform with
    /// what the integrator keeps that the contacts change (`memory`) and the step's
    /// colliders (from `cloth`, its uniform).
    pub(in crate::gpu) fn prepare(
        &mut self,
        queue: &wgpu::Queue,
        substep: f32,
        memory: Memory,
        cloth: &Params,
    ) {
        self.params.for_step(substep, memory, cloth);
        queue.write_buffer(&self.buffers[0], 0, bytemuck::bytes_of(&self.params));
    }

    /// Records a substep's face pass, where `start` says its end is: the triangles pushed
    /// out of the spheres colour after colour, then the planes again where a corner moved
    /// (nothing where the step has no sphere).
    pub(in crate::gpu) fn encode(&self, pass: &mut wgpu::ComputePass<'_>, start: Start) {
        let colliders = (self.params.colliders.iter()).take(self.params.passes[0] as usize);
        if !colliders.map(|c| c.info[0]).any(|kind| kind == SPHERE) {
            return;
        }
        let end = match start {
            Start::In(i) => 1 - i,
            Start::Kept(i) => i,
        };
        pass.set_bind_group(0, &self.groups[end], &[]);
        pass.set_pipeline(&self.kernels[0]);
        for (k, &groups) in self.workgroups.iter().enumerate() {
            let offset = (k as u64 * ROUND_STRIDE) as u32;
            pass.set_bind_group(1, &self.colours, &[offset]);
            pass.dispatch_workgroups(groups, 1, 1);
        }
        pass.set_pipeline(&self.kernels[1]);
        pass.dispatch_workgroups(self.params.counts[0].div_ceil(WORKGROUP), 1, 1);
    }
}
