//! The render pipelines, built once per renderer. WGSL is embedded at compile time.

use super::geometry::{ClothVertex, ColorVertex, SolidVertex};
use super::target::{COLOR_FORMAT, DEPTH_FORMAT};

const COMMON: &str = include_str!("../../shaders/common.wgsl");
const CLOTH: &str = include_str!("../../shaders/cloth.wgsl");
const LINES: &str = include_str!("../../shaders/lines.wgsl");
const POINTS: &str = include_str!("../../shaders/points.wgsl");
const COLLIDER: &str = include_str!("../../shaders/collider.wgsl");

pub struct Pipelines {
    pub globals_layout: wgpu::BindGroupLayout,
    pub solid_layout: wgpu::BindGroupLayout,
    pub cloth: wgpu::RenderPipeline,
    pub lines: wgpu::RenderPipeline,
    pub points: wgpu::RenderPipeline,
    pub collider: wgpu::RenderPipeline,
}

fn uniform_layout(device: &wgpu::Device, label: &str) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        }],
    })
}

struct Spec<'a> {
    label: &'static str,
    source: &'static str,
    layout: &'a wgpu::PipelineLayout,
    buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    topology: wgpu::PrimitiveTopology,
    blend: Option<wgpu::BlendState>,
}

fn build(device: &wgpu::Device, samples: u32, spec: Spec<'_>) -> wgpu::RenderPipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(spec.label),
        source: wgpu::ShaderSource::Wgsl(format!("{COMMON}\n{}", spec.source).into()),
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(spec.label),
        layout: Some(spec.layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: spec.buffers,
        },
        primitive: wgpu::PrimitiveState {
            topology: spec.topology,
            // Cloth is two-sided; nothing is culled.
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::LessEqual),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: wgpu::MultisampleState {
            count: samples,
            ..Default::default()
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format: COLOR_FORMAT,
                blend: spec.blend,
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

impl Pipelines {
    pub fn new(device: &wgpu::Device, samples: u32) -> Self {
        let globals_layout = uniform_layout(device, "clothsim globals layout");
        let solid_layout = uniform_layout(device, "clothsim solid layout");
        let layout = |label, groups: &[Option<&wgpu::BindGroupLayout>]| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: groups,
                immediate_size: 0,
            })
        };
        let global_only = layout("clothsim global pipeline layout", &[Some(&globals_layout)]);
        let with_solid = layout(
            "clothsim solid pipeline layout",
            &[Some(&globals_layout), Some(&solid_layout)],
        );
        let cloth = build(
            device,
            samples,
            Spec {
                label: "clothsim cloth",
                source: CLOTH,
                layout: &global_only,
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<ClothVertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2],
                })],
                topology: wgpu::PrimitiveTopology::TriangleList,
                blend: None,
            },
        );
        const COLOR_ATTRIBUTES: [wgpu::VertexAttribute; 2] =
            wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x4];
        let color_layout = |step_mode| wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<ColorVertex>() as u64,
            step_mode,
            attributes: &COLOR_ATTRIBUTES,
        };
        let lines = build(
            device,
            samples,
            Spec {
                label: "clothsim lines",
                source: LINES,
                layout: &global_only,
                buffers: &[Some(color_layout(wgpu::VertexStepMode::Vertex))],
                topology: wgpu::PrimitiveTopology::LineList,
                blend: Some(wgpu::BlendState::ALPHA_BLENDING),
            },
        );
        let points = build(
            device,
            samples,
            Spec {
                label: "clothsim points",
                source: POINTS,
                layout: &global_only,
                buffers: &[Some(color_layout(wgpu::VertexStepMode::Instance))],
                topology: wgpu::PrimitiveTopology::TriangleList,
                blend: None,
            },
        );
        let collider = build(
            device,
            samples,
            Spec {
                label: "clothsim collider",
                source: COLLIDER,
                layout: &with_solid,
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<SolidVertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3],
                })],
                topology: wgpu::PrimitiveTopology::TriangleList,
                blend: None,
            },
        );
        Self {
            globals_layout,
            solid_layout,
            cloth,
            lines,
            points,
            collider,
        }
    }
}
