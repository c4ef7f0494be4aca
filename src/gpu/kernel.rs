//! The compute kernel: one semi-implicit Euler substep per dispatch
//! (`shaders/substep.wgsl`), its bind group layout and pipeline, and the helpers every
//! kernel of the backend builds its layout, pipelines and bind groups with.

/// Particles per workgroup (the shader's `@workgroup_size`; a test compares them).
pub(super) const WORKGROUP: u32 = 64;

/// The substep shader's source.
pub(super) const SOURCE: &str = include_str!("../../shaders/substep.wgsl");

/// The substep pipeline and the layout of what it binds.
pub(super) struct SubstepKernel {
    pub(super) pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

/// What one dispatch binds: the uniform parameters, the state it reads and the one it
/// writes, the springs' CSR offsets and ends, and the class table.
pub(super) struct Bindings<'a> {
    pub(super) params: &'a wgpu::Buffer,
    pub(super) src: &'a wgpu::Buffer,
    pub(super) dst: &'a wgpu::Buffer,
    pub(super) offsets: &'a wgpu::Buffer,
    pub(super) neighbours: &'a wgpu::Buffer,
    pub(super) classes: &'a wgpu::Buffer,
}

/// How a compute shader binds a buffer.
#[derive(Clone, Copy)]
pub(super) enum Slot {
    Uniform,
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
                    Slot::Uniform => wgpu::BufferBindingType::Uniform,
                    Slot::Read => wgpu::BufferBindingType::Storage { read_only: true },
                    Slot::Write => wgpu::BufferBindingType::Storage { read_only: false },
                },
                has_dynamic_offset: false,
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

/// The pipelines of `source`'s `entry_points`, all with `layout`.
pub(super) fn pipelines<const N: usize>(
    device: &wgpu::Device,
    label: &str,
    source: &str,
    layout: &wgpu::BindGroupLayout,
    entry_points: [&str; N],
) -> [wgpu::ComputePipeline; N] {
    let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    entry_points.map(|entry| {
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

impl SubstepKernel {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        use Slot::{Read, Uniform, Write};
        let slots = [Uniform, Read, Write, Read, Read, Uniform];
        let layout = layout(device, "cloth substep", &slots);
        let [pipeline] = pipelines(device, "cloth substep", SOURCE, &layout, ["substep"]);
        Self { pipeline, layout }
    }

    /// The bind group of one dispatch.
    pub(super) fn bind(&self, device: &wgpu::Device, b: &Bindings<'_>) -> wgpu::BindGroup {
        let buffers = [b.params, b.src, b.dst, b.offsets, b.neighbours, b.classes];
        bind(device, "cloth substep", &self.layout, &buffers)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::packing::{CLASS_BITS, MAX_CLASSES};

    /// The value of `const NAME: u32 = …u;` in the shader.
    fn shader_const(name: &str) -> u32 {
        let line = (SOURCE.lines())
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

    /// The shader's constants are the packing's: an end's class bits, the class table's
    /// size, the workgroup.
    #[test]
    fn the_shader_and_the_host_agree_on_their_constants() {
        assert_eq!(shader_const("CLASS_BITS"), CLASS_BITS);
        assert_eq!(shader_const("CLASSES") as usize, MAX_CLASSES);
        assert!(SOURCE.contains(&format!("@workgroup_size({WORKGROUP})")));
    }
}
