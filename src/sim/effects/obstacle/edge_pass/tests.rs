use glam::Vec3;

use super::*;
use crate::cloth::{ClothModel, ClothState};
use crate::mesh::{GridOrientation, GridSpec};
use crate::sim::obstacle::Tips;
use crate::sim::self_contacts::SelfContacts;

/// The twelve sharp edges of a 20 cm cube about the origin, raised by `lift` m.
fn cube_edges(lift: f32) -> SharpEdges {
    let (v, t, normals) = crate::sim::obstacle::unit_cube();
    let v: Vec<Vec3> = (v.iter())
        .map(|&c| (c - Vec3::splat(0.5)) * 0.2 + Vec3::Y * lift)
        .collect();
    SharpEdges::of(&v, &t, &normals)
}

/// A 60 cm cloth of 32 × 32 quads at rest (1 089 particles, which the team takes into the
/// frame), lying flat `above` m over the cube's top.
fn cloth_over_cube(above: f32) -> (ClothModel, ClothState) {
    let mesh = GridSpec::square(32, 0.6, GridOrientation::Horizontal, Vec3::ZERO)
        .build()
        .unwrap();
    let model = ClothModel::new(&mesh, 0.2, &[]);
    let mut state = ClothState::at_rest(&model);
    state.pos.iter_mut().for_each(|p| p.y += 0.1 + above);
    (model, state)
}

/// Moves every particle of `pos` by up to a quarter of a millimetre each way (drawn from
/// `rnd`), and those beyond the cube's top (fully from 5 cm out) 2 mm down and `swing` m
/// outwards along x.
fn drift(pos: &mut [Vec3], rnd: &mut impl FnMut() -> f32, swing: f32) {
    for p in pos {
        let beyond = (p.x.abs().max(p.z.abs()) - 0.1).max(0.0);
        let jitter = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 0.0005;
        let swing = Vec3::X * p.x.signum() * swing;
        *p += jitter + (swing - Vec3::Y * 0.002) * (beyond * 20.0).min(1.0);
    }
}

/// One edge pass of `model` from `start` to `state` (the substep's end) against `edges`
/// fixed in the world, with a thickness of 1 cm; returns the cloth edges it moved.
fn pass(
    edges: &SharpEdges,
    model: &ClothModel,
    start: &[Vec3],
    state: &mut ClothState,
    (memory, moved): (&mut EdgeMemory, EdgesMoved),
) -> usize {
    let mut self_contacts = SelfContacts::default();
    let mut pass = ContactPass {
        model,
        start,
        substep: 0.01,
        state,
        offset: 0.01,
        self_contacts: &mut self_contacts,
        faces: None,
    };
    let frame = EdgeFrame {
        from_start: |p| p,
        to_local: |p| p,
        to_world: |n| n,
        velocity: |_| Vec3::ZERO,
    };
    push_edges(
        (edges, &Tips::default()),
        &frame,
        0.3,
        &mut pass,
        (memory, moved),
    )
}

/// A 60 cm cloth 8 mm over a 20 cm cube's top, its parts beyond the top falling and swinging
/// past the rim, every particle jittering; now and then a substep moves nothing, and one
/// jumps back to where the cloth was some substeps before (as a rolled-back frame does).
/// Each substep's edge pass with the memory kept from substep to substep (clearances and
/// odometers: most cloth edges passed by unasked) must leave every position and velocity
/// as a pass with no memory at all (every cloth edge asked, every tree walked) leaves them,
/// to the bit; and so must they where the cube rises into a still cloth from 3 cm below
/// it (as a deforming surface's edges move: every cloth edge asked, the clearances worn
/// down by the move). The remembering pass on one thread and on a team of two (whose
/// colours of more than 256 cloth edges are shared out) asks as many cloth edges and ends
/// in the same bits, and the pass with no memory asks every cloth edge in every sweep.
/// (With the last edge of each piece of a colour left out, red.)
#[test]
fn cloth_edges_passed_by_on_their_odometers_end_where_every_one_asked_ends() {
    let on = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool")
    };
    let (alone, team) = (on(1), on(2));
    // Fixed under a moving cloth 8 mm above its top, or rising 1 mm a substep (as a
    // deforming surface's edges move) into a still one 3 cm above it.
    for (moved, rise, above) in [
        (EdgesMoved::Fixed, 0.0, 0.008),
        (EdgesMoved::By(1e-3), 1e-3, 0.03),
    ] {
        let mut rnd = crate::test_rng::uniform(33);
        let (model, mut state) = cloth_over_cube(above);
        let (mut memory, mut shared_memory) = (EdgeMemory::default(), EdgeMemory::default());
        let (mut asked_fresh, mut pushes, mut earlier) = (0, 0, Vec::new());
        for substep in 0..160 {
            let start = state.pos.clone();
            if substep % 40 == 39 {
                // Back to where the cloth was ten substeps before.
                state.pos.clone_from(&earlier[substep - 10]);
            } else if substep % 13 != 12 && rise == 0.0 {
                drift(
                    &mut state.pos,
                    &mut rnd,
                    0.001 * (0.1 * substep as f32).sin(),
                );
            }
            earlier.push(state.pos.clone());
            let edges = cube_edges(rise * substep as f32);
            let mut fresh = state.clone();
            let mut none = EdgeMemory::default();
            let expected = pass(&edges, &model, &start, &mut fresh, (&mut none, moved));
            let mut shared = state.clone();
            let got =
                alone.install(|| pass(&edges, &model, &start, &mut state, (&mut memory, moved)));
            let twin = (&mut shared_memory, moved);
            let by_two = team.install(|| pass(&edges, &model, &start, &mut shared, twin));
            assert_eq!(by_two, got, "{moved:?}, substep {substep}: shared");
            assert_eq!(
                got, expected,
                "{moved:?}, substep {substep}: cloth edges moved"
            );
            let bits = |s: &ClothState| {
                (s.pos.iter().chain(&s.vel))
                    .flat_map(|v| v.to_array().map(f32::to_bits))
                    .collect::<Vec<_>>()
            };
            assert!(
                bits(&state) == bits(&fresh),
                "{moved:?}, substep {substep}: states differ"
            );
            assert!(
                bits(&shared) == bits(&state),
                "{moved:?}, substep {substep}: shared, the states differ"
            );
            // With no memory, every sweep asks every cloth edge: none left out of a colour
            // however it is cut.
            let edges_of_cloth = model.edge_colours.order.len();
            assert!(
                none.asked >= edges_of_cloth && none.asked % edges_of_cloth == 0,
                "{moved:?}, substep {substep}: {} asked of {edges_of_cloth}",
                none.asked
            );
            asked_fresh += none.asked;
            pushes += got;
        }
        // Not a test that could pass by asking every cloth edge, or by pushing none: where
        // the edges are fixed, most are passed by; where they move, none is.
        assert_eq!(
            shared_memory.asked, memory.asked,
            "{moved:?}: shared, asked"
        );
        let asked = match moved {
            EdgesMoved::Fixed => 2 * memory.asked < asked_fresh,
            EdgesMoved::By(_) => memory.asked == asked_fresh,
        };
        assert!(
            asked && pushes > 500,
            "{moved:?}: {} asked of {asked_fresh}, {pushes} pushes",
            memory.asked
        );
    }
}

/// A memory another cloth of as many particles and edges took on (here the same cloth with
/// its edges taken in the other order: each place in the order another edge) answers for
/// each cloth edge only from what it kept for those two particles: every pass ends where a
/// pass with no memory ends, to the bit.
#[test]
fn a_memory_kept_for_other_edges_passes_none_of_these_by() {
    let (model, mut state) = cloth_over_cube(0.008);
    let mut reversed = model.clone();
    reversed.edge_colours.order.reverse();
    reversed.edge_colours.ends.reverse();
    let edges = cube_edges(0.0);
    let mut memory = EdgeMemory::default();
    let mut rnd = crate::test_rng::uniform(34);
    for (substep, model) in [&model; 4].into_iter().chain([&reversed; 4]).enumerate() {
        let start = state.pos.clone();
        drift(&mut state.pos, &mut rnd, 0.0);
        let mut fresh = state.clone();
        let fixed = EdgesMoved::Fixed;
        let expected = pass(
            &edges,
            model,
            &start,
            &mut fresh,
            (&mut EdgeMemory::default(), fixed),
        );
        let got = pass(&edges, model, &start, &mut state, (&mut memory, fixed));
        assert_eq!(
            (got, &state.pos, &state.vel),
            (expected, &fresh.pos, &fresh.vel),
            "{substep}"
        );
    }
}

/// Taking a cloth of 1 089 particles into the frame on a team of two (shared out in
/// pieces): every particle's place is where it now is, its odometer has run on by its
/// move's components added up and the room for the rounding, and the reading's travel is
/// the farthest any moved since the substep began, as one loop over them all gives them.
/// (With the last particle of each piece left out, red.)
#[test]
fn taking_the_cloth_in_moves_every_particles_place_and_odometer() {
    let (model, state) = cloth_over_cube(0.0);
    let count = model.particle_count();
    let mut rnd = crate::test_rng::uniform(35);
    let mut moved = state.pos.clone();
    drift(&mut moved, &mut rnd, 0.01);
    let team = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("a pool");
    let mut memory = EdgeMemory::default();
    memory
        .before
        .extend(state.pos.iter().map(|&p| Vec3A::from(p)));
    let edges = model.edge_colours.order.len();
    team.install(|| memory.take_in(&state.pos, |p| p, edges, true));
    assert!(memory.odometers.iter().all(|&o| o > 0.0 && o < 1e-6));
    let last: Vec<f64> = memory.odometers.clone();
    let reading = team
        .install(|| memory.take_in(&moved, |p| p, edges, true))
        .expect("a reading");
    let mut farthest = 0.0f32;
    for i in 0..count {
        let (now, was) = (Vec3A::from(moved[i]), Vec3A::from(state.pos[i]));
        assert_eq!(memory.local[i], now, "particle {i}");
        let run = f64::from((now - was).abs().element_sum());
        let odometer = last[i] + run + f64::from(reading.rounding);
        assert_eq!(memory.odometers[i], odometer, "particle {i}");
        farthest = farthest.max(now.distance_squared(memory.before[i]));
    }
    assert_eq!(reading.travel, farthest.sqrt() + reading.rounding);
}
