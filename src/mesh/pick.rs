//! Ray picking against a triangle mesh, for grabbing cloth with the mouse.

use glam::Vec3;

/// The nearest triangle a ray hits: distance along the ray, triangle index, and the hit's
/// barycentric weights of the triangle's corners.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub distance: f32,
    pub triangle: usize,
    pub weights: [f32; 3],
}

impl Hit {
    /// The corner of the hit triangle nearest the hit point.
    pub fn nearest_corner(&self, triangles: &[[u32; 3]]) -> u32 {
        let t = triangles[self.triangle];
        let (k, _) = self
            .weights
            .iter()
            .enumerate()
            .fold(
                (0, f32::MIN),
                |best, (k, &w)| if w > best.1 { (k, w) } else { best },
            );
        t[k]
    }
}

/// The first triangle hit by the ray `origin + t·direction`, `t > 0` (Möller–Trumbore,
/// both sides count: cloth is two-sided).
pub fn pick(
    origin: Vec3,
    direction: Vec3,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    for (i, tri) in triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|k| positions[k as usize]);
        let (e1, e2) = (b - a, c - a);
        let p = direction.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            continue;
        }
        let inv = 1.0 / det;
        let s = origin - a;
        let u = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            continue;
        }
        let q = s.cross(e1);
        let v = direction.dot(q) * inv;
        if v < 0.0 || u + v > 1.0 {
            continue;
        }
        let t = e2.dot(q) * inv;
        if t > 0.0 && best.is_none_or(|h| t < h.distance) {
            best = Some(Hit {
                distance: t,
                triangle: i,
                weights: [1.0 - u - v, u, v],
            });
        }
    }
    best
}
