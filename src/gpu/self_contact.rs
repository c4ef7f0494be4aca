//! Self-contact on the GPU (`shaders/self_contact.wgsl`): after each substep of every
//! integrator the GPU runs (after the mesh obstacles), the triangles are kept out of the
//! spheres (what that lifts is held as resting on them), the cloth's pairs that could touch
//! are found through a hashed grid of the triangles' boxes built on the device and pushed
//! a thickness apart, in sweeps of rounds of pairs that share no particle (the CPU's
//! sweep, pair after pair), then side by side for what the rounds leave; the spheres and
//! planes put back what the pushes moved into them (triangles too); and the motion as
//! pushed is cut short where a pair could meet, in rounds, as the CPU's continuous check
//! cuts it, with a floor where f32 still resolves a pair's distance.
//! A small cloth runs each phase (the search, the pushes, the colliders again, the cuts) in
//! one dispatch of one workgroup instead (`shaders/self_together.wgsl`), the same steps in
//! the same order, with the same bits.
//! Where the grid's or the pairs' room ran out in a submission, the substeps concerned
//! keep the cloth where it started them and the room is grown before the next.

use bytemuck::{Pod, Zeroable};

use crate::cloth::ClothModel;
use crate::device::map_read;
use crate::sim::{SelfCollision, owned_parts};

use super::error::GpuError;
use super::kernel::{
    CONTACT, GEOMETRY, LAYOUT, Slot, WORKGROUP, bind, layout, pipelines, sized_buffer,
    start_end_groups,
};
use super::packing::{GpuCollider, MAX_COLLIDERS, Params, SPHERE};
use super::substep_ends::{Memory, Start};
use super::support::fits;

mod faces;

pub(super) use faces::FacePass;

const SOURCE: &str = concat!(
    include_str!("../../shaders/self_contact.wgsl"),
    include_str!("../../shaders/self_pushes.wgsl"),
    include_str!("../../shaders/self_together.wgsl")
);

/// Rounds of cuts recorded a substep: four by the safe fraction, four to the start (the
/// shader's counters have room for 14, between its `STUCK` and `MOST_ENTRIES`).
const ROUNDS: u32 = 8;

/// Sweeps of the pushes a substep (the CPU's `PUSH_SWEEPS`).
const PUSH_SWEEPS: u32 = 4;

/// Rounds of pushes by pairs that share no particle, a sweep, before what is left is
/// pushed side by side.
const PUSH_ROUNDS: u32 = 8;

/// Entries of the rounds' uniform: the cuts' rounds, then each sweep's push rounds.
const ROUND_ENTRIES: u32 = ROUNDS + PUSH_SWEEPS * PUSH_ROUNDS;

/// Bytes between two rounds' uniforms (a multiple of any device's uniform alignment).
const ROUND_STRIDE: u64 = 256;

/// Words of a particle's pushes in a sweep (the shader's `PUSH_WORDS`).
const PUSH_WORDS: u64 = 9;

/// The shader's counters before the buckets (its `COUNTERS`).
const COUNTERS: u32 = 39;

/// The counter that says whether a substep's pushes moved anything (the shader's
/// `PUSHES_MOVED`), which the mesh obstacles read ([`SelfPass::counters`]).
pub(super) const PUSHES_MOVED: u32 = 38;

/// Where the shader keeps the most grid entries and pairs a substep of the submission
/// asked for, the pairs its substeps forced and its fastest particle before the cuts
/// (`MOST_ENTRIES`, `MOST_PAIRS`, `FORCED`, `FASTEST`), in bytes.
const MOST_AT: u64 = 4 * 34;

/// Bytes of those four counters.
const MOST_BYTES: u64 = 16;

/// What a submission's substeps asked for and measured ([`SelfPass::read_counters`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Counters {
    /// The most grid entries and pairs a substep asked for.
    pub(super) asked: [u32; 2],
    /// The fastest particle any substep's searches found, after its integrator and
    /// before its cuts (m/s; not finite where a velocity was not).
    pub(super) fastest: f32,
}

/// The pass's uniform (the shader's `SelfParams`).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SelfParams {
    counts: [u32; 4],
    more: [u32; 4],
    lengths: [f32; 4],
    /// Friction between layers, the colliders' offset.
    contact: [f32; 4],
    /// How many colliders, sweeps of the pushes, push rounds a sweep.
    passes: [u32; 4],
    /// The step's sphere and plane colliders.
    colliders: [GpuCollider; MAX_COLLIDERS],
}

impl SelfParams {
    /// The step's part: the substep, the colliders' offset and the colliders (from
    /// `cloth`, the step's uniform), and what the contacts tell the solver (`memory`).
    fn for_step(&mut self, substep: f32, memory: Memory, cloth: &Params) {
        self.lengths[3] = substep;
        self.contact[1] = cloth.drag[1];
        self.passes[0] = cloth.counts[1];
        self.colliders = cloth.colliders;
        (self.more[1], self.more[2]) = match memory {
            Memory::None => (0, 0),
            Memory::Guess(at) => (1, at),
            Memory::Accelerations(at) => (2, at),
        };
    }
}

/// A pass's uniform (`label params`, a [`SelfParams`]) and its triangles (`label
/// triangles`, four words each), written.
fn uniform_and_triangles(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    triangles: &[[u32; 4]],
) -> [wgpu::Buffer; 2] {
    use wgpu::BufferUsages as U;
    let size = std::mem::size_of::<SelfParams>() as u64;
    let uniform = sized_buffer(device, &format!("{label} params"), size, U::UNIFORM);
    let bytes = 16 * triangles.len() as u64;
    let tris = sized_buffer(device, &format!("{label} triangles"), bytes, U::STORAGE);
    queue.write_buffer(&tris, 0, bytemuck::cast_slice(triangles));
    [uniform, tris]
}

/// The shader: its bindings and helpers, then the kernels.
fn shader() -> String {
    format!("{LAYOUT}{CONTACT}{GEOMETRY}{SOURCE}")
}

/// Where the workgroup counts of `pairs_of_triangles` start in the pair kernels' (bytes:
/// the shader's `size_triangle_pairs` writes from word 4).
const TRIANGLE_PAIR_GROUPS: u64 = 16;

/// Room in the grid and for pairs, per triangle, to start with.
const ENTRIES_PER_TRIANGLE: u32 = 16;
const PAIRS_PER_TRIANGLE: u32 = 16;

/// The least room for pairs to start with, whatever the cloth's size (1 MiB of lists): a
/// submission that runs out is stepped again with more, and a small cloth that lands in
/// layers asks for many more pairs than its triangles. `layers` at 6 quads (360 triangles,
/// room for 5 760 pairs) asked for 9 800 pressed on a table, and each frame in which the
/// count outgrew the room was stepped twice: a third of the landing's time on the software
/// adapter.
const LEAST_PAIRS: u32 = 1 << 15;

/// The shader's entry points (`ENTRY_POINTS` names them in this order).
#[derive(Clone, Copy)]
enum Kernel {
    Clear,
    Boxes,
    Insert,
    Find,
    Cut,
    CutApply,
    Finish,
    KeepStart,
    Push,
    PushApply,
    Claim,
    PushAlone,
    Solids,
    Faces,
    FacesApply,
    FacesLift,
    BeforeObstacles,
    ObstaclesMoved,
    SearchTogether,
    PushesTogether,
    SolidsTogether,
    CutsTogether,
    SizePairs,
    PairsOfTriangles,
    SizeTrianglePairs,
}

const KERNELS: usize = Kernel::SizeTrianglePairs as usize + 1;

const ENTRY_POINTS: [&str; KERNELS] = [
    "clear",
    "particle_boxes",
    "insert",
    "find",
    "cut",
    "cut_apply",
    "finish",
    "keep_start",
    "push",
    "push_apply",
    "claim",
    "push_alone",
    "solids",
    "faces",
    "faces_apply",
    "faces_lift",
    "before_obstacles",
    "obstacles_moved",
    "search_together",
    "pushes_together",
    "solids_together",
    "cuts_together",
    "size_pairs",
    "pairs_of_triangles",
    "size_triangle_pairs",
];

/// The most triangles, and pairs (or pairs of triangles, where those are more) the last
/// submission found in a substep, for which one workgroup runs each phase of a substep
/// (`shaders/self_together.wgsl`): five dispatches where the wide path has about a
/// hundred. Measured on the software adapter (2026-11-27, the 2-vCPU machine, its two
/// threads), a frame of `layers` at 6 quads under XPBD at 8 substeps: with 2 380 (before it
/// lands) one workgroup steps it 2.5–3 times faster; with 3 200 as fast; with 4 700 half as
/// fast, its one thread doing all the work. (Before the search's pairs of triangles had a
/// dispatch of their own, one workgroup was 1.6 times slower already at 1 400 pairs.)
const TOGETHER_TRIANGLES: u32 = 1024;
const TOGETHER_PAIRS: u32 = 3072;

/// Whether one workgroup runs the substeps of a cloth of `triangles` whose last submission
/// found at most `pairs` in a substep.
fn small(triangles: u32, pairs: u32) -> bool {
    triangles <= TOGETHER_TRIANGLES && pairs <= TOGETHER_PAIRS
}

/// The cloth's self-contact on the device.
pub(super) struct SelfPass {
    /// The shader's entry points, in [`Kernel`]'s order.
    kernels: [wgpu::ComputePipeline; KERNELS],
    /// Sweeps of the pushes a substep (at most [`PUSH_SWEEPS`]; none leaves the cuts
    /// alone, for tests).
    pub(super) sweeps: u32,
    /// Rounds of pairs that share no particle a sweep (at most [`PUSH_ROUNDS`]; none
    /// pushes every pair side by side, for tests).
    pub(super) push_rounds: u32,
    /// As the obstacles' (see `start_end_groups`).
    groups: [wgpu::BindGroup; 6],
    rounds: wgpu::BindGroup,
    /// The pair kernels' workgroup counts (x, y, z), which `size_pairs` writes after each
    /// search and their indirect dispatches read, then the same for the pairs of
    /// triangles (`size_triangle_pairs`), and its group (2).
    pair_groups: wgpu::Buffer,
    pair_groups_group: wgpu::BindGroup,
    /// What the groups bind: the uniform, the triangles, the boxes, the counters and
    /// buckets, the lists, the kept start and a stand-in for the solver's words; the
    /// solver's words bound instead, the particles.
    buffers: [wgpu::Buffer; 7],
    solve: Option<wgpu::Buffer>,
    particles: [wgpu::Buffer; 2],
    layout: wgpu::BindGroupLayout,
    params: SelfParams,
    /// The counters read after a submission, and whether one is waiting there.
    readout: wgpu::Buffer,
    pending: bool,
    /// The pairs prescribed motion forced together (no particle of theirs could be cut),
    /// added up over the submissions read since the pass was made; and whether the one
    /// waiting in `readout` was rolled back (its count is then not added).
    pub(super) forced_pairs: u64,
    undone: bool,
    /// Whether one workgroup runs the submission's substeps (see [`TOGETHER_TRIANGLES`]).
    together: bool,
    /// Whether one workgroup runs every substep (`Some(true)`) or none, whatever the size
    /// (for tests).
    pub(super) forced: Option<bool>,
    /// Room for only this many pairs and grid entries from the next submission on, as if
    /// an earlier one had needed no more (for tests: the room running out).
    pub(super) room: Option<[u32; 2]>,
}

impl SelfPass {
    /// The pass for `model`'s self-contact as `own` says, or `None` where the cloth has
    /// no triangles.
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] when its buffers exceed one binding.
    pub(super) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        particles: &[wgpu::Buffer; 2],
        model: &ClothModel,
        own: &SelfCollision,
    ) -> Result<Option<Self>, GpuError> {
        if model.triangles.is_empty() || own.thickness <= 0.0 {
            return Ok(None);
        }
        let owned = owned_parts(model);
        let triangles: Vec<[u32; 4]> = (model.triangles.iter().zip(&owned))
            .map(|(t, &o)| [t[0], t[1], t[2], o])
            .collect();
        let longest = (model.edge_rest_lengths().iter()).fold(0.0f32, |m, &r| m.max(r));
        let count = model.particle_count() as u32;
        let n = triangles.len() as u32;
        let params = SelfParams {
            counts: [
                count,
                n,
                (2 * n).next_power_of_two().max(64),
                ENTRIES_PER_TRIANGLE * n,
            ],
            more: [(PAIRS_PER_TRIANGLE * n).max(LEAST_PAIRS), 0, 0, ROUNDS],
            lengths: [
                own.thickness,
                0.1 * own.thickness,
                (2.0 * longest).max(2.0 * own.thickness).max(1e-6),
                0.0,
            ],
            contact: [own.friction, 0.0, 0.0, 0.0],
            passes: [0, PUSH_SWEEPS, PUSH_ROUNDS, 0],
            colliders: [GpuCollider::zeroed(); MAX_COLLIDERS],
        };
        use wgpu::BufferUsages as U;
        let buffer = |label: &str, size: u64, usage| sized_buffer(device, label, size, usage);
        let [uniform, tris] = uniform_and_triangles(device, queue, "self-contact", &triangles);
        let boxes = buffer(
            "self-contact boxes",
            u64::from(2 * (count + n)) * 16,
            U::STORAGE,
        );
        let kept = buffer(
            "self-contact substep start",
            particles[0].size(),
            U::STORAGE,
        );
        let no_solve = buffer("no solver words", 48, U::STORAGE);
        let (atomics, lists) = Self::rooms(device, &params)?;
        let readout = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("self-contact counters"),
            size: 16,
            usage: U::COPY_DST | U::MAP_READ,
            mapped_at_creation: false,
        });
        use Slot::{Dynamic, Read, Uniform, Write};
        let slots = [Uniform, Read, Write, Read, Write, Write, Write, Write];
        let main = layout(device, "self-contact", &slots);
        let round_layout = layout(device, "self-contact round", &[Dynamic]);
        let sizes_layout = layout(device, "self-contact pair groups", &[Write]);
        let all: &[&wgpu::BindGroupLayout] = &[&main, &round_layout];
        let sizing: &[&wgpu::BindGroupLayout] = &[&main, &round_layout, &sizes_layout];
        let kernels = pipelines(
            device,
            "self-contact",
            &shader(),
            ENTRY_POINTS.map(|entry| {
                (
                    entry,
                    if entry.starts_with("size_") {
                        sizing
                    } else {
                        all
                    },
                )
            }),
        );
        let pair_groups = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("self-contact pair groups"),
            size: 2 * TRIANGLE_PAIR_GROUPS,
            usage: U::STORAGE | U::INDIRECT,
            mapped_at_creation: false,
        });
        let pair_groups_group = bind(
            device,
            "self-contact pair groups",
            &sizes_layout,
            &[&pair_groups],
        );
        let rounds = Self::rounds(device, queue, &round_layout);
        let buffers = [uniform, tris, boxes, atomics, lists, kept, no_solve];
        let groups = Self::groups_for(device, &main, particles, &buffers, None);
        Ok(Some(Self {
            kernels,
            sweeps: PUSH_SWEEPS,
            push_rounds: PUSH_ROUNDS,
            groups,
            rounds,
            pair_groups,
            pair_groups_group,
            buffers,
            solve: None,
            particles: particles.clone(),
            layout: main,
            params,
            readout,
            pending: false,
            forced_pairs: 0,
            undone: false,
            together: small(n, 0),
            forced: None,
            room: None,
        }))
    }

    /// The counters and buckets' buffer and the lists' for `params`' room.
    fn rooms(
        device: &wgpu::Device,
        params: &SelfParams,
    ) -> Result<(wgpu::Buffer, wgpu::Buffer), GpuError> {
        let [count, triangles, buckets, entries] = params.counts.map(u64::from);
        let pairs = u64::from(params.more[0]);
        // Per particle: its cut, its pushes' words and its owner in a push round.
        let atomic_words = u64::from(COUNTERS) + buckets + (2 + PUSH_WORDS) * count;
        // Per pair: its particles, whether it was pushed this sweep, its key this round;
        // as much room for pairs of triangles (two words each); and the two counts kept.
        let list_words = 5 * entries + triangles + 8 * pairs + count + 2;
        let need = [
            (4 * atomic_words, "self-contact buckets"),
            (4 * list_words, "self-contact pairs"),
        ];
        let what = format!("{entries} grid entries, {pairs} pairs");
        fits(&device.limits(), &need, &what)?;
        let make = |label: &str, words: u64| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: (4 * words).next_multiple_of(16),
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        Ok((
            make("self-contact counters", atomic_words),
            make("self-contact lists", list_words),
        ))
    }

    /// Each round's number, at its own offset: the cuts' rounds, then each sweep's push
    /// rounds (the round counted through the substep's sweeps, and the sweep).
    fn rounds(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layout: &wgpu::BindGroupLayout,
    ) -> wgpu::BindGroup {
        let stride = ROUND_STRIDE as usize / 4;
        let mut words = vec![0u32; ROUND_ENTRIES as usize * stride];
        for r in 0..ROUNDS {
            words[r as usize * stride] = r;
        }
        for n in 0..PUSH_SWEEPS * PUSH_ROUNDS {
            let at = (ROUNDS + n) as usize * stride;
            (words[at], words[at + 1]) = (n, n / PUSH_ROUNDS);
        }
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("self-contact rounds"),
            size: u64::from(ROUND_ENTRIES) * ROUND_STRIDE,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(&buffer, 0, bytemuck::cast_slice(&words));
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("self-contact rounds"),
            layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(16),
                }),
            }],
        })
    }

    fn groups_for(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        particles: &[wgpu::Buffer; 2],
        [uniform, tris, boxes, atomics, lists, kept, no_solve]: &[wgpu::Buffer; 7],
        solve: Option<&wgpu::Buffer>,
    ) -> [wgpu::BindGroup; 6] {
        let rest = [tris, boxes, atomics, lists, solve.unwrap_or(no_solve)];
        start_end_groups(
            device,
            "self-contact",
            layout,
            (particles, kept),
            uniform,
            &rest,
        )
    }

    fn regroup(&mut self, device: &wgpu::Device) {
        let (particles, solve) = (&self.particles, self.solve.as_ref());
        self.groups = Self::groups_for(device, &self.layout, particles, &self.buffers, solve);
    }

    /// Binds the solver's words the contacts tell of what they moved (see the obstacles').
    pub(super) fn attach_solve(
        &mut self,
        device: &wgpu::Device,
        particles: &[wgpu::Buffer; 2],
        solve: Option<&wgpu::Buffer>,
    ) {
        (self.particles, self.solve) = (particles.clone(), solve.cloned());
        self.regroup(device);
    }

    /// Before a submission of substeps `substep` seconds long: grows the room where the
    /// last submission ran out of it, and writes the uniform with what the integrator
    /// keeps that the contacts change (`memory`) and the step's colliders (from `cloth`,
    /// its uniform).
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] when the room needed exceeds one binding;
    /// [`GpuError::Readback`] when the last counters cannot be read.
    pub(super) fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        substep: f32,
        memory: Memory,
        cloth: &Params,
    ) -> Result<(), GpuError> {
        if let Some(read) = self.read_counters(device)? {
            self.make_room(device, read.asked)?;
        }
        if let Some([pairs, entries]) = self.room.take() {
            let mut shrunk = self.params;
            (shrunk.more[0], shrunk.counts[3]) = (pairs, entries);
            self.resize(device, shrunk)?;
        }
        self.together = self.forced.unwrap_or(self.together);
        self.params.for_step(substep, memory, cloth);
        self.params.passes[1] = self.sweeps.min(PUSH_SWEEPS);
        self.params.passes[2] = self.push_rounds.min(PUSH_ROUNDS);
        queue.write_buffer(&self.buffers[0], 0, bytemuck::bytes_of(&self.params));
        queue.write_buffer(&self.buffers[3], MOST_AT, &[0; MOST_BYTES as usize]);
        Ok(())
    }

    /// Reads what the last submission's substeps asked for and measured, if it has not been
    /// read (`None` where it has), and adds the pairs they forced to
    /// [`Self::forced_pairs`].
    ///
    /// # Errors
    /// [`GpuError::Readback`] when the counters cannot be read.
    pub(super) fn read_counters(
        &mut self,
        device: &wgpu::Device,
    ) -> Result<Option<Counters>, GpuError> {
        if !self.pending {
            return Ok(None);
        }
        self.pending = false;
        let slice = self.readout.slice(..);
        let failed = |e: &dyn std::fmt::Display| GpuError::Readback(e.to_string());
        map_read(device, &slice).map_err(|e| failed(&e))?;
        let [entries, pairs, forced, fastest] = {
            let view = slice.get_mapped_range().map_err(|e| failed(&e))?;
            let words: &[u32] = bytemuck::cast_slice(&view);
            [words[0], words[1], words[2], words[3]]
        };
        self.readout.unmap();
        if !std::mem::take(&mut self.undone) {
            self.forced_pairs += u64::from(forced);
        }
        Ok(Some(Counters {
            asked: [entries, pairs],
            fastest: f32::from_bits(fastest),
        }))
    }

    /// Whether a submission that `asked` for grid entries and pairs ran out of the room.
    pub(super) fn runs_out(&self, [entries, pairs]: [u32; 2]) -> bool {
        entries > self.params.counts[3] || pairs > self.params.more[0]
    }

    /// Grows the room where a submission that `asked` for grid entries and pairs ran out of
    /// it (to twice what it asked) and picks the path for the next. Returns whether it ran
    /// out (then the substeps concerned left the cloth where they started it).
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] when the room needed exceeds one binding.
    pub(super) fn make_room(
        &mut self,
        device: &wgpu::Device,
        [entries, pairs]: [u32; 2],
    ) -> Result<bool, GpuError> {
        self.together = small(self.params.counts[1], pairs);
        let mut grown = self.params;
        if entries > grown.counts[3] {
            grown.counts[3] = entries.saturating_mul(2);
        }
        if pairs > grown.more[0] {
            grown.more[0] = pairs.saturating_mul(2);
        }
        let ran_out = (grown.counts, grown.more) != (self.params.counts, self.params.more);
        self.resize(device, grown)?;
        Ok(ran_out)
    }

    /// Makes the room for pairs and grid entries `params`' (new buffers where it changes).
    fn resize(&mut self, device: &wgpu::Device, params: SelfParams) -> Result<(), GpuError> {
        if (params.counts, params.more) != (self.params.counts, self.params.more) {
            let (atomics, lists) = Self::rooms(device, &params)?;
            (self.buffers[3], self.buffers[4]) = (atomics, lists);
            self.params = params;
            self.regroup(device);
        }
        Ok(())
    }

    /// The buffer of the counters, whose word [`PUSHES_MOVED`] says whether a substep's
    /// pushes moved anything (a new one where the room grows).
    pub(super) fn counters(&self) -> &wgpu::Buffer {
        &self.buffers[3]
    }

    /// The copy [`SelfPass::keep_start`] makes.
    pub(super) fn kept(&self) -> &wgpu::Buffer {
        &self.buffers[5]
    }

    /// Records a copy of the substep's start, `particles[at]`, for an integrator that
    /// writes its end over it.
    pub(super) fn keep_start(&self, pass: &mut wgpu::ComputePass<'_>, at: usize) {
        pass.set_bind_group(1, &self.rounds, &[0]);
        pass.set_bind_group(0, &self.groups[4 + at], &[]);
        self.run(pass, Kernel::KeepStart);
    }

    /// Dispatches `kernel` over what it runs on: a particle, a triangle, a pair (as many
    /// workgroups as the search's pairs need, which `size_pairs` wrote), a pair of triangles
    /// (the same, from `size_triangle_pairs`) or a counter or bucket each invocation; or the
    /// one workgroup that runs all.
    fn run(&self, pass: &mut wgpu::ComputePass<'_>, kernel: Kernel) {
        use Kernel::*;
        let [count, triangles, buckets, _] = self.params.counts;
        let n = match kernel {
            Clear => COUNTERS + buckets,
            Insert | Find | Faces => triangles,
            Cut | Push | Claim | PushAlone => {
                pass.set_pipeline(&self.kernels[kernel as usize]);
                return pass.dispatch_workgroups_indirect(&self.pair_groups, 0);
            }
            PairsOfTriangles => {
                pass.set_pipeline(&self.kernels[kernel as usize]);
                return pass.dispatch_workgroups_indirect(&self.pair_groups, TRIANGLE_PAIR_GROUPS);
            }
            Boxes | CutApply | Finish | KeepStart | PushApply | Solids | FacesApply | FacesLift
            | BeforeObstacles | ObstaclesMoved => count,
            SearchTogether | PushesTogether | SolidsTogether | CutsTogether | SizePairs
            | SizeTrianglePairs => 1,
        };
        pass.set_pipeline(&self.kernels[kernel as usize]);
        pass.dispatch_workgroups(n.div_ceil(WORKGROUP), 1, 1);
    }

    /// Searches the pairs of the substep bound ([`SelfPass::bind`]): each particle's and
    /// triangle's box, the grid, the pairs of triangles whose boxes overlap, their pairs.
    fn search(&self, pass: &mut wgpu::ComputePass<'_>) {
        if self.together {
            return self.run(pass, Kernel::SearchTogether);
        }
        for kernel in [Kernel::Clear, Kernel::Boxes, Kernel::Insert, Kernel::Find] {
            self.run(pass, kernel);
        }
        pass.set_bind_group(2, &self.pair_groups_group, &[]);
        self.run(pass, Kernel::SizeTrianglePairs);
        self.run(pass, Kernel::PairsOfTriangles);
        self.run(pass, Kernel::SizePairs);
    }

    /// Binds the groups of the substep whose start and end `start` says.
    fn bind(&self, pass: &mut wgpu::ComputePass<'_>, start: Start) {
        let group = &self.groups[match start {
            Start::In(i) => i,
            Start::Kept(i) => 2 + i,
        }];
        pass.set_bind_group(0, group, &[]);
        pass.set_bind_group(1, &self.rounds, &[0]);
    }

    /// Records, before the mesh obstacles act on substep's end (`start` says where it is),
    /// where each particle is, so that [`SelfPass::encode_pushes`] holds what they moved.
    pub(super) fn before_obstacles(&self, pass: &mut wgpu::ComputePass<'_>, start: Start) {
        self.bind(pass, start);
        self.run(pass, Kernel::BeforeObstacles);
    }

    /// Records a substep's pushes, where `start` says its start and end are: what the mesh
    /// obstacles moved held as resting on them (with `obstacles`), the triangles kept out of
    /// the spheres (the substep's colliders kept out only its particles), the pairs of the
    /// substep's motion pushed a thickness apart, and what they moved into a sphere or plane
    /// put back out.
    pub(super) fn encode_pushes(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        start: Start,
        obstacles: bool,
    ) {
        self.bind(pass, start);
        if obstacles {
            // Pushed into a table top by the layer above and put back by the obstacles'
            // pass after the pushes, the lowest layer of a stack was pressed into the next
            // one, as on a sphere (below).
            self.run(pass, Kernel::ObstaclesMoved);
        }
        let solids = self.params.passes[0] > 0;
        let colliders = self
            .params
            .colliders
            .iter()
            .take(self.params.passes[0] as usize);
        if colliders.map(|c| c.info[0]).any(|kind| kind == SPHERE) {
            // Before the search, as the CPU's colliders keep the faces out before its
            // self-contact, and what they lift held as resting on the sphere: pushed
            // down by the layer above, the lowest layer of a stack on a sphere was lifted
            // back into it after the pushes, substep after substep, and the cuts held
            // the two pressed together.
            self.run(pass, Kernel::Faces);
            self.run(pass, Kernel::FacesLift);
        }
        self.search(pass);
        if self.together {
            self.run(pass, Kernel::PushesTogether);
            if solids {
                self.run(pass, Kernel::SolidsTogether);
            }
            return;
        }
        let round = |n: u32| (u64::from(ROUNDS + n) * ROUND_STRIDE) as u32;
        for sweep in 0..self.params.passes[1] {
            for r in 0..self.params.passes[2] {
                pass.set_bind_group(1, &self.rounds, &[round(sweep * PUSH_ROUNDS + r)]);
                self.run(pass, Kernel::Claim);
                self.run(pass, Kernel::PushAlone);
            }
            self.run(pass, Kernel::Push);
            self.run(pass, Kernel::PushApply);
        }
        if solids {
            for kernel in [Kernel::Solids, Kernel::Faces, Kernel::FacesApply] {
                self.run(pass, kernel);
            }
        }
    }

    /// Records a substep's cuts, where `start` says its start and end are: the pairs of the
    /// motion as pushed, checked along it.
    pub(super) fn encode_cuts(&self, pass: &mut wgpu::ComputePass<'_>, start: Start) {
        self.bind(pass, start);
        self.search(pass);
        if self.together {
            return self.run(pass, Kernel::CutsTogether);
        }
        for r in 0..ROUNDS {
            pass.set_bind_group(1, &self.rounds, &[(u64::from(r) * ROUND_STRIDE) as u32]);
            self.run(pass, Kernel::Cut);
            self.run(pass, Kernel::CutApply);
        }
        self.run(pass, Kernel::Finish);
    }

    /// Records a copy of the last substep's counters, read before the next submission.
    pub(super) fn copy_counters(&mut self, encoder: &mut wgpu::CommandEncoder) {
        encoder.copy_buffer_to_buffer(
            &self.buffers[3],
            MOST_AT,
            &self.readout,
            0,
            Some(MOST_BYTES),
        );
        (self.pending, self.undone) = (true, false);
    }

    /// The state went back to a rollback point where `forced` pairs had been forced: the
    /// count goes back with it, and what a submission not yet read forced is not added.
    pub(super) fn roll_back_forced(&mut self, forced: u64) {
        self.forced_pairs = forced;
        self.undone = self.pending;
    }
}

#[cfg(test)]
mod tests;
