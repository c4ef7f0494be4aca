//! Forces on elements rather than springs (`shaders/elements.wgsl`): wind on triangles and
//! dihedral bending on hinges, computed one invocation per element into slots of their
//! own, which the substep sums per particle over a CSR list of the slots it is in.

use bytemuck::{Pod, Zeroable};

use crate::cloth::ClothModel;
use crate::sim::forces::DihedralBending;
use crate::sim::{Effect, Force, ForceSet, Wind};

use super::kernel::{LAYOUT, Slot, WORKGROUP, bind, layout, pipelines};

/// The shader's source.
const SOURCE: &str = include_str!("../../shaders/elements.wgsl");

/// The shader's `Params`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
struct Params {
    clock: [f32; 4],
    wind: [f32; 4],
    air: [f32; 4],
    counts: [u32; 4],
}

/// The elements as the shader reads them.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct PackedElements {
    /// Triangles (corners, 0), then per hinge its points and the bits of its rest angle
    /// and weight.
    pub(super) rows: Vec<[u32; 4]>,
    /// Per particle the range of its slots (the first particles + 1 entries), then the
    /// slots: a triangle's index, or for corner `k` of hinge `h` triangles + 4h + k.
    pub(super) incidence: Vec<u32>,
    pub(super) triangles: u32,
    pub(super) hinges: u32,
}

/// Whether `effects` have wind, and `forces` a dihedral term: what decides the element
/// pass's buffers (their strengths are the uniform's).
pub(super) fn elements_wanted(effects: &[Effect], forces: &ForceSet) -> (bool, bool) {
    let wind = effects.iter().any(|e| matches!(e, Effect::Wind(_)));
    let dihedral = (forces.terms().iter()).any(|t| t.get::<DihedralBending>().is_some());
    (wind, dihedral)
}

/// The triangles of `model` when `wind` blows and the hinges of its dihedral term in
/// `forces` when it has one, with each particle's slots.
pub(super) fn pack_elements(model: &ClothModel, forces: &ForceSet, wind: bool) -> PackedElements {
    let dihedral = (forces.terms().iter()).find_map(Force::get::<DihedralBending>);
    let mut packed = PackedElements::default();
    // (particle, slot) in slot order.
    let mut touches: Vec<(u32, u32)> = Vec::new();
    if wind {
        for (t, tri) in (0u32..).zip(&model.triangles) {
            packed.rows.push([tri[0], tri[1], tri[2], 0]);
            touches.extend(tri.iter().map(|&p| (p, t)));
        }
        packed.triangles = model.triangles.len() as u32;
    }
    if let Some(bending) = dihedral {
        let (rest, weight) = bending.rest_and_weight();
        let first = packed.triangles;
        for (h, (ids, (r, w))) in (0u32..).zip(model.hinges.iter().zip(rest.iter().zip(weight))) {
            packed.rows.push(*ids);
            packed.rows.push([r.to_bits(), w.to_bits(), 0, 0]);
            touches.extend((0u32..).zip(ids).map(|(k, &p)| (p, first + 4 * h + k)));
        }
        packed.hinges = model.hinges.len() as u32;
    }
    // A counting sort by particle keeps each particle's slots in slot order.
    let (offsets, slots) = crate::mesh::grouped(model.particle_count(), |visit| {
        touches.iter().for_each(|&(p, slot)| visit(p, slot));
    });
    packed.incidence = offsets;
    packed.incidence.extend(slots);
    packed
}

/// The element pass: its pipeline (built once), buffers and bind groups (one per particle
/// buffer).
pub(super) struct ElementKernel {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    groups: [wgpu::BindGroup; 2],
    uniform: wgpu::Buffer,
    rows: wgpu::Buffer,
    /// The frame's substep count in the first `vec4`, then one `vec4` per slot, then the
    /// handles' targets: the substep reads and counts here.
    pub(super) forces: wgpu::Buffer,
    /// `vec4`s before the targets (the count and the slots), and room for all.
    slots: u64,
    capacity: u64,
    /// [`PackedElements::incidence`], for the substep.
    pub(super) incidence: wgpu::Buffer,
    params: Params,
}

/// A buffer of `bytes` (at least 16) for `usage`, written from the host.
fn element_buffer(
    device: &wgpu::Device,
    label: &str,
    bytes: u64,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

impl ElementKernel {
    /// The pass for `packed` over either of `particles`, with the wind and the dihedral
    /// stiffness of `effects`.
    pub(super) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        particles: &[wgpu::Buffer; 2],
        packed: &PackedElements,
        effects: &[Effect],
    ) -> Self {
        use Slot::{Read, Uniform, Write};
        let layout = layout(device, "cloth elements", &[Uniform, Read, Read, Write]);
        let [pipeline] = pipelines(
            device,
            "cloth elements",
            &format!("{LAYOUT}{SOURCE}"),
            [("elements_forces", &[&layout])],
        );
        let uniform = element_buffer(
            device,
            "cloth elements params",
            size_of::<Params>() as u64,
            wgpu::BufferUsages::UNIFORM,
        );
        let empty = |label| element_buffer(device, label, 16, wgpu::BufferUsages::STORAGE);
        let (rows, forces, incidence) = (empty("rows"), empty("forces"), empty("slots"));
        let groups = element_groups(device, &layout, particles, [&uniform, &rows, &forces]);
        let mut kernel = Self {
            pipeline,
            layout,
            groups,
            uniform,
            rows,
            forces,
            slots: 1,
            capacity: 1,
            incidence,
            params: Params::default(),
        };
        kernel.pack(device, queue, particles, packed);
        kernel.tune(effects);
        kernel
    }

    /// Sends `packed` (new buffers; the pipeline stays): the substep's bind groups that
    /// read [`ElementKernel::forces`] and [`ElementKernel::incidence`] are then stale.
    pub(super) fn pack(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        particles: &[wgpu::Buffer; 2],
        packed: &PackedElements,
    ) {
        use wgpu::BufferUsages as U;
        let slots = 1 + packed.triangles as u64 + 4 * packed.hinges as u64;
        let rows = packed.rows.len() as u64 * 16;
        self.rows = element_buffer(device, "cloth elements", rows, U::STORAGE);
        self.forces = element_buffer(
            device,
            "cloth element forces",
            slots * 16,
            U::STORAGE | U::COPY_SRC,
        );
        let incidence = packed.incidence.len() as u64 * 4;
        self.incidence = element_buffer(device, "cloth element slots", incidence, U::STORAGE);
        if !packed.rows.is_empty() {
            queue.write_buffer(&self.rows, 0, bytemuck::cast_slice(&packed.rows));
        }
        queue.write_buffer(&self.incidence, 0, bytemuck::cast_slice(&packed.incidence));
        (self.slots, self.capacity) = (slots, slots);
        let buffers = [&self.uniform, &self.rows, &self.forces];
        self.groups = element_groups(device, &self.layout, particles, buffers);
        self.params.counts = [packed.triangles, packed.hinges, 0, 0];
    }

    /// Takes the wind and the dihedral stiffness of `effects` (sent with the next
    /// [`ElementKernel::start`]): a new strength needs no new buffers.
    pub(super) fn tune(&mut self, effects: &[Effect]) {
        for effect in effects {
            match effect {
                Effect::Wind(w) => {
                    let Wind {
                        velocity: v,
                        gust,
                        gust_period,
                        drag,
                        lift,
                        air_density,
                    } = *w;
                    self.params.wind = [v.x, v.y, v.z, gust];
                    self.params.air = [gust_period, drag, lift, air_density];
                }
                Effect::Bending(crate::sim::BendingModel::Dihedral { stiffness }) => {
                    self.params.clock[2] = *stiffness;
                }
                _ => {}
            }
        }
    }

    /// Where the handles' targets start in [`ElementKernel::forces`], in `vec4`s.
    pub(super) fn targets_at(&self) -> u32 {
        self.slots as u32
    }

    /// Sends the handles' `targets` after the slots, making room when there is too little
    /// (over either of `particles`). Returns whether the buffer was made anew (its bind
    /// groups elsewhere are then stale).
    pub(super) fn write_targets(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        particles: &[wgpu::Buffer; 2],
        targets: &[[f32; 4]],
    ) -> bool {
        let needed = self.slots + targets.len() as u64;
        let grew = needed > self.capacity;
        if grew {
            self.capacity = needed.next_power_of_two();
            let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC;
            let bytes = self.capacity * 16;
            self.forces = element_buffer(device, "cloth element forces", bytes, usage);
            let buffers = [&self.uniform, &self.rows, &self.forces];
            self.groups = element_groups(device, &self.layout, particles, buffers);
        }
        if !targets.is_empty() {
            queue.write_buffer(&self.forces, self.slots * 16, bytemuck::cast_slice(targets));
        }
        grew
    }

    /// Elements the pass computes (0: no pass).
    pub(super) fn elements(&self) -> u32 {
        self.params.counts[0] + self.params.counts[1]
    }

    /// Sets the substep length, seconds (sent with the next [`ElementKernel::start`]).
    pub(super) fn set_step(&mut self, h: f32) {
        self.params.clock[1] = h;
    }

    /// Before a submission whose first substep starts at `time` seconds: its clock (the
    /// substeps it has taken, which VBD's first guess reads too, start at none).
    pub(super) fn start(&mut self, queue: &wgpu::Queue, time: f64) {
        queue.write_buffer(&self.forces, 0, bytemuck::bytes_of(&[0.0f32; 4]));
        if self.elements() > 0 {
            self.params.clock[0] = time as f32;
            queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&self.params));
        }
    }

    /// Records the pass over particle buffer `current` (nothing without elements).
    pub(super) fn dispatch(&self, pass: &mut wgpu::ComputePass<'_>, current: usize) {
        let count = self.elements();
        if count > 0 {
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.groups[current], &[]);
            pass.dispatch_workgroups(count.div_ceil(WORKGROUP), 1, 1);
        }
    }
}

/// The element pass's bind groups over either of `particles`, with its uniform, rows and
/// forces.
fn element_groups(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    particles: &[wgpu::Buffer; 2],
    [uniform, rows, forces]: [&wgpu::Buffer; 3],
) -> [wgpu::BindGroup; 2] {
    [0, 1].map(|k| {
        bind(
            device,
            "cloth elements",
            layout,
            &[uniform, &particles[k], rows, forces],
        )
    })
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::super::packing::Particle;
    use super::*;
    use crate::device::{AdapterPreference, HeadlessDevice, read_buffer};
    use crate::scene::Scene;
    use crate::sim::{BendingModel, ForceTerm};

    /// The element shader's workgroups are the size the host dispatches for.
    #[test]
    fn the_element_shader_and_the_host_agree_on_the_workgroup() {
        assert!(SOURCE.contains(&format!("@workgroup_size({WORKGROUP})")));
    }

    /// On a crumpled, moving flag with two hinges' wings pressed almost onto their edges
    /// (where the force is limited), the element pass summed per particle over its slots
    /// gives the CPU's wind and dihedral forces on every particle, to f32 rounding.
    #[test]
    fn the_element_forces_summed_per_particle_are_the_cpus() {
        let gpu = HeadlessDevice::open(AdapterPreference::Software).expect("an adapter");
        let scene = Scene::builtin("flag").expect("scene");
        let model = &scene.model;
        let mut state = scene.initial.clone();
        let mut rng = crate::test_rng::uniform(11);
        let mut jitter = |s: f32| s * Vec3::new(rng() - 0.5, rng() - 0.5, rng() - 0.5);
        for (x, v) in state.pos.iter_mut().zip(&mut state.vel) {
            *x += jitter(0.03);
            *v = jitter(4.0);
        }
        for h in [3, 40] {
            let [x0, x1, a, _] = model.hinges[h].map(|i| i as usize);
            let (p0, p1) = (state.pos[x0], state.pos[x1]);
            let along = 0.3 * (p1 - p0);
            let off = (p1 - p0).any_orthonormal_vector() * 0.005 * p0.distance(p1);
            state.pos[a] = p0 + along + off;
        }
        let forces = ForceSet::new(model, &scene.params.material, &scene.effects);
        let time = 0.37;
        let mut cpu = vec![Vec3::ZERO; state.pos.len()];
        for e in &scene.effects {
            match e {
                Effect::Wind(w) => {
                    let term = crate::sim::WindForce::new(*w, model);
                    ForceTerm::<f32>::add_forces(
                        &term, model, &state.pos, &state.vel, time, &mut cpu,
                    )
                }
                Effect::Bending(BendingModel::Dihedral { .. }) => {
                    let term = (forces.terms().iter()).find_map(Force::get::<DihedralBending>);
                    term.expect("a dihedral term")
                        .add_forces::<f32>(model, &state.pos, &mut cpu);
                }
                _ => {}
            }
        }
        let packed = pack_elements(model, &forces, true);
        assert!(packed.triangles > 0 && packed.hinges > 0);
        let data: Vec<Particle> = (state.pos.iter().zip(&state.vel))
            .map(|(x, v)| Particle {
                x: [x.x, x.y, x.z, 1.0],
                v: [v.x, v.y, v.z, 0.0],
            })
            .collect();
        let particle_buffer = || {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: None,
                size: (data.len() * size_of::<Particle>()) as u64,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let particles = [particle_buffer(), particle_buffer()];
        gpu.queue
            .write_buffer(&particles[0], 0, bytemuck::cast_slice(&data));
        let (device, queue) = (&gpu.device, &gpu.queue);
        let mut kernel = ElementKernel::new(device, queue, &particles, &packed, &scene.effects);
        kernel.set_step(1e-3);
        kernel.start(queue, time);
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            kernel.dispatch(&mut pass, 0);
        }
        queue.submit([encoder.finish()]);
        let slots = kernel.forces.size() as usize / size_of::<[f32; 4]>();
        let slots: Vec<[f32; 4]> = read_buffer(device, queue, &kernel.forces, 0, slots);
        let n = model.particle_count();
        let (offsets, list) = packed.incidence.split_at(n + 1);
        let mut worst = 0.0f32;
        let largest = cpu.iter().fold(0.0f32, |m, f| m.max(f.length()));
        for p in 0..n {
            let range = offsets[p] as usize..offsets[p + 1] as usize;
            let sum = (list[range].iter()).fold(Vec3::ZERO, |s, &slot| {
                s + Vec3::from_slice(&slots[1 + slot as usize][..3])
            });
            worst = worst.max(sum.distance(cpu[p]));
        }
        eprintln!("worst {worst:e} N of {largest} N");
        assert!(largest > 0.1, "the forces are not small ({largest} N)");
        assert!(
            worst < 1e-5 * largest,
            "GPU and CPU forces differ by {worst} N"
        );
    }
}
