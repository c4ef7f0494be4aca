//! CPU-side "raw" vertex types for upload, and the static collider meshes.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ClothVertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ColorVertex {
    pub position: [f32; 3],
    pub color: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SolidVertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
}

/// A unit UV sphere: `(vertices, indices)`, counter-clockwise seen from outside.
pub fn uv_sphere(stacks: u32, slices: u32) -> (Vec<SolidVertex>, Vec<u32>) {
    let mut vertices = Vec::new();
    for i in 0..=stacks {
        let theta = std::f32::consts::PI * i as f32 / stacks as f32;
        for j in 0..=slices {
            let phi = std::f32::consts::TAU * j as f32 / slices as f32;
            let p = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            vertices.push(SolidVertex {
                position: p.into(),
                normal: p.into(),
            });
        }
    }
    let mut indices = Vec::new();
    let row = slices + 1;
    for i in 0..stacks {
        for j in 0..slices {
            let a = i * row + j;
            let (b, c, d) = (a + row, a + row + 1, a + 1);
            indices.extend_from_slice(&[a, d, b, b, d, c]);
        }
    }
    (vertices, indices)
}

/// A square of `2·half` metres in the x–z plane, normal +y.
pub fn ground_quad(half: f32) -> (Vec<SolidVertex>, Vec<u32>) {
    let v = |x: f32, z: f32| SolidVertex {
        position: [x * half, 0.0, z * half],
        normal: [0.0, 1.0, 0.0],
    };
    (
        vec![v(-1.0, -1.0), v(-1.0, 1.0), v(1.0, 1.0), v(1.0, -1.0)],
        vec![0, 1, 2, 0, 2, 3],
    )
}

/// Unique edges `[a, b]` (`a < b`, sorted) of a triangle list, for the wireframe.
pub fn triangle_edges(triangles: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut edges: Vec<[u32; 2]> = triangles
        .iter()
        .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
}
