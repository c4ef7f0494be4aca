//! The recheck after the solids: where the check before it cut nothing and the pairs are
//! the same, only the pairs of the particles the solids moved are checked again, with the
//! same result as checking every pair.

use super::*;
use crate::sim::intersections::self_intersections;

/// Two 4 × 4-quad sheets 20 cm wide, 3 cm apart (particles 0–24 below, 25–49 above), and
/// a solver and state after one substep in which every particle sank 1 mm (no pair near:
/// nothing pushed, nothing cut).
fn two_sheets_resolved() -> (ClothModel, Vec<Vec3>, ClothState, SelfContacts) {
    let (model, start) = two_sheets(0.03, false);
    let mut state = ClothState::at_rest(&model);
    state.pos.iter_mut().for_each(|p| p.y -= 0.001);
    let mut contacts = SelfContacts::default();
    (contacts.resolve([THICKNESS, 0.3], &model, &start, &mut state)).unwrap();
    assert_eq!((contacts.work.contacts, contacts.work.impacts), (0, 0));
    (model, start, state, contacts)
}

/// A solid moves the lower sheet's middle particle 6 cm up after self-contact, through the
/// upper sheet: the recheck finds the pairs of its new motion and cuts it where it would
/// pass through; no triangle crosses another.
#[test]
fn the_recheck_cuts_a_particle_a_solid_moved_through_the_cloth() {
    let (model, start, mut state, mut contacts) = two_sheets_resolved();
    let placed = state.pos.clone();
    state.pos[12].y = 0.06;
    let cut = (contacts.settle(THICKNESS, &model, [&start, &placed], &mut state)).unwrap();
    assert!(cut > 0);
    assert!(
        state.pos[12].y < 0.03 - 0.1 * THICKNESS,
        "{}",
        state.pos[12]
    );
    assert_eq!(self_intersections(&model.triangles, &state.pos), 0);
}

/// Where a recheck is narrowed to the particles the solids moved, their pairs are checked:
/// two pinned sheets 2.5 mm apart (nothing to push or cut: the check before the solids
/// cut nothing), and a solid lifting one particle of the lower sheet 2 mm, within its box
/// (the pairs hold), to 0.5 mm from the upper: its pairs come within what the check keeps
/// (1 mm), and, nothing in them free to cut, they are counted forced, as checking every
/// pair counts them.
#[test]
fn a_narrowed_recheck_checks_the_pairs_of_what_the_solids_moved() {
    let (model, start) = two_sheets(0.25 * THICKNESS, true);
    let recheck = |every_pair: bool| {
        let mut state = ClothState::at_rest(&model);
        let mut contacts = SelfContacts::default();
        (contacts.resolve([THICKNESS, 0.3], &model, &start, &mut state)).unwrap();
        assert!(contacts.cuts_whole && contacts.found.len() > 0);
        let placed = state.pos.clone();
        state.pos[12].y += 0.2 * THICKNESS;
        RECHECK_EVERY_PAIR.set(every_pair);
        NARROWED.set(0);
        let cut = (contacts.settle(THICKNESS, &model, [&start, &placed], &mut state)).unwrap();
        RECHECK_EVERY_PAIR.set(false);
        (cut, contacts.work.forced, NARROWED.get())
    };
    let (narrowed, every) = (recheck(false), recheck(true));
    assert_eq!((narrowed.2, every.2), (1, 0));
    assert!(narrowed.0 > 0 && narrowed.1 > 0, "{narrowed:?}");
    assert_eq!((narrowed.0, narrowed.1), (every.0, every.1));
}

/// The recheck narrowed to the particles the solids moved cuts what checking every pair
/// cuts, to the bit: `layers` at 8² quads (its sphere pressing the stack every substep)
/// over its first second, run narrowed and run checking every pair, ends in the same
/// positions and velocities; most of its rechecks were narrowed.
#[test]
fn the_recheck_of_the_moved_particles_cuts_what_checking_every_pair_cuts() {
    let run = |every_pair: bool| {
        RECHECK_EVERY_PAIR.set(every_pair);
        NARROWED.set(0);
        let scene = crate::scene::Scene::open_resized("layers", None, &Default::default(), Some(8));
        let mut sim = crate::scene::Simulation::new(scene.unwrap());
        for _ in 0..180 {
            sim.step_frame().unwrap();
        }
        RECHECK_EVERY_PAIR.set(false);
        let s = sim.state();
        let bits: Vec<u32> = (s.pos.iter().chain(&s.vel))
            .flat_map(|v| v.to_array().map(f32::to_bits))
            .collect();
        (bits, NARROWED.get())
    };
    let (narrowed, every) = (run(false), run(true));
    assert_eq!(every.1, 0);
    assert!(narrowed.1 > 100, "{} rechecks narrowed", narrowed.1);
    assert!(
        narrowed.0 == every.0,
        "the narrowed rechecks ended elsewhere"
    );
}
