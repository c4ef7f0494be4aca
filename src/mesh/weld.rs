//! Welding: corners at the same position — within a tolerance relative to the cloth's size
//! — become one particle.

use glam::{Vec2, Vec3};
use rustc_hash::FxHashMap;

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
/// the soup's bounding-box diagonal; 0 welds only bit-equal positions (−0 and +0 count as
/// equal).
///
/// Candidates come from a spatial hash of cubes twice the tolerance across: a particle
/// within the tolerance of a corner lies in the corner's cube or in the neighbour on the
/// nearer side along each axis, so 8 cubes are searched.
pub fn weld(soup: &PolygonSoup, relative: f32) -> Welded {
    let tolerance = relative * bbox_diagonal(&soup.positions);
    let mut out = Welded {
        positions: Vec::new(),
        uvs: Vec::new(),
        corners: Vec::with_capacity(soup.face_indices.len()),
    };
    // Each cube's particles as a chain: the newest in `cells`, each one's elder in `elder`
    // (no list allocated per cube).
    let mut cells: FxHashMap<[i64; 3], u32> =
        FxHashMap::with_capacity_and_hasher(soup.positions.len(), Default::default());
    let mut elder: Vec<u32> = Vec::new();
    let cell = 2.0 * tolerance;
    // A position seen before gets the same particle: particles made since have larger
    // numbers, so the earliest within reach is still the one it found.
    let mut seen = vec![NONE; soup.positions.len()];
    for &i in &soup.face_indices {
        if let Some(&id) = seen.get(i as usize).filter(|&&id| id != NONE) {
            out.corners.push(id);
            continue;
        }
        let p = soup.positions[i as usize];
        let (home, found) = if tolerance > 0.0 {
            let scaled = p / cell;
            let home = scaled.floor();
            // −1 or +1 per axis: towards the nearer face of the cube.
            let side = (scaled - home).cmplt(Vec3::splat(0.5));
            let toward = Vec3::select(side, Vec3::NEG_ONE, Vec3::ONE);
            let home = home.as_i64vec3().to_array();
            let step = toward.as_i64vec3().to_array();
            let found = (0..8)
                .flat_map(|corner| {
                    let pick = |axis: usize| home[axis] + step[axis] * ((corner >> axis) & 1);
                    chain(&cells, &elder, [pick(0), pick(1), pick(2)])
                })
                .filter(|&id| out.positions[id as usize].distance(p) <= tolerance)
                .min();
            (home, found)
        } else {
            let bits = |x: f32| if x == 0.0 { 0 } else { x.to_bits() as i64 };
            let home = [bits(p.x), bits(p.y), bits(p.z)];
            // Positions equal to the bit: a cube never holds two particles.
            (home, cells.get(&home).copied())
        };
        let id = found.unwrap_or_else(|| {
            let id = out.positions.len() as u32;
            out.positions.push(p);
            out.uvs
                .push(soup.uvs.as_ref().map_or(Vec2::ZERO, |uv| uv[i as usize]));
            elder.push(cells.insert(home, id).unwrap_or(NONE));
            id
        });
        seen[i as usize] = id;
        out.corners.push(id);
    }
    out
}

/// The end of a cube's chain.
const NONE: u32 = u32::MAX;

/// The particles in `cube`, newest first.
fn chain<'a>(
    cells: &'a FxHashMap<[i64; 3], u32>,
    elder: &'a [u32],
    cube: [i64; 3],
) -> impl Iterator<Item = u32> + 'a {
    std::iter::successors(cells.get(&cube).copied(), move |&id| {
        Some(elder[id as usize]).filter(|&e| e != NONE)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rule itself, corner by corner against every particle so far.
    fn brute_force(positions: &[Vec3], corners: &[u32], tolerance: f32) -> (Vec<Vec3>, Vec<u32>) {
        let (mut particles, mut out) = (Vec::<Vec3>::new(), Vec::new());
        for &i in corners {
            let p = positions[i as usize];
            let id = particles
                .iter()
                .position(|q| q.distance(p) <= tolerance)
                .unwrap_or_else(|| {
                    particles.push(p);
                    particles.len() - 1
                });
            out.push(id as u32);
        }
        (particles, out)
    }

    #[test]
    fn the_hash_finds_exactly_the_earliest_particle_within_the_tolerance() {
        // Clusters of points scattered over about three tolerances, so pairs fall on both
        // sides of cube faces, just inside and just outside the tolerance.
        let mut rnd = crate::test_rng::uniform(99);
        let mut positions = Vec::new();
        for _ in 0..60 {
            let centre = Vec3::new(rnd(), rnd(), rnd());
            for _ in 0..20 {
                positions.push(centre + 3e-3 * (Vec3::new(rnd(), rnd(), rnd()) - 0.5));
            }
        }
        positions.push(Vec3::ZERO);
        positions.push(Vec3::ONE); // bounding box diagonal √3
        // Every position once, then again in another order (shared corners, as a mesh has).
        let n = positions.len() as u32;
        let corners: Vec<u32> = (0..n).chain((0..n).rev().step_by(3)).collect();
        let soup = PolygonSoup {
            positions: positions.clone(),
            uvs: None,
            face_indices: corners.clone(),
            face_arities: vec![],
        };
        let relative = 1e-3;
        let tolerance = relative * bbox_diagonal(&positions);
        let welded = weld(&soup, relative);
        let (particles, ids) = brute_force(&positions, &corners, tolerance);
        assert!(particles.len() < positions.len() / 2, "the clusters weld");
        assert!(particles.len() > 60, "but not into one per cluster");
        assert_eq!(welded.corners, ids);
        assert_eq!(welded.positions, particles);
    }
}
