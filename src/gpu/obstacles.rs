//! Mesh obstacles on the GPU (`shaders/obstacle.wgsl`): the CPU's contact with a rigid
//! obstacle, placed and moved by its keyframes, or a deforming one (an OBJ sequence), after
//! each substep of every integrator the GPU runs.
//! Each rigid obstacle's box tree, triangles, sharp edges and tips go to the device once,
//! in the CPU's tree order, so a walk visits what the CPU's visits; the obstacles' poses at
//! each substep's start and end are written before each submission, and a deforming
//! obstacle's surface where each substep ends (the CPU's, refitted), after the rigid ones'.
//! The cloth's edges (its structural and shear springs) are coloured so that a dispatch per
//! colour sweeps them as the CPU's loop does; its triangles are too, for the tip pass (in
//! another order than the CPU's, which goes patch by patch).

use bytemuck::{Pod, Zeroable};
use glam::{Quat, Vec3};

use crate::cloth::{ClothModel, colour_greedily};
use crate::sim::obstacle::{Moment, Surface, TriangleTree};
use crate::sim::{ContactConfig, Effect, Obstacle, RigidMotion};

use super::error::GpuError;
use super::kernel::{
    CONTACT, GEOMETRY, LAYOUT, Slot, SubstepKernel, WORKGROUP, layout, pipelines, sized_buffer,
    start_end_groups,
};
use super::packing::MAX_OBSTACLES;
use super::self_contact::PUSHES_MOVED;
use super::substep_ends::{Memory, Start};
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
    /// Where its tips' tree's nodes, its tips, its smooth vertices' tree's nodes and its
    /// smooth vertices start (as `starts`).
    tips: [u32; 4],
    /// How many nodes the tips' tree has, and the smooth vertices'; the largest curvature
    /// (1/m, as bits).
    tip_counts: [u32; 4],
}

/// The pass's uniform (the shader's `ObstacleParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
struct ObstacleParams {
    counts: [u32; 4],
    obstacles: [GpuObstacle; MAX_OBSTACLES],
}

/// The mesh obstacles of a scene on the device.
pub(super) struct ObstaclePass {
    catch: wgpu::ComputePipeline,
    edges: wgpu::ComputePipeline,
    tips: wgpu::ComputePipeline,
    keep: wgpu::ComputePipeline,
    /// By [`Start`]: `groups[i]` reads the substep's start from `particles[i]` and moves
    /// the other; `groups[2 + i]` reads it from the kept copy and moves `particles[i]`;
    /// `groups[4 + i]` copies `particles[i]` into the kept copy.
    groups: [wgpu::BindGroup; 6],
    colours: Colours,
    /// The cloth's triangles' colours, for the tip pass, where it runs (as on the CPU):
    /// with an obstacle that has tips or smooth vertices.
    tip_colours: Option<Colours>,
    poses_layout: wgpu::BindGroupLayout,
    poses: wgpu::Buffer,
    poses_group: wgpu::BindGroup,
    /// Obstacles' substeps `poses` has room for, and the host's copy of what it holds
    /// (kept, so that a frame allocates nothing).
    room: u32,
    staging: Vec<[f32; 4]>,
    /// Each obstacle's motion, for its poses (or surface) at each substep.
    moving: Vec<Motion>,
    /// The rigid obstacles' surfaces, at the start of `surface`; after them, the deforming
    /// ones' at each substep of a submission (the host's copy, kept as `staging`), for as
    /// many entries in all as `surface_room`.
    fixed: Vec<[f32; 4]>,
    moments: Vec<[f32; 4]>,
    surface_room: usize,
    /// What the bind groups bind besides the particles: the uniform, the surfaces, the
    /// cloth's edges, the crossings, the kept start, a stand-in for the solver's words
    /// the contacts tell of what they moved (see [`Memory`]) and self-contact's counters
    /// ([`ObstaclePass::attach_pushed`]; a stand-in without), and their layout, and the
    /// solver's words bound instead.
    buffers: [wgpu::Buffer; 7],
    /// Whether the pass acts a second time each substep, after self-contact's pushes
    /// (where the scene has self-contact): its poses then come twice, the second time
    /// saying so.
    again: bool,
    layout: wgpu::BindGroupLayout,
    solve: Option<wgpu::Buffer>,
    particles: [wgpu::Buffer; 2],
    count: u32,
    /// What the uniform holds (read by tests).
    #[cfg(test)]
    params: ObstacleParams,
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

/// Appends `surface` to `out` as the shader reads it: its tree's nodes, its places (each
/// corner with its vertex's number, then the normal), its sharp edges' nodes and places,
/// its tips' nodes and tips, its smooth vertices' nodes and vertices (each with its
/// curvature); returns the obstacle with where each starts and how many there are.
fn push_surface(s: &Surface, out: &mut Vec<[f32; 4]>) -> GpuObstacle {
    let (nodes, node_count) = push_nodes(s.tree(), out);
    let places = out.len() as u32;
    for (corners, t) in s.tree().places() {
        let vertices = s.triangles()[t as usize];
        for (c, v) in corners.iter().zip(vertices) {
            out.push([c.x, c.y, c.z, f32::from_bits(v)]);
        }
        let n = s.normals()[t as usize];
        out.push([n.x, n.y, n.z, 0.0]);
    }
    let place_count = s.tree().len() as u32;
    let (edge_nodes, edge_node_count) = push_nodes(s.sharp_edges().tree(), out);
    let edge_places = out.len() as u32;
    for ([p, q, _], _) in s.sharp_edges().tree().places() {
        out.push([p.x, p.y, p.z, 0.0]);
        out.push([q.x, q.y, q.z, 0.0]);
    }
    let edge_count = s.sharp_edges().tree().len() as u32;
    let (tips, smooth, curvatures) = s.tips().trees();
    let mut points = |tree: &TriangleTree, curvature: &dyn Fn(u32) -> f32| {
        let (nodes, count) = push_nodes(tree, out);
        let places = out.len() as u32;
        for ([p, _, _], k) in tree.places() {
            out.push([p.x, p.y, p.z, curvature(k)]);
        }
        (nodes, count, places)
    };
    let (tip_nodes, tip_node_count, tip_places) = points(tips, &|_| 0.0);
    let (smooth_nodes, smooth_node_count, smooth_places) =
        points(smooth, &|k| curvatures[k as usize]);
    GpuObstacle {
        starts: [nodes, places, edge_nodes, edge_places],
        counts: [node_count, place_count, edge_node_count, edge_count],
        tips: [tip_nodes, tip_places, smooth_nodes, smooth_places],
        tip_counts: [
            tip_node_count,
            smooth_node_count,
            s.tips().curvature().to_bits(),
            0,
        ],
        ..GpuObstacle::default()
    }
}

/// Appends a deforming obstacle's surface where a substep ends, then each vertex's move
/// over the substep and velocity after it; returns where its parts start and how many
/// there are, and where the fields start.
fn push_moment(moment: &Moment, out: &mut Vec<[f32; 4]>) -> (GpuObstacle, u32) {
    let packed = push_surface(&moment.surface, out);
    let fields = out.len() as u32;
    for (shift, velocity) in moment.shift.iter().zip(&moment.velocity) {
        out.push([shift.x, shift.y, shift.z, 0.0]);
        out.push([velocity.x, velocity.y, velocity.z, 0.0]);
    }
    (packed, fields)
}

/// How an obstacle moves.
enum Motion {
    /// Rigidly, by its keyframes: its poses at each substep's start and end.
    Rigid(RigidMotion),
    /// As its OBJ sequence deforms it: its surface where each substep ends is written for
    /// each submission, `entries` long.
    Deforming {
        obstacle: Box<Obstacle>,
        entries: u32,
    },
}

/// The obstacles of `effects` as the shader reads them, the rigid ones' surfaces packed
/// into one list, and their motions; `None` when there is none.
fn pack(
    effects: &[Effect],
    contact: &ContactConfig,
) -> Option<(ObstacleParams, Vec<[f32; 4]>, Vec<Motion>)> {
    let mut params = ObstacleParams::default();
    let (mut surface, mut moving) = (Vec::new(), Vec::new());
    let placed = effects.iter().filter_map(|e| match e {
        Effect::Obstacle(o) => o.placed().map(|p| (o, p)),
        _ => None,
    });
    for (slot, (obstacle, placed)) in placed.take(MAX_OBSTACLES).enumerate() {
        let thickness = obstacle.thickness.unwrap_or(contact.offset);
        let mut info = [thickness, obstacle.friction, 0.0, 0.0];
        let (packed, pivot) = match &placed.sequence {
            None => {
                moving.push(Motion::Rigid(placed.motion.clone()));
                (push_surface(&placed.surface, &mut surface), placed.pivot)
            }
            Some(sequence) => {
                // Laid out from 0: each substep's copy starts where its poses say.
                let mut layout = Vec::new();
                let (packed, fields) = push_moment(&sequence.moment(0.0, 0.0), &mut layout);
                info[2] = f32::from_bits(fields);
                info[3] = 1.0;
                let entries = layout.len() as u32;
                let obstacle = Box::new(obstacle.clone());
                moving.push(Motion::Deforming { obstacle, entries });
                (packed, Vec3::ZERO)
            }
        };
        params.obstacles[slot] = GpuObstacle {
            pivot: [pivot.x, pivot.y, pivot.z, 0.0],
            info,
            ..packed
        };
    }
    (!moving.is_empty()).then_some((params, surface, moving))
}

/// Appends the cloth's triangles to `out` (two entries each: two corners, then the third),
/// coloured so that a dispatch per colour keeps them off the tips; returns each colour's
/// record (`[first, count, serial, invocations]`, from the first triangle).
fn push_triangles(model: &ClothModel, out: &mut Vec<[u32; 2]>) -> Vec<[u32; 4]> {
    let triangles = &model.triangles;
    let (order, runs) = colour_greedily(model.particle_count(), triangles.iter().copied());
    for t in order {
        let [a, b, c] = triangles[t as usize];
        out.extend([[a, b], [c, 0]]);
    }
    (runs.iter())
        .map(|(range, shared)| colour_record(range.start, range.len(), *shared))
        .collect()
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
        let Some((mut params, fixed, moving)) = pack(effects, contact) else {
            return Ok(None);
        };
        let (mut edges, records) = sweeps_of(model);
        // The pass acts again after self-contact's pushes, where the scene has it.
        let own = (effects.iter()).any(|e| matches!(e, Effect::SelfCollision(_)));
        // The tip pass runs where the CPU's does: wherever an obstacle has tips.
        let tipped = (params.obstacles.iter()).any(|o| o.tip_counts[..2] != [0, 0]);
        params.counts[1] = edges.len() as u32;
        let triangles = tipped.then(|| push_triangles(model, &mut edges));
        let bytes = |n: usize, each: usize| (n * each) as u64;
        fits(
            &device.limits(),
            &[
                (bytes(fixed.len(), 16), "obstacle surfaces"),
                (bytes(edges.len(), 8), "cloth edges and triangles"),
            ],
            &format!("{} surface entries", fixed.len()),
        )?;
        let count = model.particle_count() as u32;
        (params.counts[0], params.counts[2]) = (count, PUSHES_MOVED);
        let buffer = |label: &str, data: &[u8], usage: wgpu::BufferUsages| {
            let buffer = sized_buffer(device, label, data.len() as u64, usage);
            queue.write_buffer(&buffer, 0, data);
            buffer
        };
        use wgpu::BufferUsages as U;
        let uniform = buffer("obstacle params", bytemuck::bytes_of(&params), U::UNIFORM);
        let surface = buffer(
            "obstacle surfaces",
            bytemuck::cast_slice(&fixed),
            U::STORAGE,
        );
        // The cloth's edges, then (for the tip pass) its triangles.
        let cloth = buffer(
            "cloth edges and triangles",
            bytemuck::cast_slice(&edges),
            U::STORAGE,
        );
        let crossings = buffer("edge crossings", &[0; 4 * EDGE_SWEEPS], U::STORAGE);
        let no_solve = buffer("no solver words", &[0; 48], U::STORAGE);
        // Self-contact's counters, where it runs (`attach_pushed`).
        let pushed = buffer("no pushes", &[0; 16], U::STORAGE);
        use Slot::{Dynamic, Read, Uniform, Write};
        let slots = [Uniform, Read, Write, Read, Read, Write, Write, Read];
        let main = layout(device, "obstacles", &slots);
        let poses_layout = layout(device, "obstacle poses", &[Dynamic]);
        let all: &[&wgpu::BindGroupLayout] = &[&main, &kernel.colour_layout, &poses_layout];
        let [catch, edges_pipeline, tips, keep] = pipelines(
            device,
            "obstacles",
            &format!("{LAYOUT}{CONTACT}{GEOMETRY}{SOURCE}"),
            [
                ("catch_moves", all),
                ("edges", all),
                ("tips", all),
                ("keep_start", all),
            ],
        );
        // The substep's start, for an integrator that writes its end over it (XPBD, VBD).
        let kept = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("obstacle substep start"),
            size: particles[0].size(),
            usage: U::STORAGE,
            mapped_at_creation: false,
        });
        let buffers = [uniform, surface, cloth, crossings, kept, no_solve, pushed];
        let groups = Self::groups_for(device, &main, particles, &buffers, None);
        let (poses, poses_group) = Self::poses_for(device, &poses_layout, 1);
        Ok(Some(Self {
            catch,
            edges: edges_pipeline,
            tips,
            keep,
            groups,
            colours: Colours::new(device, queue, kernel, &records),
            tip_colours: triangles.map(|records| Colours::new(device, queue, kernel, &records)),
            poses_layout,
            poses,
            poses_group,
            room: 1,
            staging: Vec::new(),
            moving,
            surface_room: fixed.len(),
            fixed,
            moments: Vec::new(),
            buffers,
            layout: main,
            solve: None,
            particles: particles.clone(),
            count,
            #[cfg(test)]
            params,
            again: own,
        }))
    }

    /// The six bind groups (see `groups`), binding the solver's words `solve` (a stand-in
    /// without).
    fn groups_for(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        particles: &[wgpu::Buffer; 2],
        [uniform, surface, cloth, crossings, kept, no_solve, pushed]: &[wgpu::Buffer; 7],
        solve: Option<&wgpu::Buffer>,
    ) -> [wgpu::BindGroup; 6] {
        let rest = [surface, cloth, crossings, solve.unwrap_or(no_solve), pushed];
        start_end_groups(
            device,
            "obstacles",
            layout,
            (particles, kept),
            uniform,
            &rest,
        )
    }

    /// Binds the solver's words the contacts tell of what they moved (`None`: the
    /// integrator keeps nothing they change): implicit Euler's solve or VBD's stencil.
    pub(super) fn attach_solve(
        &mut self,
        device: &wgpu::Device,
        particles: &[wgpu::Buffer; 2],
        solve: Option<&wgpu::Buffer>,
    ) {
        (self.particles, self.solve) = (particles.clone(), solve.cloned());
        self.regroup(device);
    }

    fn regroup(&mut self, device: &wgpu::Device) {
        let (particles, solve) = (&self.particles, self.solve.as_ref());
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
    /// `substep` seconds from `time` (a deforming obstacle's surface where each ends), for
    /// the submission about to be encoded, and what the integrator keeps that the contacts
    /// change (`memory`; its words attached).
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] when the deforming obstacles' surfaces over the
    /// submission's substeps exceed one binding.
    pub(super) fn write_poses(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (substeps, time, substep): (u32, f64, f32),
        memory: Memory,
    ) -> Result<(), GpuError> {
        // Twice where the pass acts again after self-contact's pushes, the second saying so.
        let runs = 1 + usize::from(self.again);
        let blocks = substeps * self.moving.len() as u32 * runs as u32;
        if blocks > self.room {
            (self.poses, self.poses_group) = Self::poses_for(device, &self.poses_layout, blocks);
            self.room = blocks;
        }
        self.make_room(device, queue, substeps)?;
        let entries = (POSE_STRIDE / 16) as usize;
        let data = &mut self.staging;
        data.clear();
        data.resize(blocks as usize * entries, [0.0; 4]);
        self.moments.clear();
        let (mode, at) = match memory {
            Memory::None => (0.0, 0),
            Memory::Guess(at) => (1.0, at),
            Memory::Accelerations(at) => (2.0, at),
        };
        let mut blocks = data.chunks_mut(entries * runs);
        // The times as the CPU's clock reaches them: a substep added at a time.
        let mut t = time;
        for _ in 0..substeps {
            let t0 = t;
            t += f64::from(substep);
            for (o, motion) in self.moving.iter().enumerate() {
                let v = |v: Vec3| [v.x, v.y, v.z, 0.0];
                let Some(both) = blocks.next() else {
                    break;
                };
                let (block, second) = both.split_at_mut(entries);
                let which = [f32::from_bits(o as u32), mode, f32::from_bits(at), substep];
                match motion {
                    Motion::Rigid(motion) => {
                        let (start, end) = (motion.at(t0), motion.at(t));
                        block[..7].copy_from_slice(&[
                            v(start.translation),
                            start.rotation.to_array(),
                            v(end.translation),
                            end.rotation.to_array(),
                            v(end.velocity),
                            v(end.spin),
                            which,
                        ]);
                    }
                    Motion::Deforming { obstacle, .. } => {
                        let Some(sequence) = obstacle.placed().and_then(|p| p.sequence.as_ref())
                        else {
                            continue;
                        };
                        // Where the CPU's contact asks for it: back a substep from its end.
                        let moment = sequence.moment(t - f64::from(substep), t);
                        let at = (self.fixed.len() + self.moments.len()) as u32;
                        push_moment(&moment, &mut self.moments);
                        let still = Quat::IDENTITY.to_array();
                        block[..8].copy_from_slice(&[
                            [0.0; 4],
                            still,
                            [0.0; 4],
                            still,
                            [0.0; 4],
                            [0.0; 4],
                            which,
                            [f32::from_bits(at), moment.largest_shift, 0.0, 0.0],
                        ]);
                    }
                }
                if !second.is_empty() {
                    second.copy_from_slice(block);
                    second[7][2] = 1.0;
                }
            }
        }
        queue.write_buffer(&self.poses, 0, bytemuck::cast_slice(data));
        if !self.moments.is_empty() {
            let offset = (self.fixed.len() * 16) as u64;
            queue.write_buffer(
                &self.buffers[1],
                offset,
                bytemuck::cast_slice(&self.moments),
            );
        }
        Ok(())
    }

    /// Makes room in the surfaces' buffer for the deforming obstacles' surfaces over
    /// `substeps` substeps (a larger buffer, the rigid ones' surfaces written again, bound
    /// anew).
    fn make_room(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        substeps: u32,
    ) -> Result<(), GpuError> {
        let each: u32 = (self.moving.iter())
            .map(|m| match m {
                Motion::Deforming { entries, .. } => *entries,
                Motion::Rigid(_) => 0,
            })
            .sum();
        let need = self.fixed.len() + substeps as usize * each as usize;
        if need <= self.surface_room {
            return Ok(());
        }
        let bytes = (need * 16) as u64;
        let what = format!("{substeps} substeps of a deforming obstacle");
        fits(&device.limits(), &[(bytes, "obstacle surfaces")], &what)?;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("obstacle surfaces"),
            size: bytes.next_multiple_of(16),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(&buffer, 0, bytemuck::cast_slice(&self.fixed));
        self.buffers[1] = buffer;
        self.surface_room = need;
        self.regroup(device);
        Ok(())
    }

    /// Binds self-contact's counters, whose word [`PUSHES_MOVED`] says whether a substep's
    /// pushes moved something: the pass's second run in the substep acts only then, as the
    /// CPU's solids act again after its self-contact only where it moved something.
    pub(super) fn attach_pushed(&mut self, device: &wgpu::Device, counters: &wgpu::Buffer) {
        if self.buffers[6] != *counters {
            self.buffers[6] = counters.clone();
            self.regroup(device);
        }
    }

    /// How many sharp edges each obstacle keeps the cloth off, as packed (a deforming one's
    /// at its start).
    #[cfg(test)]
    pub(super) fn sharp_edges(&self) -> Vec<u32> {
        let obstacles = self.params.obstacles.iter().take(self.moving.len());
        obstacles.map(|o| o.counts[3]).collect()
    }

    /// The copy [`ObstaclePass::keep_start`] makes.
    pub(super) fn kept(&self) -> &wgpu::Buffer {
        &self.buffers[4]
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
    /// moves, then sweeps the cloth's edges, then (where it has tips) its triangles.
    /// `again`: the second time in the substep, after self-contact's pushes, which acts
    /// only where they moved something ([`ObstaclePass::attach_pushed`]).
    pub(super) fn encode(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        (k, again): (u32, bool),
        start: Start,
    ) {
        let group = &self.groups[match start {
            Start::In(i) => i,
            Start::Kept(i) => 2 + i,
        }];
        let obstacles = self.moving.len() as u32;
        let runs = 1 + u32::from(self.again);
        for o in 0..obstacles {
            let block = (k * obstacles + o) * runs + u32::from(again && self.again);
            let offset = (u64::from(block) * POSE_STRIDE) as u32;
            pass.set_bind_group(2, &self.poses_group, &[offset]);
            pass.set_pipeline(&self.catch);
            pass.set_bind_group(0, group, &[]);
            pass.set_bind_group(1, self.colours.group(), &[0]);
            pass.dispatch_workgroups(self.count.div_ceil(WORKGROUP), 1, 1);
            self.colours.sweep(pass, &self.edges, group);
            if let Some(colours) = &self.tip_colours {
                colours.sweep(pass, &self.tips, group);
            }
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
