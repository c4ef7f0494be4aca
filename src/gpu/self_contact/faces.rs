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

use super::super::kernel::{Slot, SubstepKernel, WORKGROUP, bind, layout, pipelines, sized_buffer};
use super::super::packing::{Params, SPHERE};
use super::super::substep_ends::{Memory, Start};
use super::super::xpbd::{Colours, colour_record};
use super::{COUNTERS, PUSH_WORDS, SelfParams, shader, uniform_and_triangles};

/// The triangles kept out of the spheres after each substep, without self-contact.
pub(in crate::gpu) struct FacePass {
    /// `faces_coloured` (a triangle of a colour each invocation), then `faces_settle` (a
    /// particle each).
    kernels: [wgpu::ComputePipeline; 2],
    /// `groups[j]` moves `particles[j]` (the start is bound to the other, which the
    /// kernels do not read).
    groups: [wgpu::BindGroup; 2],
    /// Each colour's first triangle, how many, whether they may share a particle and how
    /// many invocations take them.
    colours: Colours,
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
        (device, queue, kernel): (&wgpu::Device, &wgpu::Queue, &SubstepKernel),
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
        // No buckets: each particle's count follows the counters and its (unused) cut.
        let params = SelfParams {
            counts: [count, triangles.len() as u32, 0, 0],
            ..SelfParams::zeroed()
        };
        let [uniform, tris] = uniform_and_triangles(device, queue, "sphere faces", &triangles);
        let words = u64::from(COUNTERS) + (1 + PUSH_WORDS) * u64::from(count);
        let storage = |label: &str, bytes: u64| {
            sized_buffer(device, label, bytes, wgpu::BufferUsages::STORAGE)
        };
        let counts = storage("sphere faces pushes", 4 * words);
        let [boxes, lists] = [0, 1].map(|_| storage("sphere faces unused", 32));
        let no_solve = storage("no solver words", 48);
        let buffers = [uniform, tris, counts, boxes, lists, no_solve];
        use Slot::{Read, Uniform, Write};
        let slots = [Uniform, Read, Write, Read, Write, Write, Write, Write];
        let main = layout(device, "sphere faces", &slots);
        let both: &[&wgpu::BindGroupLayout] = &[&main, &kernel.colour_layout];
        let kernels = pipelines(
            device,
            "sphere faces",
            &shader(),
            [("faces_coloured", both), ("faces_settle", both)],
        );
        let records: Vec<[u32; 4]> = (runs.iter())
            .map(|(range, shared)| colour_record(range.start, range.len(), *shared))
            .collect();
        let colours = Colours::new(device, queue, kernel, &records);
        let groups = Self::groups_for(device, &main, particles, &buffers, None);
        Some(Self {
            kernels,
            groups,
            colours,
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
        self.colours
            .sweep(pass, &self.kernels[0], &self.groups[end]);
        pass.set_pipeline(&self.kernels[1]);
        pass.dispatch_workgroups(self.params.counts[0].div_ceil(WORKGROUP), 1, 1);
    }
}
