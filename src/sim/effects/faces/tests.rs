//! The patches: a face pass takes every triangle a solid could touch, each once, in
//! colour order, and few besides.

use glam::Vec3;

use super::*;
use crate::mesh::{GridOrientation, GridSpec};

/// A `quads`² cloth 1 m wide, folded over along its middle and crumpled by random offsets
/// of up to 2 cm.
fn folded(quads: u32) -> (ClothModel, Vec<Vec3>) {
    let mesh = GridSpec::square(quads, 1.0, GridOrientation::Horizontal, Vec3::ZERO)
        .build()
        .unwrap();
    let model = ClothModel::new(&mesh, 0.2, &[]);
    let mut rnd = crate::test_rng::uniform(11);
    let mut jitter = || Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 0.04;
    let pos = (mesh.positions.iter())
        .map(|&p| {
            let p = if p.x > 0.0 {
                Vec3::new(-p.x, p.y + 0.05, p.z)
            } else {
                p
            };
            p + jitter()
        })
        .collect();
    (model, pos)
}

/// Whether the box `lo..hi` comes within `r` of `c`.
fn within(c: Vec3, r: f32) -> impl Fn(Vec3, Vec3) -> bool {
    move |lo, hi| c.clamp(lo, hi).distance(c) < r
}

#[test]
fn a_face_pass_takes_every_triangle_a_ball_reaches_once_in_order_and_few_besides() {
    let (model, pos) = folded(24);
    let mut patches = FacePatches::default();
    // Every patch taken: every triangle, once, colour after colour (those of a colour
    // share no particle).
    let all = patches.near(&model, &pos, |_, _| true).to_vec();
    let (order, runs) = colour_greedily(model.particle_count(), model.triangles.iter().copied());
    assert_eq!(all, order);
    for (run, _) in &runs {
        let mut seen = std::collections::HashSet::new();
        let corners = order[run.clone()]
            .iter()
            .flat_map(|&t| model.triangles[t as usize]);
        assert!(
            corners.into_iter().all(|i| seen.insert(i)),
            "a colour shares a particle"
        );
    }
    let rank = |t: u32| order.iter().position(|&u| u == t).unwrap_or(usize::MAX);
    // Balls of a few cells, and one just around each particle (a corner a patch left out
    // shows there). The first takes more triangles than are sorted, the second fewer.
    let balls = [(Vec3::new(-0.2, 0.02, 0.1), 0.08), (pos[300], 0.03)]
        .into_iter()
        .chain(pos.iter().map(|&p| (p, 1e-4)));
    for (k, (c, r)) in balls.enumerate() {
        let taken = patches.near(&model, &pos, within(c, r)).to_vec();
        let many = taken.len() * SORTED_BELOW >= model.triangles.len();
        assert!(k > 1 || many == (k == 0), "ball {k}: {} taken", taken.len());
        assert!(
            taken.windows(2).all(|w| rank(w[0]) < rank(w[1])),
            "in colour order, each once"
        );
        // Every triangle whose corners' box the ball reaches.
        let reached: Vec<u32> = (0..model.triangles.len() as u32)
            .filter(|&t| {
                let x = model.triangles[t as usize].map(|i| pos[i as usize]);
                within(c, r)(x[0].min(x[1]).min(x[2]), x[0].max(x[1]).max(x[2]))
            })
            .collect();
        assert!(!reached.is_empty());
        let missed: Vec<_> = reached.iter().filter(|t| !taken.contains(t)).collect();
        assert!(missed.is_empty(), "passed by {missed:?}");
        // Patches are pieces of cloth that stay together: a ball a few cells across takes
        // the patches around the triangles it reaches, not the cloth.
        assert!(
            taken.len() <= 3 * reached.len() + 4 * PATCH && 4 * taken.len() < model.triangles.len(),
            "{} taken for {} reached of {}",
            taken.len(),
            reached.len(),
            model.triangles.len()
        );
    }
}

/// Prepared once for a cloth (a stepper's setup cuts them, and the face passes after find
/// them cut), and again for another.
#[test]
fn patches_are_cut_again_for_another_cloth() {
    let mut patches = FacePatches::default();
    for quads in [6, 24, 3] {
        let (model, pos) = folded(quads);
        assert!(patches.prepare(&model), "{quads}");
        assert!(!patches.prepare(&model), "{quads}");
        let mut all = patches.near(&model, &pos, |_, _| true).to_vec();
        all.sort_unstable();
        assert_eq!(all, (0..model.triangles.len() as u32).collect::<Vec<_>>());
    }
}
