//! Per-vertex normals, recomputed every frame for shading.

use glam::Vec3;

/// Area-weighted vertex normals: each triangle adds its unnormalised face normal (twice its
/// area) to its corners, then every sum is normalised. Writes into `out` (resized to
/// `positions.len()`), so a caller can reuse the buffer every frame. A vertex whose triangles
/// cancel out gets `+Y`.
pub fn vertex_normals(positions: &[Vec3], triangles: &[[u32; 3]], out: &mut Vec<Vec3>) {
    out.clear();
    out.resize(positions.len(), Vec3::ZERO);
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            out[i as usize] += n;
        }
    }
    for n in out.iter_mut() {
        *n = n.try_normalize().unwrap_or(Vec3::Y);
    }
}
