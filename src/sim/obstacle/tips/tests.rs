//! Which vertices are tips: corners and apexes, not the points of a flat or gently curved
//! surface.

use glam::Vec3;

use crate::sim::obstacle::{Surface, unit_cube};

/// The tips of `vertices` and `triangles`, as a surface finds them, sorted by place.
fn tips_of(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Vec<[f32; 3]> {
    let surface = Surface::new(vertices, triangles);
    let tips = surface.tips();
    let mut found = Vec::new();
    let far = Vec3::splat(1e6);
    tips.in_box(-far, far, |tip| found.push(tip.to_array()));
    assert_eq!(found.len(), tips.len());
    found.sort_by(|a, b| a.partial_cmp(b).expect("finite"));
    found
}

/// A flat `n` × `n` grid of unit cells in the plane y = 0, lifted at its middle vertex by
/// `lift` (a gentle bump or a spike).
fn grid(n: u32, lift: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let at = |i: u32, j: u32| i * (n + 1) + j;
    let vertices = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| (i, j)))
        .map(|(i, j)| {
            let middle = i == n / 2 && j == n / 2;
            Vec3::new(i as f32, if middle { lift } else { 0.0 }, j as f32)
        })
        .collect();
    let triangles = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .flat_map(|(i, j)| {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            [[a, c, b], [a, d, c]]
        })
        .collect();
    (vertices, triangles)
}

#[test]
fn a_cubes_tips_are_its_eight_corners() {
    let (v, t, _) = unit_cube();
    let tips = tips_of(v.clone(), t);
    let mut corners: Vec<[f32; 3]> = v.iter().map(|p| p.to_array()).collect();
    corners.sort_by(|a, b| a.partial_cmp(b).expect("finite"));
    assert_eq!(tips, corners);
}

/// A spike in the middle of a flat sheet is a tip, and so are the vertices round it (their
/// faces turn there); a bump whose faces turn by less than 10° is not. The sheet's border
/// (open edges, sharp) ends at tips all round it.
#[test]
fn a_spike_is_a_tip_and_a_gentle_bump_is_not() {
    let border = |tips: &[[f32; 3]]| tips.iter().filter(|p| p[1] == 0.0).count();
    let (v, t) = grid(4, 0.05);
    let gentle = tips_of(v, t);
    assert_eq!(border(&gentle), 16, "the border's vertices");
    assert_eq!(gentle.len(), 16, "no bump: {gentle:?}");
    let (v, t) = grid(4, 0.5);
    let spiked = tips_of(v, t);
    assert!(spiked.contains(&[2.0, 0.5, 2.0]));
    // The spike's six neighbours (the grid's diagonals run one way).
    let ring = [[1, 1], [1, 2], [2, 1], [2, 3], [3, 2], [3, 3]];
    let inner = |p: &&[f32; 3]| p[0] > 0.0 && p[0] < 4.0 && p[2] > 0.0 && p[2] < 4.0;
    let mut found: Vec<[f32; 3]> = spiked.iter().filter(inner).copied().collect();
    found.retain(|p| p[1] == 0.0);
    let ring: Vec<[f32; 3]> = ring.map(|[i, j]| [i as f32, 0.0, j as f32]).to_vec();
    assert_eq!(found, ring);
    assert_eq!(spiked.len(), 16 + 1 + 6);
}

/// A surface written with each face's corners apart is one surface: a cube of 36
/// vertices (each triangle its own) has the same eight tips; and refitted over moved
/// vertices, the tips move with them.
#[test]
fn tips_are_found_across_faces_written_apart_and_move_with_a_refit() {
    let (v, t, _) = unit_cube();
    let apart: Vec<Vec3> = t
        .iter()
        .flat_map(|tri| tri.map(|i| v[i as usize]))
        .collect();
    let triangles: Vec<[u32; 3]> = (0..t.len() as u32)
        .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
        .collect();
    let tips = tips_of(apart.clone(), triangles.clone());
    let mut unique = tips.clone();
    unique.dedup();
    assert_eq!(unique.len(), 8, "{tips:?}");
    let mut surface = Surface::new(apart.clone(), triangles);
    let moved: Vec<Vec3> = apart
        .iter()
        .map(|&p| p + Vec3::new(2.0, 0.0, 0.0))
        .collect();
    surface.refit(&moved);
    let mut count = 0;
    surface
        .tips()
        .in_box(Vec3::new(1.9, -0.1, -0.1), Vec3::new(3.1, 1.1, 1.1), |_| {
            count += 1
        });
    assert_eq!(count, surface.tips().len());
}

/// A smooth bowl-shaped cap `y = c (x² + z²) / 2`, finely cut (its faces turn by under 10°
/// round every vertex): no tips but its open border's, and the curvature read from its
/// faces not below `c` by more than a fifth, nor above twice it (the estimate takes the
/// sharpest turn of each fan over the distance between its faces' centroids, which reads
/// high across a grid's diagonals: up to 1.5 `c` here).
#[test]
fn a_smooth_caps_vertices_are_smooth_and_its_curvature_is_read_from_its_faces() {
    let (n, c) = (40u32, 4.0f32);
    let at = |i: u32, j: u32| i * (n + 1) + j;
    let vertices: Vec<Vec3> = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| (i, j)))
        .map(|(i, j)| {
            let (x, z) = (i as f32 / n as f32 - 0.5, j as f32 / n as f32 - 0.5);
            Vec3::new(x, 0.5 * c * (x * x + z * z), z)
        })
        .collect();
    let triangles: Vec<[u32; 3]> = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .flat_map(|(i, j)| {
            let (a, b, d, e) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            [[a, d, b], [a, e, d]]
        })
        .collect();
    let surface = Surface::new(vertices, triangles);
    let tips = surface.tips();
    // Its border is open (sharp): only the border's vertices are tips.
    assert_eq!(tips.len(), 4 * n as usize);
    let curvature = tips.curvature();
    assert!((0.8 * c..2.0 * c).contains(&curvature), "{curvature}");
    let mut middle = Vec::new();
    let near = Vec3::splat(0.05);
    tips.smooth_in_box(-near, near, |p, k| middle.push((p, k)));
    assert!(!middle.is_empty());
    for (p, k) in middle {
        assert!((0.8 * c..2.0 * c).contains(&k), "{k} at {p}");
    }
}

/// A face collapsed to a point (its three corners written at one place, as some exporters
/// write them) has no normal and says nothing: the flat sheet's middle vertex it lies on
/// stays smooth, and only the border's vertices are tips.
#[test]
fn a_face_collapsed_to_a_point_makes_no_tip() {
    let (mut v, mut t) = grid(4, 0.0);
    let (middle, k) = (v[12], v.len() as u32);
    assert_eq!(middle, Vec3::new(2.0, 0.0, 2.0));
    v.extend([middle; 3]);
    t.push([k, k + 1, k + 2]);
    assert_eq!(tips_of(v, t).len(), 16, "the border's vertices only");
}
