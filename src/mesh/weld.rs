//! Welding: corners at the same position — within a tolerance relative to the cloth's size
//! — become one particle.

use glam::{Vec2, Vec3};
use rustc_hash::FxHashMap;

use super::bounds::bbox_diagonal;
use super::polygons::PolygonSoup;

/// The soup's corners welded into particles.
pub struct Welded {
    /// One position per particle (its earliest vertex's), in the order of the soup's
    /// vertices (a file's `v` statements), whatever order the faces use them in.
    pub positions: Vec<Vec3>,
    /// One texture coordinate per particle (its earliest vertex's; zero without UVs).
    pub uvs: Vec<Vec2>,
    /// Particle of every face corner, parallel to `PolygonSoup::face_indices`.
    pub corners: Vec<u32>,
}

/// Welds the corners of `soup`: each vertex a face uses, in the soup's order, joins the
/// earliest particle within `relative` × the soup's bounding-box diagonal; 0 welds only
/// bit-equal positions (−0 and +0 count as equal).
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
    // The particle of each vertex the faces use (each is welded once; its corners then
    // read it here).
    let mut seen = vec![NONE; soup.positions.len()];
    // The vertices the faces use, in the file's order: particles keep the order the
    // vertices were written in (row by row for a grid), which keeps neighbours' numbers
    // close together (see `SpringRuns`).
    let mut used = vec![false; soup.positions.len()];
    for &i in &soup.face_indices {
        used[i as usize] = true;
    }
    for i in (0..soup.positions.len()).filter(|&i| used[i]) {
        let p = soup.positions[i];
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
                .push(soup.uvs.as_ref().map_or(Vec2::ZERO, |uv| uv[i]));
            elder.push(cells.insert(home, id).unwrap_or(NONE));
            id
        });
        seen[i] = id;
    }
    out.corners
        .extend(soup.face_indices.iter().map(|&i| seen[i as usize]));
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

    /// The rule itself: each used vertex in the soup's order against every particle so far.
    fn brute_force(positions: &[Vec3], corners: &[u32], tolerance: f32) -> (Vec<Vec3>, Vec<u32>) {
        let mut particles = Vec::<Vec3>::new();
        let mut id = vec![u32::MAX; positions.len()];
        for (i, &p) in positions.iter().enumerate() {
            if corners.contains(&(i as u32)) {
                let found = particles.iter().position(|q| q.distance(p) <= tolerance);
                id[i] = found.unwrap_or_else(|| {
                    particles.push(p);
                    particles.len() - 1
                }) as u32;
            }
        }
        (particles, corners.iter().map(|&i| id[i as usize]).collect())
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
        // Every third position backwards, then every position (shared corners, as a mesh
        // has): particles still come in the positions' order, not in the corners'.
        let n = positions.len() as u32;
        let corners: Vec<u32> = (0..n).rev().step_by(3).chain(0..n).collect();
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
