//! What the renderer draws: a plain description of one frame, built by the caller. The
//! renderer knows nothing of simulations or scenes.

use glam::{Mat4, Quat, Vec2, Vec3};

use crate::mesh::SpringKind;

/// Springs as parallel slices (`a[i]`–`b[i]`, rest length, kind).
#[derive(Clone, Copy, Debug, Default)]
pub struct SpringLines<'a> {
    pub a: &'a [u32],
    pub b: &'a [u32],
    /// Rest lengths, metres (for colouring by strain).
    pub rest: &'a [f32],
    pub kind: &'a [SpringKind],
}

/// A solid to draw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A sphere turned by `rotation` (its stripes show a spin).
    Sphere {
        center: Vec3,
        radius: f32,
        rotation: Quat,
    },
    /// A ground plane through `point` with unit `normal`.
    Plane { point: Vec3, normal: Vec3 },
}

/// A triangle mesh to draw (an obstacle), flat-shaded in its own colour: `id` names it
/// while its triangles stay the same (the renderer keeps its buffers from frame to frame,
/// and rewrites the vertices only when it `deforms`), `transform` places it.
#[derive(Clone, Debug)]
pub struct MeshShape<'a> {
    pub id: usize,
    pub vertices: std::borrow::Cow<'a, [Vec3]>,
    pub deforms: bool,
    pub triangles: &'a [[u32; 3]],
    pub transform: Mat4,
}

/// Particle positions that live on the device the renderer draws with (the GPU backend's
/// state): particle i's position, metres, is the xyz of the `vec4` at index `i · stride`.
#[derive(Clone, Copy, Debug)]
pub struct DevicePositions<'a> {
    pub buffer: &'a wgpu::Buffer,
    pub stride: u32,
}

/// One frame: the cloth, its springs and pins, and the solids around it.
#[derive(Clone, Debug, Default)]
pub struct Frame<'a> {
    /// Particle positions, metres (not read when `device_positions` is given).
    pub positions: &'a [Vec3],
    /// The positions on the renderer's device, when they live there: the renderer draws
    /// from them without reading them back. There is one per texture coordinate.
    pub device_positions: Option<DevicePositions<'a>>,
    /// One texture coordinate per particle.
    pub uvs: &'a [Vec2],
    pub triangles: &'a [[u32; 3]],
    pub springs: SpringLines<'a>,
    /// Indices of pinned particles.
    pub pinned: &'a [u32],
    pub shapes: Vec<Shape>,
    /// Meshes around it (obstacles).
    pub meshes: Vec<MeshShape<'a>>,
}
