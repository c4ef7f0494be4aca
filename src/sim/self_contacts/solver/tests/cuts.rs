//! What a cut leaves of a particle's velocity: the share of it that the particle keeps of
//! its motion. A substep's motion can hold moves that are no velocity (the pushes', which
//! carry their impulses in the velocity already); made one, a push's depth became speed
//! each substep where a stack lies pressed together, and the stack buzzed.

use super::*;

/// Two 4 × 4-quad sheets 20 cm wide, 3 cm apart (particles 0–24 below, 25–49 above): the
/// upper sheet moves 5 cm down in one substep, through the lower one, to 2 cm below it (no
/// pair within the thickness there, so nothing is pushed), at `speed` m/s (its motion over
/// a 240th of a second, or none). Returns where its middle particle's motion was cut to,
/// as a share, and its velocity after.
fn middle_cut(speed: f32) -> (f32, Vec3) {
    let (model, start) = two_sheets(0.03, false);
    let middle = 25 + 12;
    let mut state = ClothState::at_rest(&model);
    for i in 25..50 {
        state.pos[i].y -= 0.05;
        state.vel[i] = Vec3::new(0.0, -speed, 0.0);
    }
    let mut contacts = SelfContacts::default();
    (contacts.resolve([THICKNESS, 0.3], &model, &start, &mut state)).unwrap();
    let work = contacts.work;
    assert!(work.contacts == 0 && work.impacts > 0, "{work:?}");
    let share = (start[middle].y - state.pos[middle].y) / 0.05;
    (share, state.vel[middle])
}

/// Moved through the other sheet with no velocity (as a push moves a particle), the sheet
/// is cut short of it and keeps no velocity: the average velocity of what it kept of its
/// motion would be some 7 m/s down.
#[test]
fn a_cut_gives_no_velocity_to_a_move_that_had_none() {
    let (share, vel) = middle_cut(0.0);
    assert!((0.3..0.7).contains(&share), "{share}");
    assert_eq!(vel, Vec3::ZERO);
}

/// Moving at the velocity of its motion (12 m/s down), the particle cut to a share of its
/// motion keeps that share of its velocity.
#[test]
fn a_cut_particle_keeps_the_share_of_its_velocity_that_it_keeps_of_its_motion() {
    let speed = 0.05 * 240.0;
    let (share, vel) = middle_cut(speed);
    assert!((0.3..0.7).contains(&share), "{share}");
    let kept = Vec3::new(0.0, -speed * share, 0.0);
    assert!((vel - kept).length() < 1e-4 * speed, "{vel} against {kept}");
}
