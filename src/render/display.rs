//! Drawing from positions that live on the device (the GPU backend's state): a compute pass
//! fills the renderer's vertex buffers there, in the layouts the CPU path uploads, so the
//! same render pipelines draw them and nothing is read back. What does not change from frame
//! to frame (triangles, texture coordinates, which lines, which pins) is uploaded when it
//! changes.

use bytemuck::{Pod, Zeroable};

use super::frame::{DevicePositions, Frame};
use crate::device::GrowBuffer;
use crate::mesh::triangles_around;

const SOURCE: &str = include_str!("../../shaders/display.wgsl");
/// Invocations per workgroup (the shader's `@workgroup_size`).
const WORKGROUP: u32 = 64;

/// Colour of a free particle's dot, linear RGBA.
pub const PARTICLE_COLOR: [f32; 4] = [1.0, 0.85, 0.15, 1.0];
/// Colour of a pinned particle's dot, linear RGBA.
pub const PINNED_COLOR: [f32; 4] = [1.0, 0.05, 0.05, 1.0];

/// One line to draw: between particles `a` and `b`, in `color`, or coloured by the strain of
/// a spring of rest length `rest` when `by_strain` is 1. Both paths build their lines from
/// these; the CPU path turns them into vertices itself, this one on the device.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct LineSpec {
    pub a: u32,
    pub b: u32,
    pub rest: f32,
    pub by_strain: u32,
    pub color: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Info {
    count: u32,
    stride: u32,
    lines: u32,
    corners_at: u32,
    particle_color: [f32; 4],
    pinned_color: [f32; 4],
}

/// A storage buffer of inputs, uploaded only when its bytes change.
struct Input {
    buffer: GrowBuffer,
    sent: Option<Vec<u8>>,
}

impl Input {
    fn new(device: &wgpu::Device, label: &'static str) -> Self {
        Self {
            buffer: GrowBuffer::new(device, label, wgpu::BufferUsages::STORAGE, 256),
            sent: None,
        }
    }

    fn put(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, bytes: &[u8]) {
        if self.sent.as_deref() != Some(bytes) {
            self.buffer.write(device, queue, bytes);
            let sent = self.sent.get_or_insert_with(Vec::new);
            sent.clear();
            sent.extend_from_slice(bytes);
        }
    }
}

/// One entry point: its pipeline, and its bind group with the buffers it was made for
/// (made again only when one of them changes: a grown output, another source).
struct Stage {
    pipeline: wgpu::ComputePipeline,
    bound: Vec<wgpu::Buffer>,
    group: Option<wgpu::BindGroup>,
}

impl Stage {
    fn new(device: &wgpu::Device, module: &wgpu::ShaderModule, entry: &str) -> Self {
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("clothsim display"),
            // The entry point's own layout: it binds only what it uses.
            layout: None,
            module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        });
        Self {
            pipeline,
            bound: Vec::new(),
            group: None,
        }
    }

    /// Binds `buffers` (binding, buffer) and dispatches one invocation per item, in
    /// workgroups of [`WORKGROUP`] (wrapping into a second dimension past `max_groups`).
    fn dispatch(
        &mut self,
        device: &wgpu::Device,
        pass: &mut wgpu::ComputePass<'_>,
        buffers: &[(u32, &wgpu::Buffer)],
        items: usize,
        max_groups: u32,
    ) {
        let same = self.bound.len() == buffers.len()
            && (self.bound.iter().zip(buffers)).all(|(old, (_, new))| old == *new);
        let group = match &self.group {
            Some(group) if same => group,
            _ => {
                let entries: Vec<wgpu::BindGroupEntry<'_>> = (buffers.iter())
                    .map(|&(binding, buffer)| wgpu::BindGroupEntry {
                        binding,
                        resource: buffer.as_entire_binding(),
                    })
                    .collect();
                self.bound = buffers.iter().map(|&(_, b)| b.clone()).collect();
                self.group
                    .insert(device.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("clothsim display"),
                        layout: &self.pipeline.get_bind_group_layout(0),
                        entries: &entries,
                    }))
            }
        };
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        let groups = (items as u32).div_ceil(WORKGROUP);
        let x = groups.clamp(1, max_groups);
        pass.dispatch_workgroups(x, groups.div_ceil(x), 1);
    }
}

/// The vertex buffers a display pass fills (`cloth` only when the surface is drawn).
pub(super) struct Outputs<'b> {
    pub cloth: Option<&'b mut GrowBuffer>,
    pub lines: &'b mut GrowBuffer,
    pub points: Option<&'b mut GrowBuffer>,
}

pub(super) struct DisplayPass {
    cloth: Stage,
    line_ends: Stage,
    points: Stage,
    /// The device's `max_compute_workgroups_per_dimension`.
    max_groups: u32,
    info: wgpu::Buffer,
    topology: Input,
    /// The `(particles, topology generation)` `topology` was built for.
    topology_of: Option<(usize, u64)>,
    uvs: Input,
    lines: Input,
    pinned: Input,
    pinned_flags: Vec<u32>,
}

impl DisplayPass {
    pub fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("clothsim display"),
            source: wgpu::ShaderSource::Wgsl(SOURCE.into()),
        });
        Self {
            cloth: Stage::new(device, &module, "cloth"),
            line_ends: Stage::new(device, &module, "line_ends"),
            points: Stage::new(device, &module, "points"),
            max_groups: device.limits().max_compute_workgroups_per_dimension,
            info: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("clothsim display info"),
                size: std::mem::size_of::<Info>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            topology: Input::new(device, "clothsim display topology"),
            topology_of: None,
            uvs: Input::new(device, "clothsim display uvs"),
            lines: Input::new(device, "clothsim display lines"),
            pinned: Input::new(device, "clothsim display pins"),
            pinned_flags: Vec::new(),
        }
    }

    /// Encodes the passes that fill `out` from `source` for `frame` (whose `positions` are
    /// not read) with `lines`; `generation` changes whenever the frame's triangles do.
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        source: DevicePositions<'_>,
        frame: &Frame<'_>,
        generation: u64,
        lines: &[LineSpec],
        out: Outputs<'_>,
    ) {
        let count = frame.uvs.len();
        if self.topology_of != Some((count, generation)) {
            self.topology_of = Some((count, generation));
            let words = incident_triangles(count, frame.triangles);
            self.topology
                .put(device, queue, bytemuck::cast_slice(&words));
        }
        let info = Info {
            count: count as u32,
            stride: source.stride,
            lines: lines.len() as u32,
            // The offsets, then one entry per corner.
            corners_at: (count + 1 + 3 * frame.triangles.len()) as u32,
            particle_color: PARTICLE_COLOR,
            pinned_color: PINNED_COLOR,
        };
        queue.write_buffer(&self.info, 0, bytemuck::bytes_of(&info));
        let float = std::mem::size_of::<f32>() as u64;
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("clothsim display"),
            timestamp_writes: None,
        });
        let (info, source) = ((0, &self.info), (1, source.buffer));
        let max_groups = self.max_groups;
        if let Some(cloth) = out.cloth {
            self.uvs.put(device, queue, bytemuck::cast_slice(frame.uvs));
            cloth.reserve(device, count as u64 * 8 * float);
            let buffers = [
                info,
                source,
                (2, self.topology.buffer.buffer()),
                (3, self.uvs.buffer.buffer()),
                (4, cloth.buffer()),
            ];
            (self.cloth).dispatch(device, &mut pass, &buffers, count, max_groups);
        }
        if !lines.is_empty() {
            self.lines.put(device, queue, bytemuck::cast_slice(lines));
            out.lines.reserve(device, lines.len() as u64 * 14 * float);
            let buffers = [
                info,
                source,
                (5, self.lines.buffer.buffer()),
                (6, out.lines.buffer()),
            ];
            (self.line_ends).dispatch(device, &mut pass, &buffers, lines.len(), max_groups);
        }
        if let Some(points) = out.points {
            self.pinned_flags.clear();
            self.pinned_flags.resize(count, 0);
            for &p in frame.pinned {
                if let Some(flag) = self.pinned_flags.get_mut(p as usize) {
                    *flag = 1;
                }
            }
            self.pinned
                .put(device, queue, bytemuck::cast_slice(&self.pinned_flags));
            points.reserve(device, count as u64 * 7 * float);
            let buffers = [
                info,
                source,
                (7, self.pinned.buffer.buffer()),
                (6, points.buffer()),
            ];
            (self.points).dispatch(device, &mut pass, &buffers, count, max_groups);
        }
    }
}

/// The shader's topology words: `count + 1` offsets into the list that follows, the
/// triangles around each particle in increasing order (a triangle that names a particle
/// twice is listed twice, as the CPU's normals count it twice), then three corners per
/// triangle.
fn incident_triangles(count: usize, triangles: &[[u32; 3]]) -> Vec<u32> {
    let (mut words, list) = triangles_around(count, triangles);
    words.extend(list);
    words.extend(triangles.iter().flatten());
    words
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn incident_triangles_lists_each_corner_in_triangle_order() {
        // Particles 0..4; triangle 2 names particle 3 twice.
        let triangles = [[0, 1, 2], [2, 1, 3], [3, 3, 0]];
        let words = incident_triangles(4, &triangles);
        let (offsets, rest) = words.split_at(5);
        assert_eq!(offsets, [0, 2, 4, 6, 9]);
        assert_eq!(&rest[..9], [0, 2, 0, 1, 0, 1, 1, 2, 2]);
        assert_eq!(&rest[9..], [0, 1, 2, 2, 1, 3, 3, 3, 0]);
    }
}
