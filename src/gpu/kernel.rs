//! The compute kernel: one semi-implicit Euler substep per dispatch
//! (`shaders/substep.wgsl`), its bind group layout and pipeline.

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

impl SubstepKernel {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("cloth substep"),
            source: wgpu::ShaderSource::Wgsl(SOURCE.into()),
        });
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let storage = |read_only| wgpu::BufferBindingType::Storage { read_only };
        let uniform = wgpu::BufferBindingType::Uniform;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("cloth substep"),
            entries: &[
                entry(0, uniform),
                entry(1, storage(true)),
                entry(2, storage(false)),
                entry(3, storage(true)),
                entry(4, storage(true)),
                entry(5, uniform),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("cloth substep"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("cloth substep"),
            layout: Some(&pipeline_layout),
            module: &shader,
            entry_point: Some("substep"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self { pipeline, layout }
    }

    /// The bind group of one dispatch.
    pub(super) fn bind(&self, device: &wgpu::Device, b: &Bindings<'_>) -> wgpu::BindGroup {
        let buffers = [b.params, b.src, b.dst, b.offsets, b.neighbours, b.classes];
        let entries: Vec<wgpu::BindGroupEntry<'_>> = (0u32..)
            .zip(buffers)
            .map(|(binding, buffer)| wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("cloth substep"),
            layout: &self.layout,
            entries: &entries,
        })
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
