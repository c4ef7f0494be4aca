//! Mesh obstacles on the GPU (`shaders/obstacle.wgsl`): the CPU's contact with a rigid
//! obstacle, placed and moved by its keyframes, after each substep of every integrator
//! the GPU runs.
//! Each obstacle's box tree, triangles and sharp edges go to the device once, in the CPU's
//! tree order, so a walk visits what the CPU's visits; the obstacles' poses at each
//! substep's start and end are written before each submission. The cloth's edges (its
//! structural and shear springs) are coloured so that a dispatch per colour sweeps them as
//! the CPU's loop does, in another order.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::cloth::ClothModel;
use crate::sim::obstacle::TriangleTree;
use crate::sim::{ContactConfig, Effect, RigidMotion};

use super::error::GpuError;
use super::kernel::{CONTACT, LAYOUT, Slot, SubstepKernel, WORKGROUP, bind, layout, pipelines};
use super::packing::MAX_OBSTACLES;
use super::support::fits;
use super::xpbd::{Colours, colour_record};

const SOURCE: &str = include_str!("../../shaders/obstacle.wgsl");

/// Bytes of one obstacle's poses in one substep (its start, its end, its number), at an
/// offset that is a multiple of the device's uniform alignment (at most 256).
const POSE_STRIDE: u64 = 256;

/// Sweeps of the edge pass a substep at most (the CPU's `EDGE_SWEEPS`): as there, a sweep
/// runs only after one that found a crossing (on the device, every sweep's dispatches are
/// recorded, and each returns at once where the sweep before counted none).
const EDGE_SWEEPS: usize = 4;

/// One obstacle as the shader reads it (its `Obstacle`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
struct GpuObstacle {
    starts: [u32; 4],
    counts: [u32; 4],
    pivot: [f32; 4],
    info: [f32; 4],
}

/// The pass's uniform (the shader's `ObstacleParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
struct ObstacleParams {
    counts: [u32; 4],
    obstacles: [GpuObstacle; MAX_OBSTACLES],
}

/// What the integrator keeps that a contact changes, which the contacts then update, in
/// the words [`ObstaclePass::attach_solve`] bound.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Memory {
    None,
    /// Implicit Euler's first guess, whose flag is this word of its solve: a contact that
    /// moves a particle leaves the guess no history.
    Guess(u32),
    /// VBD's last accelerations, from this word of its stencil, four a particle: a contact
    /// adds its change of velocity over the substep.
    Accelerations(u32),
}

/// Where a substep's start and end are for the contacts.
#[derive(Clone, Copy, Debug)]
pub(super) enum Start {
    /// The start in `particles[i]`, the end in the other (semi-implicit Euler).
    In(usize),
    /// The start in the copy [`ObstaclePass::keep_start`] made, the end in `particles[i]`
    /// (XPBD and VBD, which write their end over their start).
    Kept(usize),
}

/// The rigid mesh obstacles of a scene on the device.
pub(super) struct ObstaclePass {
    catch: wgpu::ComputePipeline,
    edges: wgpu::ComputePipeline,
    keep: wgpu::ComputePipeline,
    /// By [`Start`]: `groups[i]` reads the substep's start from `particles[i]` and moves
    /// the other; `groups[2 + i]` reads it from the kept copy and moves `particles[i]`;
    /// `groups[4 + i]` copies `particles[i]` into the kept copy.
    groups: [wgpu::BindGroup; 6],
    colours: Colours,
    poses_layout: wgpu::BindGroupLayout,
    poses: wgpu::Buffer,
    poses_group: wgpu::BindGroup,
    /// Obstacles' substeps `poses` has room for, and the host's copy of what it holds
    /// (kept, so that a frame allocates nothing).
    room: u32,
    staging: Vec<[f32; 4]>,
    /// Each obstacle's motion, for its poses at each substep.
    moving: Vec<RigidMotion>,
    /// What the bind groups bind besides the particles: the uniform, the surfaces, the
    /// cloth's edges, the crossings, the kept start, and a stand-in for the solver's words
    /// the contacts tell of what they moved (see [`Memory`]), and their layout.
    buffers: [wgpu::Buffer; 6],
    layout: wgpu::BindGroupLayout,
    count: u32,
}

/// Appends `tree`'s nodes to `out` (two entries each) and returns where they start and
/// how many there are.
fn push_nodes(tree: &TriangleTree, out: &mut Vec<[f32; 4]>) -> (u32, u32) {
    let start = out.len() as u32;
    for (lo, hi, first, count) in tree.nodes() {
        out.push([lo.x, lo.y, lo.z, f32::from_bits(first)]);
        out.push([hi.x, hi.y, hi.z, f32::from_bits(count)]);
    }
    (start, out.len() as u32 - start)
}

/// The rigid obstacles of `effects` as the shader reads them, their surfaces packed into
/// one list, and their motions; `None` when there is none.
fn pack(
    effects: &[Effect],
    contact: &ContactConfig,
) -> Option<(ObstacleParams, Vec<[f32; 4]>, Vec<RigidMotion>)> {
    let mut params = ObstacleParams::default();
    let (mut surface, mut moving) = (Vec::new(), Vec::new());
    let placed = effects.iter().filter_map(|e| match e {
        Effect::Obstacle(o) => o.placed().map(|p| (o, p)),
        _ => None,
    });
    for (slot, (obstacle, placed)) in placed.take(MAX_OBSTACLES).enumerate() {
        let s = &placed.surface;
        let (nodes, node_count) = push_nodes(s.tree(), &mut surface);
        let places = surface.len() as u32;
        for ([a, b, c], t) in s.tree().places() {
            let n = s.normals()[t as usize];
            surface.push([a.x, a.y, a.z, f32::from_bits(t)]);
            surface.push([b.x, b.y, b.z, 0.0]);
            surface.push([c.x, c.y, c.z, 0.0]);
            surface.push([n.x, n.y, n.z, 0.0]);
        }
        let place_count = s.tree().len() as u32;
        let (edge_nodes, edge_node_count) = push_nodes(s.sharp_edges().tree(), &mut surface);
        let edge_places = surface.len() as u32;
        for ([p, q, _], _) in s.sharp_edges().tree().places() {
            surface.push([p.x, p.y, p.z, 0.0]);
            surface.push([q.x, q.y, q.z, 0.0]);
        }
        let edge_count = s.sharp_edges().tree().len() as u32;
        let thickness = obstacle.thickness.unwrap_or(contact.offset);
        let pivot = placed.pivot;
        params.obstacles[slot] = GpuObstacle {
            starts: [nodes, places, edge_nodes, edge_places],
            counts: [node_count, place_count, edge_node_count, edge_count],
            pivot: [pivot.x, pivot.y, pivot.z, 0.0],
            info: [thickness, obstacle.friction, 0.0, 0.0],
        };
        moving.push(placed.motion.clone());
    }
    (!moving.is_empty()).then_some((params, surface, moving))
}

/// The cloth's edges (their two particles) in the model's colour order, and each sweep's
/// records, colour after colour: `[first, count, serial | sweep << 1, invocations]`.
fn sweeps_of(model: &ClothModel) -> (Vec<[u32; 2]>, Vec<[u32; 4]>) {
    let (springs, colours) = (&model.springs, &model.edge_colours);
    let edges = (colours.order.iter())
        .map(|&e| [springs.a[e as usize], springs.b[e as usize]])
        .collect();
    let records = (0..EDGE_SWEEPS as u32)
        .flat_map(|sweep| {
            colours.runs.iter().map(move |(range, shared)| {
                let [first, count, serial, invocations] =
                    colour_record(range.start, range.len(), *shared);
                [first, count, serial | sweep << 1, invocations]
            })
        })
        .collect();
    (edges, records)
}

impl ObstaclePass {
    /// The pass for the rigid obstacles of `effects` over `model`'s particles (in
    /// `particles`), or `None` where there are none.
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] when the surfaces or the cloth's edges exceed one binding.
    pub(super) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        kernel: &SubstepKernel,
        particles: &[wgpu::Buffer; 2],
        (model, effects, contact): (&ClothModel, &[Effect], &ContactConfig),
    ) -> Result<Option<Self>, GpuError> {
        let Some((mut params, surface, moving)) = pack(effects, contact) else {
            return Ok(None);
        };
        let (edges, records) = sweeps_of(model);
        let bytes = |n: usize, each: usize| (n * each) as u64;
        fits(
            &device.limits(),
            &[
                (bytes(surface.len(), 16), "obstacle surfaces"),
                (bytes(edges.len(), 8), "cloth edges"),
            ],
            &format!("{} surface entries", surface.len()),
        )?;
        let count = model.particle_count() as u32;
        params.counts[0] = count;
        let buffer = |label: &str, data: &[u8], usage: wgpu::BufferUsages| {
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: (data.len() as u64).max(32).next_multiple_of(16),
                usage: usage | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            queue.write_buffer(&buffer, 0, data);
            buffer
        };
        use wgpu::BufferUsages as U;
        let uniform = buffer("obstacle params", bytemuck::bytes_of(&params), U::UNIFORM);
        let surface = buffer(
            "obstacle surfaces",
            bytemuck::cast_slice(&surface),
            U::STORAGE,
        );
        let cloth_edges = buffer("cloth edges", bytemuck::cast_slice(&edges), U::STORAGE);
        let crossings = buffer("edge crossings", &[0; 4 * EDGE_SWEEPS], U::STORAGE);
        let no_solve = buffer("no solver words", &[0; 48], U::STORAGE);
        use Slot::{Dynamic, Read, Uniform, Write};
        let slots = [Uniform, Read, Write, Read, Read, Write, Write];
        let main = layout(device, "obstacles", &slots);
        let poses_layout = layout(device, "obstacle poses", &[Dynamic]);
        let all: &[&wgpu::BindGroupLayout] = &[&main, &kernel.colour_layout, &poses_layout];
        let [catch, edges_pipeline, keep] = pipelines(
            device,
            "obstacles",
            &format!("{LAYOUT}{CONTACT}{SOURCE}"),
            [("catch_moves", all), ("edges", all), ("keep_start", all)],
        );
        // The substep's start, for an integrator that writes its end over it (XPBD, VBD).
        let kept = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("obstacle substep start"),
            size: particles[0].size(),
            usage: U::STORAGE,
            mapped_at_creation: false,
        });
        let buffers = [uniform, surface, cloth_edges, crossings, kept, no_solve];
        let groups = Self::groups_for(device, &main, particles, &buffers, None);
        let (poses, poses_group) = Self::poses_for(device, &poses_layout, 1);
        Ok(Some(Self {
            catch,
            edges: edges_pipeline,
            keep,
            groups,
            colours: Colours::new(device, queue, kernel, &records),
            poses_layout,
            poses,
            poses_group,
            room: 1,
            staging: Vec::new(),
            moving,
            buffers,
            layout: main,
            count,
        }))
    }

    /// The six bind groups (see `groups`), binding the solver's words `solve` (a stand-in
    /// without).
    fn groups_for(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        particles: &[wgpu::Buffer; 2],
        [uniform, surface, cloth_edges, crossings, kept, no_solve]: &[wgpu::Buffer; 6],
        solve: Option<&wgpu::Buffer>,
    ) -> [wgpu::BindGroup; 6] {
        let solve = solve.unwrap_or(no_solve);
        [0, 1, 2, 3, 4, 5].map(|g| {
            let i = g % 2;
            let (start, end) = match g / 2 {
                0 => (&particles[i], &particles[1 - i]),
                1 => (kept, &particles[i]),
                _ => (&particles[i], kept),
            };
            let buffers = [uniform, start, end, surface, cloth_edges, crossings, solve];
            bind(device, "obstacles", layout, &buffers)
        })
    }

    /// Binds the solver's words the contacts tell of what they moved (`None`: the
    /// integrator keeps nothing they change): implicit Euler's solve or VBD's stencil.
    pub(super) fn attach_solve(
        &mut self,
        device: &wgpu::Device,
        particles: &[wgpu::Buffer; 2],
        solve: Option<&wgpu::Buffer>,
    ) {
        self.groups = Self::groups_for(device, &self.layout, particles, &self.buffers, solve);
    }

    /// A poses buffer with room for `blocks` obstacles' substeps and its bind group.
    fn poses_for(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        blocks: u32,
    ) -> (wgpu::Buffer, wgpu::BindGroup) {
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("obstacle poses"),
            size: u64::from(blocks.max(1)) * POSE_STRIDE,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("obstacle poses"),
            layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(POSE_STRIDE),
                }),
            }],
        });
        (buffer, group)
    }

    /// Writes every obstacle's poses at the start and end of `substeps` substeps of
    /// `substep` seconds from `time`, for the submission about to be encoded, and what the
    /// integrator keeps that the contacts change (`memory`; its words attached).
    pub(super) fn write_poses(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (substeps, time, substep): (u32, f64, f32),
        memory: Memory,
    ) {
        let blocks = substeps * self.moving.len() as u32;
        if blocks > self.room {
            (self.poses, self.poses_group) = Self::poses_for(device, &self.poses_layout, blocks);
            self.room = blocks;
        }
        let entries = (POSE_STRIDE / 16) as usize;
        let data = &mut self.staging;
        data.clear();
        data.resize(blocks as usize * entries, [0.0; 4]);
        let (mode, at) = match memory {
            Memory::None => (0.0, 0),
            Memory::Guess(at) => (1.0, at),
            Memory::Accelerations(at) => (2.0, at),
        };
        let mut blocks = data.chunks_mut(entries);
        // The times as the CPU's clock reaches them: a substep added at a time.
        let mut t = time;
        for _ in 0..substeps {
            let t0 = t;
            t += f64::from(substep);
            for (o, motion) in self.moving.iter().enumerate() {
                let (start, end) = (motion.at(t0), motion.at(t));
                let v = |v: Vec3| [v.x, v.y, v.z, 0.0];
                if let Some(block) = blocks.next() {
                    block[..7].copy_from_slice(&[
                        v(start.translation),
                        start.rotation.to_array(),
                        v(end.translation),
                        end.rotation.to_array(),
                        v(end.velocity),
                        v(end.spin),
                        [f32::from_bits(o as u32), mode, f32::from_bits(at), substep],
                    ]);
                }
            }
        }
        queue.write_buffer(&self.poses, 0, bytemuck::cast_slice(data));
    }

    /// Records a copy of the substep's start, `particles[at]`, for an integrator that
    /// writes its end over it ([`Start::Kept`] then reads it).
    pub(super) fn keep_start(&self, pass: &mut wgpu::ComputePass<'_>, at: usize) {
        pass.set_bind_group(2, &self.poses_group, &[0]);
        pass.set_bind_group(1, self.colours.group(), &[0]);
        pass.set_pipeline(&self.keep);
        pass.set_bind_group(0, &self.groups[4 + at], &[]);
        pass.dispatch_workgroups(self.count.div_ceil(WORKGROUP), 1, 1);
    }

    /// Records substep `k`'s contacts, where `start` says its start and end are: each
    /// obstacle in turn (as the CPU's effects, in the scene's order) catches the particles'
    /// moves, then sweeps the cloth's edges.
    pub(super) fn encode(&self, pass: &mut wgpu::ComputePass<'_>, k: u32, start: Start) {
        let group = &self.groups[match start {
            Start::In(i) => i,
            Start::Kept(i) => 2 + i,
        }];
        let obstacles = self.moving.len() as u32;
        for o in 0..obstacles {
            let offset = (u64::from(k * obstacles + o) * POSE_STRIDE) as u32;
            pass.set_bind_group(2, &self.poses_group, &[offset]);
            pass.set_pipeline(&self.catch);
            pass.set_bind_group(0, group, &[]);
            pass.set_bind_group(1, self.colours.group(), &[0]);
            pass.dispatch_workgroups(self.count.div_ceil(WORKGROUP), 1, 1);
            self.colours.sweep(pass, &self.edges, group);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shader counts the crossings of as many sweeps as the host records.
    #[test]
    fn the_shader_has_room_for_every_sweeps_crossings() {
        let line = format!("const SWEEPS: u32 = {EDGE_SWEEPS}u;");
        assert!(SOURCE.contains(&line), "obstacle.wgsl lacks `{line}`");
    }
}
