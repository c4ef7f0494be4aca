//! XPBD on the GPU (`xpbd_*` in `shaders/substep.wgsl`): the springs as distance
//! constraints in the CPU's colour order ([`crate::sim::DistanceConstraints::halves`]: the
//! two halves' colours, then the seam's), one dispatch per colour (the halves' k-th
//! colours together), so a sweep is the CPU's Gauss–Seidel sweep: constraints that run at
//! the same time share no particle, and each particle meets its constraints in the CPU's
//! order.

use std::ops::Range;

use bytemuck::{Pod, Zeroable};

use crate::sim::Halves;

use super::error::GpuError;
use super::kernel::{SubstepKernel, WORKGROUP};
use super::support::fits;

/// A constraint as the shader reads it (its `Constraint`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub(super) struct GpuConstraint {
    a: u32,
    b: u32,
    rest: f32,
    compliance: f32,
    /// Compliance × dashpot, s (the CPU's product, in f32).
    damped: f32,
    lambda: f32,
}

/// Bytes between colour records: dynamic uniform offsets must be multiples of the device's
/// alignment, which is at most 256.
const COLOUR_STRIDE: u64 = 256;

/// Workgroups one dispatch may have along x.
const MOST_GROUPS: u32 = 65_535;

/// Colours to dispatch one after another, each a range of entries (constraints or
/// particles in colour order): a record per colour in a uniform buffer, bound at a dynamic
/// offset.
pub(super) struct Colours {
    group: wgpu::BindGroup,
    /// Workgroups per colour, in order.
    groups: Vec<u32>,
}

impl Colours {
    /// The colours `records` (`[first, count, serial, invocations]`) on `device`.
    pub(super) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        kernel: &SubstepKernel,
        records: &[[u32; 4]],
    ) -> Self {
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("colours"),
            size: (records.len() as u64).max(1) * COLOUR_STRIDE,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        for (k, record) in records.iter().enumerate() {
            let at = k as u64 * COLOUR_STRIDE;
            queue.write_buffer(&uniform, at, bytemuck::bytes_of(record));
        }
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("colour"),
            layout: &kernel.colour_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &uniform,
                    offset: 0,
                    size: wgpu::BufferSize::new(16),
                }),
            }],
        });
        Self {
            group,
            groups: records.iter().map(|c| c[3] / WORKGROUP).collect(),
        }
    }

    /// The colours' bind group (each colour at its own dynamic offset).
    pub(super) fn group(&self) -> &wgpu::BindGroup {
        &self.group
    }

    /// Records `pipeline` over every colour in order, with the substep's `group`.
    pub(super) fn sweep(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        pipeline: &wgpu::ComputePipeline,
        group: &wgpu::BindGroup,
    ) {
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, group, &[]);
        for (k, &groups) in self.groups.iter().enumerate() {
            let offset = (k as u64 * COLOUR_STRIDE) as u32;
            pass.set_bind_group(1, &self.group, &[offset]);
            pass.dispatch_workgroups(groups, 1, 1);
        }
    }
}

/// The record of a colour of `count` entries from `first`: `serial` when they may share a
/// particle (one invocation takes them in order), else one invocation each (at most
/// [`MOST_GROUPS`] workgroups, each invocation taking every so many).
pub(super) fn colour_record(first: usize, count: usize, serial: bool) -> [u32; 4] {
    let count = count as u32;
    let groups = if serial {
        1
    } else {
        count.div_ceil(WORKGROUP).clamp(1, MOST_GROUPS)
    };
    [first as u32, count, u32::from(serial), groups * WORKGROUP]
}

/// XPBD's constraints on the device and its colours.
pub(super) struct XpbdPass {
    /// Bound in the substep's group 0.
    pub(super) constraints: wgpu::Buffer,
    /// Its colours, one dispatch each a sweep.
    pub(super) colours: Colours,
    pub(super) count: u32,
}

/// Each colour's record `[first, count, serial, invocations]` in sweep order, and the
/// constraints of `halves` as the shader reads them, laid out in that order. The halves
/// share no particle, so the k-th colour of each goes in one dispatch (when neither is
/// serial): every particle still meets its constraints in the CPU's order, and a sweep
/// takes one dispatch per colour of the larger half and of the seam rather than of all
/// three.
pub(super) fn pack_constraints(halves: &Halves) -> (Vec<GpuConstraint>, Vec<[u32; 4]>) {
    let c = &halves.constraints;
    let gpu = |k: usize| GpuConstraint {
        a: c.a[k],
        b: c.b[k],
        rest: c.rest[k],
        compliance: c.compliance[k],
        damped: c.compliance[k] * c.damping[k],
        lambda: 0.0,
    };
    let mut constraints = Vec::with_capacity(c.len());
    let mut colours = Vec::new();
    let mut colour = |ranges: &[&Range<usize>], independent: bool| {
        let first = constraints.len();
        for range in ranges {
            constraints.extend((*range).clone().map(gpu));
        }
        let count = constraints.len() - first;
        if count > 0 {
            colours.push(colour_record(first, count, !independent));
        }
    };
    let [low, high] = &halves.halves;
    for k in 0..low.len().max(high.len()) {
        match (low.get(k), high.get(k)) {
            (Some((a, true)), Some((b, true))) => colour(&[a, b], true),
            (a, b) => {
                for (range, independent) in [a, b].into_iter().flatten() {
                    colour(&[range], *independent);
                }
            }
        }
    }
    for (range, independent) in &halves.seam {
        colour(&[range], *independent);
    }
    (constraints, colours)
}

impl XpbdPass {
    /// The pass for `halves` (none: nothing to project) on `device`.
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] with the sizes when the constraints exceed one binding.
    pub(super) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        kernel: &SubstepKernel,
        halves: Option<&Halves>,
    ) -> Result<Self, GpuError> {
        let (constraints, colours) = halves.map(pack_constraints).unwrap_or_default();
        let bytes = (constraints.len() * size_of::<GpuConstraint>()) as u64;
        let count = format!("{} constraints", constraints.len());
        fits(&device.limits(), &[(bytes, "XPBD constraints")], &count)?;
        let storage = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("xpbd constraints"),
            size: bytes.max(32),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        if !constraints.is_empty() {
            queue.write_buffer(&storage, 0, bytemuck::cast_slice(&constraints));
        }
        Ok(Self {
            constraints: storage,
            colours: Colours::new(device, queue, kernel, &colours),
            count: constraints.len() as u32,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;
    use crate::sim::ForceSet;

    /// The bench cloth's constraints, packed: each once; no two in a colour that runs at
    /// once share a particle; each particle meets its constraints in the CPU's order (the
    /// halves' colours, then the seam's), so the sweep's arithmetic is the CPU's; and the
    /// halves' colours share dispatches.
    #[test]
    fn the_halves_colours_share_dispatches_and_each_particle_keeps_the_cpus_order() {
        let scene = Scene::open_resized("hanging-bench", None, &Default::default(), Some(23))
            .expect("a scene");
        let forces = ForceSet::new(&scene.model, &scene.params.material, &scene.effects);
        let halves = forces.constraints(&scene.model).halves(&scene.initial.pos);
        let (packed, records) = pack_constraints(&halves);
        let c = &halves.constraints;
        let key = |a: u32, b: u32, rest: f32| (a, b, rest.to_bits());
        // The CPU's order: the halves' colours, then the seam's.
        let cpu: Vec<_> = (halves.halves.iter().flatten())
            .chain(&halves.seam)
            .flat_map(|(range, _)| range.clone())
            .map(|k| key(c.a[k], c.b[k], c.rest[k]))
            .collect();
        let gpu: Vec<_> = (records.iter())
            .flat_map(|r| r[0] as usize..(r[0] + r[1]) as usize)
            .map(|k| key(packed[k].a, packed[k].b, packed[k].rest))
            .collect();
        let mut sorted = [cpu.clone(), gpu.clone()];
        sorted.iter_mut().for_each(|v| v.sort_unstable());
        assert_eq!(sorted[0], sorted[1], "each constraint once");
        assert_eq!(gpu.len(), packed.len());
        for r in records.iter().filter(|r| r[2] == 0) {
            let mut seen = std::collections::HashSet::new();
            for k in r[0]..r[0] + r[1] {
                let p = &packed[k as usize];
                assert!(
                    seen.insert(p.a) && seen.insert(p.b),
                    "colour {r:?} shares a particle"
                );
            }
        }
        let order = |list: &[(u32, u32, u32)]| {
            let mut met = vec![Vec::new(); halves.particles];
            for &(a, b, rest) in list {
                met[a as usize].push((a, b, rest));
                met[b as usize].push((a, b, rest));
            }
            met
        };
        assert!(
            order(&cpu) == order(&gpu),
            "a particle meets its constraints out of order"
        );
        let cpu_colours = (halves.halves.iter().flatten()).chain(&halves.seam).count();
        eprintln!(
            "{} dispatches a sweep, against {cpu_colours}",
            records.len()
        );
        assert!(records.len() < cpu_colours);
    }
}
