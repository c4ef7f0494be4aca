//! Axis-aligned bounds of point sets.

use glam::Vec3;

/// Axis-aligned bounds `(min, max)` of a point set; `(0, 0)` when empty.
pub fn bounds(points: &[Vec3]) -> (Vec3, Vec3) {
    if points.is_empty() {
        return (Vec3::ZERO, Vec3::ZERO);
    }
    points.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
        (lo.min(p), hi.max(p))
    })
}

/// Length of the bounding-box diagonal of a point set, metres (0 when empty).
pub fn bbox_diagonal(points: &[Vec3]) -> f32 {
    let (lo, hi) = bounds(points);
    (hi - lo).length()
}

/// Index (0 = x, 1 = y, 2 = z) of the smallest extent of the box `lo..hi`: the normal
/// axis of a flat cloth. Ties go to the lower index.
pub fn thinnest_axis(lo: Vec3, hi: Vec3) -> usize {
    let ext = hi - lo;
    if ext.x <= ext.y && ext.x <= ext.z {
        0
    } else if ext.y <= ext.z {
        1
    } else {
        2
    }
}
