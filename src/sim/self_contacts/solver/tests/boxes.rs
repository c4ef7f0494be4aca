//! Where the pairs are judged by the boxes, the patches certified for every place the boxes
//! allow: none of their pairs comes within the thickness anywhere in the particles'
//! rooms, and a refresh searches the corners of the particles that left theirs again.

use super::*;

/// The thickness here: half the rest gap of a grid 2 cm between particles (1.41 cm, half
/// its diagonal).
const T: f32 = 0.007;

/// A flat `quads`² cloth 2 cm between particles in the xz plane, and its particles.
fn flat(quads: u32) -> (ClothModel, Vec<Vec3>) {
    grid(quads, 0.02 * quads as f32)
}

/// Checks the particles' motion from `start` to `end` against the pairs `contacts` holds
/// for thickness [`T`], finding them (again) where it must.
fn step(contacts: &mut SelfContacts, model: &ClothModel, start: &[Vec3], end: &[Vec3]) {
    contacts.prepare(model).unwrap();
    let moved = Moved::plain(start, end);
    contacts.update_pairs(model, T, T, Some(moved)).unwrap();
}

/// A solver with the pairs found, for thickness [`T`], for the motion from `start` to
/// `end`.
fn searched_for(model: &ClothModel, start: &[Vec3], end: &[Vec3]) -> SelfContacts {
    let mut contacts = SelfContacts::default();
    step(&mut contacts, model, start, end);
    contacts
}

/// How many corners are closed.
fn closed(contacts: &SelfContacts) -> usize {
    contacts.certificates.open.iter().filter(|&&o| !o).count()
}

/// Every pair of the cloth: of each two triangles that share no corner, and each corner's.
fn every_pair(contacts: &SelfContacts, triangles: &[[u32; 3]]) -> Vec<(Pair, StoredPair)> {
    let mut pairs = Vec::new();
    for a in 0..triangles.len() {
        for b in a + 1..triangles.len() {
            if !triangles[a].iter().any(|i| triangles[b].contains(i)) {
                (contacts.owners).each_pair(triangles, a, b, |p, s| pairs.push((p, s)));
            }
        }
    }
    let owners = &contacts.owners;
    for &stored in &owners.neighbours {
        pairs.push((stored.expand(triangles, &owners.edges), stored));
    }
    pairs
}

/// The pairs the certificates pass by: those of two triangles a covered node holds, and
/// those of the corners left closed.
fn certified(contacts: &SelfContacts, triangles: &[[u32; 3]]) -> Vec<Pair> {
    let (tree, mut pairs) = (&contacts.tree, Vec::new());
    for (i, _) in
        (tree.nodes().iter().enumerate()).filter(|&(i, _)| tree.covered.get(i) == Some(&true))
    {
        let held = tree.held(i);
        for (k, &a) in held.iter().enumerate() {
            for &b in &held[k + 1..] {
                let (a, b) = (a as usize, b as usize);
                (contacts.owners).each_pair(triangles, a, b, |p, _| pairs.push(p));
            }
        }
    }
    let open = &contacts.certificates.open;
    for c in (0..open.len()).filter(|&c| !open[c]) {
        for &stored in contacts.owners.corner_pairs(c) {
            pairs.push(stored.expand(triangles, &contacts.owners.edges));
        }
    }
    pairs
}

/// The least distance between the sides of any of `pairs` with each particle put at the
/// corner of its room (its box less half the thickness, where its motion must keep for the
/// pairs to hold) towards the middle of the other side's rooms.
fn least_in_rooms(contacts: &SelfContacts, pairs: &[Pair]) -> f64 {
    let (lo, hi) = (&contacts.boxes.vertex_lo, &contacts.boxes.vertex_hi);
    let half = Vec3::splat(0.5 * T);
    let room = |i: usize| (lo[i] + half, hi[i] - half);
    let middle = |i: usize| 0.5 * (room(i).0 + room(i).1);
    let mut least = f64::INFINITY;
    for pair in pairs {
        let (ids, s) = (pair.ids(), pair.first_side());
        let side = |r: std::ops::Range<usize>| {
            let n = r.len() as f32;
            r.map(|k| middle(ids[k])).sum::<Vec3>() / n
        };
        let (a, b) = (side(0..s), side(s..4));
        let x = std::array::from_fn(|k| {
            let ((lo, hi), towards) = (room(ids[k]), if k < s { b } else { a });
            Vec3::select(towards.cmpgt(middle(ids[k])), hi, lo).as_dvec3()
        });
        least = least.min(distance(pair, x));
    }
    least
}

/// Still, each particle's room is a quarter of the thickness each way: the patches of a
/// flat 8 × 8-quad cloth are covered and the corners they hold closed, and none of their
/// pairs comes within the thickness anywhere in the rooms. Moving as a whole 3 mm a
/// substep along a diagonal (slow: judged by the boxes), each room runs a thickness ahead
/// of its motion, so two particles of a patch may close by more than the rest gap leaves
/// (some pair of the cloth comes within the thickness in the rooms): nothing is covered,
/// though the patches keep their shape. With the rooms left out of the certificate's
/// reach, the moving patches are covered and a pair of theirs can touch in the rooms.
#[test]
fn patches_covered_for_the_boxes_keep_their_pairs_apart_anywhere_in_them() {
    let (model, rest) = flat(8);
    let triangles = &model.triangles;
    let still = searched_for(&model, &rest, &rest);
    assert!(!still.boxes.swept);
    let (pairs, closed) = (certified(&still, triangles), closed(&still));
    assert!(
        pairs.len() > 5000 && closed > 40,
        "{} pairs, {closed} corners",
        pairs.len()
    );
    let least = least_in_rooms(&still, &pairs);
    assert!(least >= f64::from(T), "still: a certified pair at {least}");

    let along = Vec3::new(1.0, 0.0, 1.0).normalize() * 0.003;
    let end: Vec<Vec3> = rest.iter().map(|&p| p + along).collect();
    let moving = searched_for(&model, &rest, &end);
    assert!(!moving.boxes.swept);
    let every: Vec<Pair> = (every_pair(&moving, triangles).into_iter())
        .map(|(p, _)| p)
        .collect();
    let near = least_in_rooms(&moving, &every);
    assert!(
        near < f64::from(T),
        "the rooms keep every pair {near} apart"
    );
    let pairs = certified(&moving, triangles);
    let least = least_in_rooms(&moving, &pairs);
    assert!(least >= f64::from(T), "moving: a certified pair at {least}");
}

/// A refresh searches again the corners of the particles that left their boxes, though
/// a covered patch closed them: one particle of the still cloth of
/// [`patches_covered_for_the_boxes_keep_their_pairs_apart_anywhere_in_them`] slides along
/// the cloth 3 mm a substep for five substeps, to 5 mm from its neighbour (whose other
/// triangles it then meets); at every substep each pair that comes within the thickness
/// at the substep's end is among the pairs held. With the corners left closed, the pairs
/// of the neighbour's triangles with the particle's are missed.
#[test]
fn a_refresh_by_the_boxes_searches_the_corners_that_left_them() {
    let (model, rest) = flat(8);
    let triangles = &model.triangles;
    let mut contacts = searched_for(&model, &rest, &rest);
    let moved = 4 * 9 + 4;
    let closed = closed(&contacts);
    assert!(
        !contacts.certificates.open[moved + 1],
        "{closed} corners closed"
    );
    let mut pos = rest.clone();
    let mut near_total = 0;
    for _ in 0..5 {
        let start = pos.clone();
        pos[moved].x += 0.003;
        step(&mut contacts, &model, &start, &pos);
        assert!(!contacts.boxes.swept);
        let held = sorted(contacts.found.stored().copied().collect());
        for (pair, stored) in every_pair(&contacts, triangles) {
            let x = pair.ids().map(|i| pos[i].as_dvec3());
            if distance(&pair, x) < f64::from(T) {
                near_total += 1;
                let stored = stored.canonical();
                assert!(held.binary_search(&stored).is_ok(), "{pair:?} missed");
            }
        }
    }
    assert!(near_total > 5, "{near_total} pairs came near");
    assert!(contacts.work.refreshes > 0, "{:?}", contacts.work);
}
