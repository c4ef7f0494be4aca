//! What the pass refuses: states that have blown up, before anything moves.

use super::*;

/// A state that has blown up is refused by the first particle whose position is not
/// finite (a NaN, an infinity, or two infinities of opposite signs, which a sum of the
/// motion would cancel into a NaN), and nothing is moved.
#[test]
fn a_position_that_is_not_finite_is_refused_by_its_first_particle() {
    let (model, start) = crumpled();
    let n = start.len();
    for (first, other, bad) in [
        (7, n - 1, [f32::NAN, f32::NAN]),
        (n / 2, n - 3, [f32::INFINITY, f32::INFINITY]),
        (3, n / 3, [f32::INFINITY, f32::NEG_INFINITY]),
        (n - 1, n - 1, [f32::NEG_INFINITY; 2]),
    ] {
        let mut state = ClothState::at_rest(&model);
        state.pos = start
            .iter()
            .map(|&p| p + Vec3::new(0.0, -0.002, 0.0))
            .collect();
        // Along one axis, so that two infinities of opposite signs meet in the sum.
        (state.pos[other].x, state.pos[first].x) = (bad[1], bad[0]);
        let before = position_bits(&state.pos);
        let refused = SelfContacts::default().resolve([THICKNESS, 0.3], &model, &start, &mut state);
        assert_eq!(
            refused,
            Err(ContactError::NonFinite { particle: first }),
            "{first}"
        );
        assert_eq!(position_bits(&state.pos), before, "nothing moved");
    }
}

/// The bits of `x`, to tell whether anything moved.
fn position_bits(x: &[Vec3]) -> Vec<[u32; 3]> {
    x.iter().map(|p| p.to_array().map(f32::to_bits)).collect()
}

/// Resolves the motion from `start` to `end` with the guard's strain `limit` set; returns
/// what the resolve gave and where it left the particles.
fn resolved_with(
    model: &ClothModel,
    [start, end]: [&[Vec3]; 2],
    limit: Option<f32>,
) -> (Result<usize, ContactError>, Vec<Vec3>) {
    let mut contacts = SelfContacts {
        strain_limit: limit,
        ..SelfContacts::default()
    };
    let mut state = ClothState::at_rest(model);
    state.pos = end.to_vec();
    let result = contacts.resolve([THICKNESS, 0.3], model, start, &mut state);
    (result, state.pos)
}

/// A state blown up within a frame: a 12 × 12-quad cloth of 1 cm quads balled into a
/// 1.5 cm cube (hundreds of pairs a particle, where cloth in contact has a few), one
/// particle flung 5 cm from it so that its springs stretch past 200 %. Against the guard's
/// strain limit it is refused, its stretch and pairs named, before anything moves; with
/// the limit above the stretch, or none set, it is resolved. The same stretch on a cloth
/// that finds few pairs is left to the frame's end: resolved.
#[test]
fn a_state_with_many_pairs_and_a_spring_past_the_guards_limit_is_refused() {
    let (model, _) = grid(12, 0.12);
    let n = model.particle_count();
    let mut rnd = crate::test_rng::uniform(3);
    let start: Vec<Vec3> = (0..n)
        .map(|_| Vec3::new(rnd(), rnd(), rnd()) * 0.015)
        .collect();
    let mut end: Vec<Vec3> = start.iter().map(|&p| p + Vec3::Y * 1e-4).collect();
    end[n / 2] += Vec3::new(0.05, 0.0, 0.0);
    let strain = model.springs.largest_strain(&end);
    assert!(strain > 2.0, "{strain}");
    let (refused, pos) = resolved_with(&model, [&start, &end], Some(1.0));
    match refused {
        Err(ContactError::Stretched {
            strain: named,
            limit,
            pairs,
            particles,
        }) => {
            assert_eq!((named, limit, particles), (strain, 1.0, n));
            assert!(pairs > SUSPECT_PAIRS * n, "{pairs} pairs");
        }
        other => panic!("not refused: {other:?}"),
    }
    assert_eq!(position_bits(&pos), position_bits(&end), "nothing moved");
    for limit in [Some(strain * 1.01), None] {
        let (result, pos) = resolved_with(&model, [&start, &end], limit);
        assert!(result.is_ok(), "{limit:?}: {result:?}");
        assert!(pos.iter().all(|p| p.is_finite()));
    }
    // 4 cm quads: no pair within the thickness but the flung particle's.
    let (model, flat) = grid(12, 0.48);
    let mut end = flat.clone();
    end[n / 2] += Vec3::new(0.0, 0.0, 0.2);
    assert!(model.springs.largest_strain(&end) > 2.0);
    let (result, _) = resolved_with(&model, [&flat, &end], Some(1.0));
    assert!(result.is_ok(), "{result:?}");
}
