//! The compute kernel: one semi-implicit Euler substep per dispatch
//! (`shaders/substep.wgsl`), its bind group layout and pipeline, and the helpers every
//! kernel of the backend builds its layout, pipelines and bind groups with.

/// Particles per workgroup (the shader's `@workgroup_size`; a test compares them).
pub(super) const WORKGROUP: u32 = 64;

/// What every compute shader of the backend reads the cloth as: particles and spring ends.
pub(super) const LAYOUT: &str = include_str!("../../shaders/cloth_layout.wgsl");
/// What the step shaders share: the contact response, then parameters, bindings, element
/// forces, colliders.
pub(super) const COMMON: &str = concat!(
    include_str!("../../shaders/contact.wgsl"),
    include_str!("../../shaders/step_common.wgsl")
);
/// The closest points of a triangle and of two segments, which the obstacles and
/// self-contact share.
pub(super) const GEOMETRY: &str = include_str!("../../shaders/geometry.wgsl");
/// The contact response every contact shares (part of [`COMMON`] too).
pub(super) const CONTACT: &str = include_str!("../../shaders/contact.wgsl");
/// Semi-implicit Euler's and XPBD's entry points.
pub(super) const SOURCE: &str = include_str!("../../shaders/substep.wgsl");
/// VBD's entry points.
pub(super) const VBD: &str = include_str!("../../shaders/vbd.wgsl");
/// Implicit Euler's entry points (`implicit`).
pub(super) const IMPLICIT: &str = include_str!("../../shaders/implicit.wgsl");

/// The substep's pipelines (semi-implicit Euler's one, XPBD's three, VBD's three) and the
/// layouts of what they bind: group 0 for all, and for XPBD's projection and VBD's descent
/// group 1, the colour they take.
pub(super) struct SubstepKernel {
    pub(super) pipeline: wgpu::ComputePipeline,
    pub(super) predict: wgpu::ComputePipeline,
    pub(super) project: wgpu::ComputePipeline,
    pub(super) finish: wgpu::ComputePipeline,
    /// VBD's three, built the first time VBD steps (most runs never compile its shader).
    pub(super) vbd: Option<VbdPipelines>,
    /// Counts a substep.
    pub(super) tick: wgpu::ComputePipeline,
    pub(super) layout: wgpu::BindGroupLayout,
    pub(super) colour_layout: wgpu::BindGroupLayout,
}

/// What one dispatch binds: the uniform parameters, the state it reads and the one it
/// writes, the springs' CSR offsets and ends, the class table, and the element forces with
/// each particle's slots among them (see `elements`).
pub(super) struct Bindings<'a> {
    pub(super) params: &'a wgpu::Buffer,
    pub(super) src: &'a wgpu::Buffer,
    pub(super) dst: &'a wgpu::Buffer,
    pub(super) offsets: &'a wgpu::Buffer,
    pub(super) neighbours: &'a wgpu::Buffer,
    pub(super) classes: &'a wgpu::Buffer,
    pub(super) element_forces: &'a wgpu::Buffer,
    pub(super) incidence: &'a wgpu::Buffer,
    /// XPBD's constraints or VBD's stencil.
    pub(super) solver: &'a wgpu::Buffer,
}

/// How a compute shader binds a buffer.
#[derive(Clone, Copy)]
pub(super) enum Slot {
    Uniform,
    /// A uniform bound at an offset given with each dispatch.
    Dynamic,
    Read,
    Write,
}

/// A bind group layout for a compute shader whose bindings 0, 1, … are buffers bound as
/// `slots` says.
pub(super) fn layout(device: &wgpu::Device, label: &str, slots: &[Slot]) -> wgpu::BindGroupLayout {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = (0u32..)
        .zip(slots)
        .map(|(binding, slot)| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: match slot {
                    Slot::Uniform | Slot::Dynamic => wgpu::BufferBindingType::Uniform,
                    Slot::Read => wgpu::BufferBindingType::Storage { read_only: true },
                    Slot::Write => wgpu::BufferBindingType::Storage { read_only: false },
                },
                has_dynamic_offset: matches!(slot, Slot::Dynamic),
                min_binding_size: None,
            },
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    })
}

/// The pipelines of `source`'s `entry_points`, each with its bind group layouts (group
/// 0, 1, …).
pub(super) fn pipelines<const N: usize>(
    device: &wgpu::Device,
    label: &str,
    source: &str,
    entry_points: [(&str, &[&wgpu::BindGroupLayout]); N],
) -> [wgpu::ComputePipeline; N] {
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    entry_points.map(|(entry, layouts)| {
        let groups: Vec<Option<&wgpu::BindGroupLayout>> =
            layouts.iter().copied().map(Some).collect();
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &groups,
            immediate_size: 0,
        });
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(&pipeline_layout),
            module: &shader,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    })
}

/// A buffer of `size` bytes (at least 32, a multiple of 16) for `usage`, written to by the
/// host.
pub(super) fn sized_buffer(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(32).next_multiple_of(16),
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// A bind group of `layout` with `buffers` at bindings 0, 1, ….
pub(super) fn bind(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry<'_>> = (0u32..)
        .zip(buffers)
        .map(|(binding, buffer)| wgpu::BindGroupEntry {
            binding,
            resource: buffer.as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// The six bind groups of a contact pass that binds `uniform`, a substep's start and its
/// end, then `rest`: `[i]` reads the start from `particles[i]` and moves the other;
/// `[2 + i]` reads it from `kept` and moves `particles[i]`; `[4 + i]` binds `particles[i]`
/// as the start and `kept` as the end (to copy the one into the other).
pub(super) fn start_end_groups(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    (particles, kept): (&[wgpu::Buffer; 2], &wgpu::Buffer),
    uniform: &wgpu::Buffer,
    rest: &[&wgpu::Buffer],
) -> [wgpu::BindGroup; 6] {
    [0, 1, 2, 3, 4, 5].map(|g| {
        let i = g % 2;
        let (start, end) = match g / 2 {
            0 => (&particles[i], &particles[1 - i]),
            1 => (kept, &particles[i]),
            _ => (&particles[i], kept),
        };
        let mut buffers = vec![uniform, start, end];
        buffers.extend_from_slice(rest);
        bind(device, label, layout, &buffers)
    })
}

/// VBD's entry points' pipelines.
pub(super) struct VbdPipelines {
    pub(super) predict: wgpu::ComputePipeline,
    pub(super) descend: wgpu::ComputePipeline,
    pub(super) finish: wgpu::ComputePipeline,
}

impl SubstepKernel {
    /// VBD's pipelines, built on the first call.
    pub(super) fn vbd(&mut self, device: &wgpu::Device) -> &VbdPipelines {
        let (layout, colour) = (&self.layout, &self.colour_layout);
        self.vbd.get_or_insert_with(|| {
            let [predict, descend, finish] = pipelines(
                device,
                "cloth vbd",
                &format!("{LAYOUT}{COMMON}{VBD}"),
                [
                    ("vbd_predict", &[layout]),
                    ("vbd_descend", &[layout, colour]),
                    ("vbd_finish", &[layout]),
                ],
            );
            VbdPipelines {
                predict,
                descend,
                finish,
            }
        })
    }

    pub(super) fn new(device: &wgpu::Device) -> Self {
        use Slot::{Dynamic, Read, Uniform, Write};
        let slots = [
            Uniform, Read, Write, Read, Read, Uniform, Write, Read, Write,
        ];
        let layout = layout(device, "cloth substep", &slots);
        let colour_layout = self::layout(device, "cloth colour", &[Dynamic]);
        let one: &[&wgpu::BindGroupLayout] = &[&layout];
        let two: &[&wgpu::BindGroupLayout] = &[&layout, &colour_layout];
        let [pipeline, predict, project, finish, tick] = pipelines(
            device,
            "cloth substep",
            &format!("{LAYOUT}{COMMON}{SOURCE}"),
            [
                ("substep", one),
                ("xpbd_predict", one),
                ("xpbd_project", two),
                ("xpbd_finish", one),
                ("tick", one),
            ],
        );
        Self {
            pipeline,
            predict,
            project,
            finish,
            vbd: None,
            tick,
            layout,
            colour_layout,
        }
    }

    /// The substep's bind groups: `[i]` reads particle buffer `i` and writes the other, with
    /// the `fixed` uniform, spring offsets, spring ends and class table, and the element
    /// pass's forces and slots and XPBD's constraints.
    /// Records the substep's count (`tick`) with the substep's `group` bound: what ran
    /// before it in the pass may have bound a group of another layout.
    pub(super) fn count_substep(&self, pass: &mut wgpu::ComputePass<'_>, group: &wgpu::BindGroup) {
        pass.set_pipeline(&self.tick);
        pass.set_bind_group(0, group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
    }

    pub(super) fn groups(
        &self,
        device: &wgpu::Device,
        particles: &[wgpu::Buffer; 2],
        [params, offsets, neighbours, classes]: [&wgpu::Buffer; 4],
        [element_forces, incidence, solver]: [&wgpu::Buffer; 3],
    ) -> [wgpu::BindGroup; 2] {
        [0, 1].map(|from| {
            let bindings = Bindings {
                params,
                src: &particles[from],
                dst: &particles[1 - from],
                offsets,
                neighbours,
                classes,
                element_forces,
                incidence,
                solver,
            };
            self.bind(device, &bindings)
        })
    }

    /// The bind group of one dispatch.
    pub(super) fn bind(&self, device: &wgpu::Device, b: &Bindings<'_>) -> wgpu::BindGroup {
        let buffers = [
            b.params,
            b.src,
            b.dst,
            b.offsets,
            b.neighbours,
            b.classes,
            b.element_forces,
            b.incidence,
            b.solver,
        ];
        bind(device, "cloth substep", &self.layout, &buffers)
    }
}

/// The value of `const NAME: u32 = …u;` in the shader `source` (for tests that hold the
/// host's copies of a shader's constants to it).
#[cfg(test)]
pub(super) fn shader_const(source: &str, name: &str) -> u32 {
    let line = (source.lines())
        .find(|l| l.starts_with(&format!("const {name}: u32 = ")))
        .unwrap_or_else(|| panic!("no `const {name}` in the shader"));
    let value = line.split('=').nth(1).unwrap_or_default();
    value
        .trim()
        .trim_end_matches(';')
        .trim_end_matches('u')
        .parse()
        .unwrap()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::packing::{CLASS_BITS, MAX_CLASSES};

    /// The shader's constants are the packing's: an end's class bits, the class table's
    /// size, the workgroup.
    #[test]
    fn the_shader_and_the_host_agree_on_their_constants() {
        assert_eq!(shader_const(LAYOUT, "CLASS_BITS"), CLASS_BITS);
        assert_eq!(shader_const(LAYOUT, "CLASSES") as usize, MAX_CLASSES);
        for source in [SOURCE, VBD, IMPLICIT] {
            let ours = format!("@workgroup_size({WORKGROUP})");
            assert!(source.contains(&ours));
            // Besides the one-invocation `tick`.
            let single = source.matches("@workgroup_size(1)\n").count();
            let all = source.matches("@workgroup_size(").count();
            assert_eq!(all, source.matches(&ours).count() + single);
            assert!(single <= 1);
        }
    }
}
