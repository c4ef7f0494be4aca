//! Welding: corners at the same position become one particle.

use std::collections::HashMap;

use glam::{Vec2, Vec3};

use super::polygons::PolygonSoup;

/// The soup's corners welded into particles.
pub struct Welded {
    /// One position per particle, in first-use order.
    pub positions: Vec<Vec3>,
    /// One texture coordinate per particle (the first corner's; zero without UVs).
    pub uvs: Vec<Vec2>,
    /// Particle of every face corner, parallel to `PolygonSoup::face_indices`.
    pub corners: Vec<u32>,
}

/// Exact position key: equal coordinates weld (−0 and +0 count as equal).
fn weld_key(p: Vec3) -> [u32; 3] {
    let bits = |x: f32| if x == 0.0 { 0 } else { x.to_bits() };
    [bits(p.x), bits(p.y), bits(p.z)]
}

/// Welds the corners of `soup` by exact position, numbering particles in first-use order.
pub fn weld(soup: &PolygonSoup) -> Welded {
    let mut ids: HashMap<[u32; 3], u32> = HashMap::with_capacity(soup.positions.len());
    let mut out = Welded {
        positions: Vec::new(),
        uvs: Vec::new(),
        corners: Vec::with_capacity(soup.face_indices.len()),
    };
    for &i in &soup.face_indices {
        let p = soup.positions[i as usize];
        let id = *ids.entry(weld_key(p)).or_insert_with(|| {
            out.positions.push(p);
            out.uvs
                .push(soup.uvs.as_ref().map_or(Vec2::ZERO, |uv| uv[i as usize]));
            (out.positions.len() - 1) as u32
        });
        out.corners.push(id);
    }
    out
}
