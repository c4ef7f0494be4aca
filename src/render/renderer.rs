//! The renderer: owns pipelines and GPU buffers and draws a cloth frame into a
//! [`RenderTarget`]. GUI, PNG capture and golden tests all come through [`Renderer::render`].

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Quat, Vec3};
use wgpu::util::DeviceExt;

use crate::mesh::{SpringKind, vertex_normals};

use super::camera::OrbitCamera;
use super::display::{DisplayPass, LineSpec, Outputs, PARTICLE_COLOR, PINNED_COLOR};
use super::frame::{Frame, MeshShape, Shape};
use super::geometry::{
    ClothVertex, ColorVertex, SolidVertex, ground_quad, triangle_edges, uv_sphere,
};
use super::options::{RenderOptions, SpringColoring};
use super::pipelines::Pipelines;
use super::target::RenderTarget;
use crate::device::GrowBuffer;

/// Background, sRGB-encoded (it is written to the target as is): linear (0.10, 0.11, 0.13).
pub const CLEAR_COLOR: wgpu::Color = wgpu::Color {
    r: 0.349,
    g: 0.366,
    b: 0.396,
    a: 1.0,
};

/// Half the side of the drawn ground square, metres.
const GROUND_HALF_SIZE: f32 = 6.0;
/// Grid spacing on the ground, metres.
const GROUND_GRID: f32 = 0.25;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GlobalsRaw {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    light_dir: [f32; 4],
    viewport: [f32; 4],
    front_color: [f32; 4],
    back_color: [f32; 4],
    options: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SolidRaw {
    model: [[f32; 4]; 4],
    color: [f32; 4],
    pattern: [f32; 4],
}

/// A static indexed mesh (collider geometry).
struct StaticMesh {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    count: u32,
}

impl StaticMesh {
    fn new(device: &wgpu::Device, label: &str, (v, i): (Vec<SolidVertex>, Vec<u32>)) -> Self {
        let init = |contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        Self {
            vertices: init(
                bytemuck::cast_slice(&v),
                wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            ),
            indices: init(bytemuck::cast_slice(&i), wgpu::BufferUsages::INDEX),
            count: i.len() as u32,
        }
    }
}

/// A flat-shaded mesh: each triangle's corners with its normal.
fn flat_mesh(shape: &MeshShape<'_>) -> (Vec<SolidVertex>, Vec<u32>) {
    let v = &shape.vertices;
    let vertices: Vec<SolidVertex> = (shape.triangles.iter())
        .flat_map(|t| {
            let [a, b, c] = t.map(|i| v.get(i as usize).copied().unwrap_or(Vec3::ZERO));
            let normal = (b - a).cross(c - a).normalize_or_zero().to_array();
            [a, b, c].map(|p| SolidVertex {
                position: p.to_array(),
                normal,
            })
        })
        .collect();
    let indices = (0..vertices.len() as u32).collect();
    (vertices, indices)
}

/// What a collider slot draws.
#[derive(Clone, Copy, Debug, PartialEq)]
enum SolidDraw {
    Sphere,
    Ground,
    /// The mesh at this place in `meshes`.
    Mesh(usize),
}

/// Colour of obstacles, linear RGBA (a warm grey, apart from the cloth and the blue sphere).
const OBSTACLE_COLOR: [f32; 4] = [0.62, 0.55, 0.45, 1.0];

/// Per-collider uniform slot; slots are created when a scene has more colliders than before.
struct SolidSlot {
    buffer: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

pub struct Renderer {
    pipelines: Pipelines,
    sample_count: u32,
    globals: wgpu::Buffer,
    globals_bind_group: wgpu::BindGroup,
    cloth_vertices: GrowBuffer,
    cloth_indices: GrowBuffer,
    /// The triangles last uploaded; indices are re-uploaded only when they change.
    uploaded_triangles: Vec<[u32; 3]>,
    /// Counts the changes of `uploaded_triangles`.
    topology_generation: u64,
    /// Fills the vertex buffers on the device for frames whose positions live there; made
    /// for the first such frame.
    display: Option<DisplayPass>,
    /// Unique edges of those triangles, for the wireframe.
    wire_edges: Vec<[u32; 2]>,
    lines: GrowBuffer,
    line_vertices: u32,
    points: GrowBuffer,
    point_count: u32,
    sphere: StaticMesh,
    ground: StaticMesh,
    solids: Vec<SolidSlot>,
    /// The meshes drawn last frame, by their frame's `id` (kept while they are drawn).
    meshes: Vec<(usize, StaticMesh)>,
    // Scratch reused every frame.
    /// `(slot, what)` of the colliders to draw, in order.
    solid_draws: Vec<(usize, SolidDraw)>,
    normals: Vec<Vec3>,
    line_specs: Vec<LineSpec>,
    cloth_scratch: Vec<ClothVertex>,
    line_scratch: Vec<ColorVertex>,
    point_scratch: Vec<ColorVertex>,
}

impl Renderer {
    /// Builds pipelines for targets with `sample_count` samples.
    pub fn new(device: &wgpu::Device, sample_count: u32) -> Self {
        let pipelines = Pipelines::new(device, sample_count);
        let globals = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("clothsim globals"),
            size: std::mem::size_of::<GlobalsRaw>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let globals_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("clothsim globals"),
            layout: &pipelines.globals_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: globals.as_entire_binding(),
            }],
        });
        // Vertex buffers a display pass may fill on the device, where it can run.
        let vertex = if device.limits().max_storage_buffers_per_shader_stage >= 4 {
            wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::STORAGE
        } else {
            wgpu::BufferUsages::VERTEX
        };
        Self {
            sample_count,
            globals,
            globals_bind_group,
            cloth_vertices: GrowBuffer::new(device, "clothsim cloth vertices", vertex, 1 << 16),
            cloth_indices: GrowBuffer::new(
                device,
                "clothsim cloth indices",
                wgpu::BufferUsages::INDEX,
                1 << 16,
            ),
            uploaded_triangles: Vec::new(),
            topology_generation: 0,
            display: None,
            wire_edges: Vec::new(),
            lines: GrowBuffer::new(device, "clothsim lines", vertex, 1 << 16),
            line_vertices: 0,
            points: GrowBuffer::new(device, "clothsim points", vertex, 1 << 14),
            point_count: 0,
            sphere: StaticMesh::new(device, "clothsim sphere", uv_sphere(32, 64)),
            ground: StaticMesh::new(device, "clothsim ground", ground_quad(GROUND_HALF_SIZE)),
            solids: Vec::new(),
            meshes: Vec::new(),
            solid_draws: Vec::new(),
            pipelines,
            normals: Vec::new(),
            line_specs: Vec::new(),
            cloth_scratch: Vec::new(),
            line_scratch: Vec::new(),
            point_scratch: Vec::new(),
        }
    }

    pub fn sample_count(&self) -> u32 {
        self.sample_count
    }

    /// Uploads the frame and draws it into `target`, submitting one command buffer. A frame
    /// whose positions live on the device is drawn from them there (nothing is read back);
    /// if their buffer is too small for the frame's particles, from `positions`.
    pub fn render(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        target: &RenderTarget,
        camera: &OrbitCamera,
        frame: &Frame<'_>,
        options: &RenderOptions,
    ) {
        if target.sample_count() != self.sample_count {
            // Only when a target of another sample count is used; not per frame.
            *self = Renderer::new(device, target.sample_count());
        }
        let (width, height) = target.size();
        self.upload_globals(queue, camera, width, height, options);
        self.update_topology(device, queue, frame);
        self.line_specs(frame, options);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("clothsim frame"),
        });
        // A buffer too small for the frame's particles (a stale one) is not read.
        let vec4 = 16;
        let on_device = frame.device_positions.filter(|d| {
            d.buffer.size() >= frame.uvs.len() as u64 * u64::from(d.stride.max(1)) * vec4
        });
        match on_device {
            Some(source) => {
                let display = self.display.get_or_insert_with(|| DisplayPass::new(device));
                let outputs = Outputs {
                    cloth: options.mesh.then_some(&mut self.cloth_vertices),
                    lines: &mut self.lines,
                    points: options.particles.then_some(&mut self.points),
                };
                display.encode(
                    device,
                    queue,
                    &mut encoder,
                    source,
                    frame,
                    self.topology_generation,
                    &self.line_specs,
                    outputs,
                );
                self.line_vertices = 2 * self.line_specs.len() as u32;
                self.point_count = if options.particles {
                    frame.uvs.len() as u32
                } else {
                    0
                };
            }
            None => {
                // Normals and vertices are only worth computing when the surface is drawn.
                if options.mesh {
                    self.upload_cloth(device, queue, frame);
                }
                self.upload_lines(device, queue, frame);
                self.upload_points(device, queue, frame, options);
            }
        }
        self.solid_draws.clear();
        if options.colliders {
            self.upload_solids(device, queue, frame);
        }
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("clothsim frame"),
                color_attachments: &[Some(target.color_attachment(CLEAR_COLOR))],
                depth_stencil_attachment: Some(target.depth_attachment()),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &self.globals_bind_group, &[]);
            pass.set_pipeline(&self.pipelines.collider);
            for &(slot, what) in &self.solid_draws {
                let mesh = match what {
                    SolidDraw::Sphere => &self.sphere,
                    SolidDraw::Ground => &self.ground,
                    SolidDraw::Mesh(at) => &self.meshes[at].1,
                };
                pass.set_bind_group(1, &self.solids[slot].bind_group, &[]);
                pass.set_vertex_buffer(0, mesh.vertices.slice(..));
                pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..mesh.count, 0, 0..1);
            }
            if options.mesh && !self.uploaded_triangles.is_empty() {
                pass.set_pipeline(&self.pipelines.cloth);
                pass.set_vertex_buffer(0, self.cloth_vertices.slice());
                pass.set_index_buffer(self.cloth_indices.slice(), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..self.uploaded_triangles.len() as u32 * 3, 0, 0..1);
            }
            if self.line_vertices > 0 {
                pass.set_pipeline(&self.pipelines.lines);
                pass.set_vertex_buffer(0, self.lines.slice());
                pass.draw(0..self.line_vertices, 0..1);
            }
            if self.point_count > 0 {
                pass.set_pipeline(&self.pipelines.points);
                pass.set_vertex_buffer(0, self.points.slice());
                pass.draw(0..6, 0..self.point_count);
            }
        }
        queue.submit([encoder.finish()]);
    }

    fn upload_globals(
        &self,
        queue: &wgpu::Queue,
        camera: &OrbitCamera,
        width: u32,
        height: u32,
        options: &RenderOptions,
    ) {
        let raw = GlobalsRaw {
            view_proj: camera
                .view_projection(width as f32 / height as f32)
                .to_cols_array_2d(),
            eye: camera.eye().extend(1.0).into(),
            light_dir: Vec3::new(0.4, 1.0, 0.6).normalize().extend(0.0).into(),
            viewport: [width as f32, height as f32, options.particle_size, 0.0],
            front_color: options.front_color.extend(1.0).into(),
            back_color: options.back_color.extend(1.0).into(),
            options: [
                f32::from(u8::from(options.checker)),
                options.checker_scale,
                0.28,
                0.0,
            ],
        };
        queue.write_buffer(&self.globals, 0, bytemuck::bytes_of(&raw));
    }

    /// Re-uploads indices and re-derives wireframe edges only when the triangles changed.
    fn update_topology(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, frame: &Frame<'_>) {
        if self.uploaded_triangles != frame.triangles {
            self.uploaded_triangles = frame.triangles.to_vec();
            self.topology_generation += 1;
            self.wire_edges = triangle_edges(frame.triangles);
            self.cloth_indices
                .write(device, queue, bytemuck::cast_slice(frame.triangles));
        }
    }

    fn upload_cloth(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, frame: &Frame<'_>) {
        vertex_normals(frame.positions, frame.triangles, &mut self.normals);
        self.cloth_scratch.clear();
        self.cloth_scratch.extend(
            frame
                .positions
                .iter()
                .zip(&self.normals)
                .zip(frame.uvs)
                .map(|((p, n), uv)| ClothVertex {
                    position: p.to_array(),
                    normal: n.to_array(),
                    uv: uv.to_array(),
                }),
        );
        self.cloth_vertices
            .write(device, queue, bytemuck::cast_slice(&self.cloth_scratch));
    }

    /// The lines the options ask for (wireframe, then springs), into `line_specs`.
    fn line_specs(&mut self, frame: &Frame<'_>, options: &RenderOptions) {
        let specs = &mut self.line_specs;
        specs.clear();
        let line = |a, b, rest, by_strain, color| LineSpec {
            a,
            b,
            rest,
            by_strain: u32::from(by_strain),
            color,
        };
        if options.wireframe {
            let wire = [0.02, 0.02, 0.03, 0.85];
            specs.extend(
                self.wire_edges
                    .iter()
                    .map(|&[a, b]| line(a, b, 0.0, false, wire)),
            );
        }
        if options.springs {
            let s = &frame.springs;
            let by_strain = options.spring_coloring == SpringColoring::ByStrain;
            for i in 0..s.a.len() {
                let kind = s.kind[i];
                if options.spring_kinds[kind.index()] {
                    specs.push(line(s.a[i], s.b[i], s.rest[i], by_strain, kind_color(kind)));
                }
            }
        }
    }

    fn upload_lines(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, frame: &Frame<'_>) {
        let pos = frame.positions;
        self.line_scratch.clear();
        for l in &self.line_specs {
            let (a, b) = (pos[l.a as usize], pos[l.b as usize]);
            let color = if l.by_strain == 0 {
                l.color
            } else {
                strain_color((a.distance(b) - l.rest) / l.rest.max(1e-9))
            };
            for position in [a, b] {
                self.line_scratch.push(ColorVertex {
                    position: position.to_array(),
                    color,
                });
            }
        }
        self.line_vertices = self.line_scratch.len() as u32;
        self.lines
            .write(device, queue, bytemuck::cast_slice(&self.line_scratch));
    }

    fn upload_points(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        frame: &Frame<'_>,
        options: &RenderOptions,
    ) {
        self.point_scratch.clear();
        if options.particles {
            self.point_scratch
                .extend(frame.positions.iter().map(|p| ColorVertex {
                    position: p.to_array(),
                    color: PARTICLE_COLOR,
                }));
            for &p in frame.pinned {
                if let Some(v) = self.point_scratch.get_mut(p as usize) {
                    v.color = PINNED_COLOR;
                }
            }
        }
        self.point_count = self.point_scratch.len() as u32;
        self.points
            .write(device, queue, bytemuck::cast_slice(&self.point_scratch));
    }

    /// Writes one uniform slot per shape and lists them in `solid_draws`.
    fn upload_solids(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, frame: &Frame<'_>) {
        while self.solids.len() < frame.shapes.len() + frame.meshes.len() {
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("clothsim solid"),
                size: std::mem::size_of::<SolidRaw>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("clothsim solid"),
                layout: &self.pipelines.solid_layout,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: buffer.as_entire_binding(),
                }],
            });
            self.solids.push(SolidSlot { buffer, bind_group });
        }
        for (slot, shape) in frame.shapes.iter().enumerate() {
            let raw = match *shape {
                Shape::Sphere {
                    center,
                    radius,
                    rotation,
                } => SolidRaw {
                    model: Mat4::from_scale_rotation_translation(
                        Vec3::splat(radius),
                        rotation,
                        center,
                    )
                    .to_cols_array_2d(),
                    color: [0.30, 0.42, 0.62, 1.0],
                    pattern: [0.0, 0.0, 0.0, 0.0],
                },
                Shape::Plane { point, normal } => SolidRaw {
                    model: Mat4::from_rotation_translation(
                        Quat::from_rotation_arc(Vec3::Y, normal.normalize()),
                        point,
                    )
                    .to_cols_array_2d(),
                    color: [0.55, 0.56, 0.58, 1.0],
                    pattern: [1.0, GROUND_GRID, 0.0, 0.0],
                },
            };
            queue.write_buffer(&self.solids[slot].buffer, 0, bytemuck::bytes_of(&raw));
            let what = match shape {
                Shape::Sphere { .. } => SolidDraw::Sphere,
                Shape::Plane { .. } => SolidDraw::Ground,
            };
            self.solid_draws.push((slot, what));
        }
        // Meshes: built when first drawn, dropped when a frame no longer has them.
        self.meshes
            .retain(|(id, _)| frame.meshes.iter().any(|m| m.id == *id));
        for (k, shape) in frame.meshes.iter().enumerate() {
            let at = match self.meshes.iter().position(|(id, _)| *id == shape.id) {
                Some(at) => {
                    if shape.deforms {
                        let (vertices, _) = flat_mesh(shape);
                        let bytes = bytemuck::cast_slice(&vertices);
                        queue.write_buffer(&self.meshes[at].1.vertices, 0, bytes);
                    }
                    at
                }
                None => {
                    let mesh = StaticMesh::new(device, "clothsim obstacle", flat_mesh(shape));
                    self.meshes.push((shape.id, mesh));
                    self.meshes.len() - 1
                }
            };
            let raw = SolidRaw {
                model: shape.transform.to_cols_array_2d(),
                color: OBSTACLE_COLOR,
                pattern: [2.0, 0.0, 0.0, 0.0],
            };
            let slot = frame.shapes.len() + k;
            queue.write_buffer(&self.solids[slot].buffer, 0, bytemuck::bytes_of(&raw));
            self.solid_draws.push((slot, SolidDraw::Mesh(at)));
        }
    }
}

/// Linear RGBA of a spring kind.
pub fn kind_color(kind: SpringKind) -> [f32; 4] {
    match kind {
        SpringKind::Structural => [0.15, 0.45, 1.0, 1.0],
        SpringKind::Shear => [0.1, 0.8, 0.2, 1.0],
        SpringKind::Bend => [1.0, 0.45, 0.05, 1.0],
    }
}

/// Linear RGBA for a strain (relative extension): grey at 0, red at ≥ +10 %, blue at ≤ −10 %.
pub fn strain_color(strain: f32) -> [f32; 4] {
    let t = (strain / 0.1).clamp(-1.0, 1.0);
    let grey = Vec3::splat(0.45);
    let c = if t >= 0.0 {
        grey.lerp(Vec3::new(1.0, 0.08, 0.02), t)
    } else {
        grey.lerp(Vec3::new(0.05, 0.3, 1.0), -t)
    };
    c.extend(1.0).into()
}

#[cfg(test)]
mod tests {
    use glam::Vec2;

    use super::*;
    use crate::device::{AdapterPreference, HeadlessDevice};
    use crate::mesh::{GridOrientation, GridSpec};
    use crate::render::{DevicePositions, RgbaImage, SpringLines, read_target};

    /// The first `floats` floats of `buffer`, read back.
    fn read_floats(gpu: &HeadlessDevice, buffer: &GrowBuffer, floats: usize) -> Vec<f32> {
        crate::device::read_buffer(&gpu.device, &gpu.queue, buffer.buffer(), 0, floats)
    }

    /// The cloth, line and point vertices a renderer drew last, and the picture.
    struct Drawn {
        cloth: Vec<f32>,
        lines: Vec<f32>,
        points: Vec<f32>,
        image: RgbaImage,
    }

    fn draw(gpu: &HeadlessDevice, renderer: &mut Renderer, frame: &Frame<'_>) -> Drawn {
        let options = RenderOptions {
            wireframe: true,
            springs: true,
            spring_coloring: SpringColoring::ByStrain,
            spring_kinds: [true; 3],
            particles: true,
            ..RenderOptions::default()
        };
        let target = RenderTarget::new(&gpu.device, 96, 72, 1).expect("target");
        let camera = OrbitCamera::framing(frame.positions, 96.0 / 72.0);
        renderer.render(&gpu.device, &gpu.queue, &target, &camera, frame, &options);
        let n = frame.positions.len();
        Drawn {
            cloth: read_floats(gpu, &renderer.cloth_vertices, 8 * n),
            lines: read_floats(gpu, &renderer.lines, 7 * renderer.line_vertices as usize),
            points: read_floats(gpu, &renderer.points, 7 * n),
            image: read_target(&gpu.device, &gpu.queue, &target).expect("image"),
        }
    }

    fn assert_close(what: &str, cpu: &[f32], device: &[f32], tolerance: f32) {
        assert_eq!(cpu.len(), device.len(), "{what}: lengths");
        let worst = (cpu.iter().zip(device))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        assert!(worst <= tolerance, "{what}: differ by up to {worst}");
    }

    /// A crumpled cloth drawn from positions on the device (every overlay on, springs
    /// coloured by strain) gets the vertices and the picture the CPU path makes from the
    /// same positions; and after its triangles change, and from another buffer, still does.
    #[test]
    fn drawing_from_device_positions_matches_drawing_from_the_cpu() {
        let gpu = HeadlessDevice::open(AdapterPreference::Software).expect("software adapter");
        let mesh = GridSpec::square(8, 1.0, GridOrientation::Vertical, Vec3::ZERO)
            .build()
            .expect("grid");
        let rest = mesh.positions.clone();
        // Crumpled out of plane and stretched or squeezed up to ±20 %: varied normals, and
        // strains past both ends of the colour scale.
        let positions: Vec<Vec3> = (rest.iter().enumerate())
            .map(|(i, p)| {
                let f = i as f32;
                Vec3::new(
                    p.x * (1.0 + 0.2 * (0.7 * f).sin()),
                    p.y,
                    0.15 * (1.3 * f).sin() * p.x.cos(),
                )
            })
            .collect();
        let (mut a, mut b, mut lengths, mut kinds) = (vec![], vec![], vec![], vec![]);
        let pairs = (mesh.edges.iter().zip(&mesh.edge_kinds))
            .map(|(e, &k)| (*e, k))
            .chain(mesh.bend_pairs.iter().map(|&e| (e, SpringKind::Bend)));
        for ([i, j], kind) in pairs {
            a.push(i);
            b.push(j);
            lengths.push(rest[i as usize].distance(rest[j as usize]));
            kinds.push(kind);
        }
        // On the device: position, then a velocity the renderer must skip (stride 2).
        let on_device = |positions: &[Vec3]| {
            let words: Vec<[f32; 4]> = positions
                .iter()
                .flat_map(|p| [p.extend(1.0).to_array(), [99.0; 4]])
                .collect();
            let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("test positions"),
                size: (words.len() * 16) as u64,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            gpu.queue
                .write_buffer(&buffer, 0, bytemuck::cast_slice(&words));
            buffer
        };
        let buffer = on_device(&positions);
        // The same cloth moved, in a buffer of its own (a new source must be bound).
        let moved: Vec<Vec3> = positions
            .iter()
            .map(|p| *p + Vec3::new(0.1, 0.2, 0.0))
            .collect();
        let moved_buffer = on_device(&moved);
        let uvs: Vec<Vec2> = mesh.uvs.clone();
        let pinned = [0u32, 8];
        let mut frame = Frame {
            positions: &positions,
            device_positions: None,
            uvs: &uvs,
            triangles: &mesh.triangles,
            springs: SpringLines {
                a: &a,
                b: &b,
                rest: &lengths,
                kind: &kinds,
            },
            pinned: &pinned,
            shapes: Vec::new(),
            meshes: Vec::new(),
        };
        let (mut cpu, mut device) = (Renderer::new(&gpu.device, 1), Renderer::new(&gpu.device, 1));
        let half = &mesh.triangles[..mesh.triangles.len() / 2];
        let cases = [
            (&mesh.triangles[..], &positions, &buffer),
            (half, &positions, &buffer),
            (half, &moved, &moved_buffer),
        ];
        for (triangles, positions, buffer) in cases {
            frame.triangles = triangles;
            frame.positions = positions;
            frame.device_positions = None;
            let want = draw(&gpu, &mut cpu, &frame);
            frame.device_positions = Some(DevicePositions { buffer, stride: 2 });
            let got = draw(&gpu, &mut device, &frame);
            assert_close("cloth vertices", &want.cloth, &got.cloth, 1e-6);
            assert_close("line vertices", &want.lines, &got.lines, 1e-6);
            assert_close("particle vertices", &want.points, &got.points, 0.0);
            let differing = (want.image.as_raw().iter().zip(got.image.as_raw()))
                .filter(|(x, y)| x.abs_diff(**y) > 1)
                .count();
            assert!(
                differing <= 8,
                "{differing} image bytes differ by more than 1"
            );
        }
        // A buffer too small for the frame's particles (a stale one) is not read: the frame
        // is drawn from `positions`.
        let stale = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("test stale positions"),
            size: 64,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        frame.device_positions = None;
        let want = draw(&gpu, &mut cpu, &frame);
        frame.device_positions = Some(DevicePositions {
            buffer: &stale,
            stride: 2,
        });
        let got = draw(&gpu, &mut device, &frame);
        assert_eq!(want.cloth, got.cloth, "drawn from the positions");
        assert_eq!(want.image.as_raw(), got.image.as_raw());
    }
}
