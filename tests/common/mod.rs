//! What the GPU test files share.

/// The largest distance between the same particle in `a` and `b`, metres.
pub fn farthest(a: &[glam::Vec3], b: &[glam::Vec3]) -> f32 {
    (a.iter().zip(b))
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f32::max)
}
