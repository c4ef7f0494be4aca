//! Refreshes that would go on for ever: where a few particles leave their boxes every
//! substep, the whole tree is searched again once the refreshes since the last whole
//! search have cost as much as it did.

use super::*;

/// Two particles (far apart) of a 24 × 24-quad cloth lying flat, set down 0.4 of the
/// thickness at each of 60 substeps and staying there: slow, so the pairs are judged by
/// the boxes, and each of those two leaves its box (a quarter of the thickness of room)
/// once. Every substep takes a refresh or a whole search; a refresh only while the
/// refreshes since the last whole search have cost less than it did (counted in
/// triangles and the pairs of triangles tested, a triangle refreshed as twelve searched
/// whole), and a whole search as soon as they have cost as much: four of them here,
/// after 10, 13, 12 and 12 refreshes, and 9 refreshes after the last.
#[test]
fn refreshes_that_go_on_give_way_to_a_whole_search_now_and_then() {
    let (model, flat) = grid(24, 1.0);
    let n = flat.len();
    // Particle `i` is set down at substep `i / 2 + 1` of a walk through the cloth in
    // strides of 97 particles (coprime with its 625).
    let moved_at = |i: usize| (i * 97 % n) / 2 + 1;
    let at = |k: usize| -> Vec<Vec3> {
        (flat.iter().enumerate())
            .map(|(i, &p)| {
                p - Vec3::Y
                    * if moved_at(i) <= k {
                        0.4 * THICKNESS
                    } else {
                        0.0
                    }
            })
            .collect()
    };
    let mut contacts = searched_to(&model, &at(0), &at(0));
    let mut runs = Vec::new();
    let mut refreshes = 0;
    for k in 1..=60 {
        let (before, work) = (contacts.costs, contacts.work);
        let (from, to) = (at(k - 1), at(k));
        let moved = Moved::plain(&from, &to);
        contacts
            .update_pairs(&model, THICKNESS, THICKNESS, Some(moved))
            .unwrap();
        assert!(!contacts.boxes.swept, "substep {k}");
        let (searched, refreshed) = (
            contacts.work.searches - work.searches,
            contacts.work.refreshes - work.refreshes,
        );
        assert_eq!(searched + refreshed, 1, "substep {k}");
        // Each is taken by what the refreshes since the last whole search cost.
        let due = before.whole_due();
        assert_eq!(searched == 1, due, "substep {k}: {before:?}");
        if searched == 1 {
            runs.push(std::mem::take(&mut refreshes));
        } else {
            refreshes += 1;
        }
    }
    assert_eq!((runs, refreshes), (vec![10, 13, 12, 12], 9));
}

/// Where a few particles move fast (in the frame that moves with the cloth) and the rest
/// keep still, refreshing those few every substep costs less than whole searches by the
/// motion every other substep: the pairs are judged by the boxes. Where many do, by the
/// motion. A 24 × 24-quad cloth lying flat (1 152 triangles), 2 and then 40 of its
/// particles moving two thicknesses a substep (each refreshed as its six triangles, four
/// times over: 576 and 11 520 against the triangles), judged alike by its first search and
/// a later one.
#[test]
fn a_few_fast_particles_leave_the_pairs_judged_by_the_boxes() {
    let (model, flat) = grid(24, 1.0);
    let n = flat.len();
    for (fast, swept) in [(2, false), (40, true)] {
        let end: Vec<Vec3> = (flat.iter().enumerate())
            .map(|(i, &p)| {
                let moves = (0..fast).any(|k| k * 97 % n == i);
                p + Vec3::Y * if moves { 2.0 * THICKNESS } else { 0.0 }
            })
            .collect();
        let mut contacts = searched_to(&model, &flat, &end);
        assert_eq!(contacts.boxes.swept, swept, "{fast}: the first search");
        // The next substep searches the whole tree again.
        contacts.found_for = None;
        let moved = Moved::plain(&flat, &end);
        contacts
            .update_pairs(&model, THICKNESS, THICKNESS, Some(moved))
            .unwrap();
        assert_eq!(contacts.work.searches, 2);
        assert_eq!(contacts.boxes.swept, swept, "{fast}");
    }
}
