//! Welding: corners at the same position — within a tolerance relative to the cloth's size
//! — become one particle.

use std::collections::HashMap;

use glam::{Vec2, Vec3};

use super::bounds::bbox_diagonal;
use super::polygons::PolygonSoup;

/// The soup's corners welded into particles.
pub struct Welded {
    /// One position per particle (its first corner's), in first-use order.
    pub positions: Vec<Vec3>,
    /// One texture coordinate per particle (the first corner's; zero without UVs).
    pub uvs: Vec<Vec2>,
    /// Particle of every face corner, parallel to `PolygonSoup::face_indices`.
    pub corners: Vec<u32>,
}

/// Welds the corners of `soup`: a corner joins the earliest particle within `relative` ×
/// the soup's bounding-box diagonal (a spatial hash of cells that size finds candidates in
/// the 27 cells around it); 0 welds only bit-equal positions (−0 and +0 count as equal).
pub fn weld(soup: &PolygonSoup, relative: f32) -> Welded {
    let tolerance = relative * bbox_diagonal(&soup.positions);
    let mut out = Welded {
        positions: Vec::new(),
        uvs: Vec::new(),
        corners: Vec::with_capacity(soup.face_indices.len()),
    };
    let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::with_capacity(soup.positions.len());
    let cell_of = |p: Vec3| -> [i64; 3] {
        if tolerance > 0.0 {
            (p / tolerance).floor().as_i64vec3().to_array()
        } else {
            let bits = |x: f32| if x == 0.0 { 0 } else { x.to_bits() as i64 };
            [bits(p.x), bits(p.y), bits(p.z)]
        }
    };
    for &i in &soup.face_indices {
        let p = soup.positions[i as usize];
        let home = cell_of(p);
        let found = if tolerance > 0.0 {
            neighbours(home)
                .filter_map(|c| cells.get(&c))
                .flatten()
                .copied()
                .filter(|&id| out.positions[id as usize].distance(p) <= tolerance)
                .min()
        } else {
            cells.get(&home).and_then(|ids| ids.first().copied())
        };
        let id = found.unwrap_or_else(|| {
            let id = out.positions.len() as u32;
            out.positions.push(p);
            out.uvs
                .push(soup.uvs.as_ref().map_or(Vec2::ZERO, |uv| uv[i as usize]));
            cells.entry(home).or_default().push(id);
            id
        });
        out.corners.push(id);
    }
    out
}

/// The 27 cells around (and including) `c`.
fn neighbours(c: [i64; 3]) -> impl Iterator<Item = [i64; 3]> {
    (-1..=1).flat_map(move |dx| {
        (-1..=1).flat_map(move |dy| (-1..=1).map(move |dz| [c[0] + dx, c[1] + dy, c[2] + dz]))
    })
}
