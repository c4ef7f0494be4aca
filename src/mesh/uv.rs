//! Texture coordinates for meshes that have none.

use glam::{Vec2, Vec3};

use super::bounds::{bounds, thinnest_axis};

/// Planar projection onto the two largest extents of the bounding box, with one common
/// scale so a checker stays square: the longer side maps to `[0, 1]`.
pub fn planar_uvs(positions: &[Vec3]) -> Vec<Vec2> {
    let (lo, hi) = bounds(positions);
    let ext = hi - lo;
    // Drop the thinnest axis.
    let thin = thinnest_axis(lo, hi);
    let (a, b) = match thin {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let scale = ext[a].max(ext[b]).max(f32::MIN_POSITIVE);
    positions
        .iter()
        .map(|p| Vec2::new((p[a] - lo[a]) / scale, (p[b] - lo[b]) / scale))
        .collect()
}
