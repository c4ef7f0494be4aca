//! Patches certified apart by the cloth's shape at rest. Where the cloth lands, a search
//! spends most of its time proving what is plain to see: that a smooth patch does not
//! touch itself. The tree's nodes of [`SMALLEST`]–[`TRIANGLES_PER_PIECE`] triangles are
//! patches that stay together however the cloth folds; at rest no two sides of a pair of
//! the cloth are closer than its rest gap (measured once per cloth, up to its longest
//! edge). A linear map of the rest shape, carried anywhere, shrinks no distance by more
//! than the least it stretches any direction (`σ`), and a pair's distance differs from its
//! distance so mapped by at most twice the farthest its particles are from where the map
//! puts them. So while every particle of a patch stays within `(σ·gap − reach)/2` of where
//! such a map of its rest offset, carried with the middle of the patch, puts it, no pair of
//! two of its triangles comes within the reach — those that share a corner included. Maps
//! are fitted to the starts and to the ends by least squares (any maps keep the bound;
//! fitted ones keep it tight), and along the motion the map runs from one to the other:
//! each particle's offset from its place is then linear in time, so a patch is certified
//! for the whole motion from its start and end, as the corners' certificates are
//! ([`super::certify`]); the map in between shrinks no distance by more than the middle
//! map's least stretch less half how far the map moves (Weyl's inequality), so a patch
//! that turns as a whole stays certified.
//!
//! Where the cloth lies flat at rest, a patch that is one convex region of its plane is
//! also certified by how far its triangles turn from the map, rather than how far its
//! particles stray from it ([`flat`]): a patch bent evenly keeps that one.
//!
//! A certified node is covered, and so is every node under it: a whole search walks past a
//! covered node against itself and leaves the corners whose ring a covered node holds
//! closed. A corner's ring is such a patch too. The certificates need no reference taken
//! again: the rest shape is the reference.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{Vec3, Vec3A};

use super::certify::{MARGIN, frame, shave};
use super::primitives::{Pair, boxes_apart_by, nearer};
use super::search::{NONE, Owners};
use super::tree::{TRIANGLES_PER_PIECE, TriangleTree};
use crate::parallel::{Disjoint, PARALLEL_ELEMENTS, Team};
use flat::Flat;

mod flat;

/// The cloth's triangles, and some of them by number (a patch's).
type Triangles<'a> = (&'a [[u32; 3]], &'a [u32]);

/// Triangles in the smallest node certified on its own (smaller ones are covered only
/// with a node above them: their walk is short, and their frames would turn on a few
/// particles).
const SMALLEST: u32 = 4;

/// A node's count of searches still to leave it out of ([`Patches::decide`]), in the low
/// bits of its backoff (the failures in a row above them).
const WAITING: u8 = 0x0f;

/// The patches of one cloth, from its rest shape.
#[derive(Clone, Debug, Default)]
pub(super) struct Patches {
    /// Each node's parent (the root its own).
    parent: Vec<u32>,
    /// Each node's entries, `start[i]..start[i + 1]` (none: it is not certified on its
    /// own).
    start: Vec<u32>,
    /// Each corner's ring's entries (the corner and its ring), `rings[c]..rings[c + 1]`
    /// (none: it has no pairs).
    rings: Vec<u32>,
    /// Each entry's particle, and its offset at rest from its patch's middle, in the
    /// patch's frame at rest.
    particle: Vec<u32>,
    reference: Vec<Vec3>,
    /// Each node's and each corner's ring's inverse second moments of its offsets in the
    /// frame's first two axes (`[xx, xy, yy]` of the inverse), which weigh the fit.
    inverse: Vec<[f32; 3]>,
    ring_inverse: Vec<[f32; 3]>,
    /// Each corner's smallest node holding every triangle around it ([`NONE`]: none of at
    /// most [`TRIANGLES_PER_PIECE`] triangles).
    home: Vec<u32>,
    /// The least distance at rest between the sides of a pair of the cloth, up to its
    /// longest edge, rounded down, m.
    gap: f32,
    /// The cloth's plane, where it lies flat at rest: then every patch's frame is the
    /// plane's, and a patch whose rest shape is convex is certified by its triangles'
    /// turns too ([`flat`]).
    flat: Option<Flat>,
    /// Whether each node's, and each corner's ring's, triangles make one convex region of
    /// the plane at rest (none where the cloth is not flat).
    convex: Vec<bool>,
    ring_convex: Vec<bool>,
}

impl Patches {
    /// The patches of the cloth of `triangles` whose `tree` is built from its `rest`
    /// positions, with its `owners` and the least distance at rest between the sides of
    /// the pairs of two triangles that share a corner (`corners`, measured with their
    /// certificates). Leaves the tree fitted to the rest shape and uncovered.
    pub(super) fn build(
        tree: &mut TriangleTree,
        triangles: &[[u32; 3]],
        rest: &[Vec3],
        (owners, corners): (&Owners, f32),
    ) -> Patches {
        let nodes = tree.nodes().to_vec();
        let all: Vec<u32> = (0..rest.len() as u32).collect();
        let plane = anchor(&all, rest).map(|j| rest[j as usize]);
        // Where the cloth is flat, its outline tells which patches are convex.
        let (flat, mut outline) = Flat::of(triangles, rest, plane, &owners.rings).unzip();
        let mut patches = Patches {
            parent: vec![0; nodes.len()],
            start: vec![0],
            gap: rest_gap(tree, triangles, rest, (owners, corners)),
            flat,
            ..Patches::default()
        };
        for (i, node) in nodes.iter().enumerate() {
            if node.second != 0 {
                patches.parent[i + 1] = i as u32;
                patches.parent[node.second as usize] = i as u32;
            }
        }
        // Each node's particles, each once: the stamp is the node that took it last.
        let mut stamp = vec![NONE; rest.len()];
        let mut held = Vec::new();
        for (i, node) in nodes.iter().enumerate() {
            held.clear();
            if (SMALLEST..=TRIANGLES_PER_PIECE).contains(&node.count) {
                for &t in tree.held(i) {
                    for j in triangles[t as usize] {
                        if std::mem::replace(&mut stamp[j as usize], i as u32) != i as u32 {
                            held.push(j);
                        }
                    }
                }
            }
            let inverse = patches.add(&held, rest);
            patches.inverse.push(inverse);
            patches.start.push(patches.particle.len() as u32);
            let convex = (outline.as_mut()).is_some_and(|o| {
                let (first, count) = (node.first, node.count);
                let holds = |t: u32| (first..first + count).contains(&tree.place(t));
                !held.is_empty() && o.convex(tree.held(i), triangles, holds)
            });
            patches.convex.push(convex);
        }
        patches.rings.push(patches.particle.len() as u32);
        for c in 0..rest.len() {
            held.clear();
            if !owners.corner_pairs(c).is_empty() {
                held.push(c as u32);
                held.extend_from_slice(&owners.rings.ring[owners.rings.range(c)]);
            }
            let inverse = patches.add(&held, rest);
            patches.ring_inverse.push(inverse);
            let around = owners.rings.triangles_of(c);
            let convex = (outline.as_mut()).is_some_and(|o| {
                let holds = |t: u32| around.contains(&t);
                !held.is_empty() && o.convex(around, triangles, holds)
            });
            patches.ring_convex.push(convex);
            patches.rings.push(patches.particle.len() as u32);
        }
        patches.home = homes(tree, &nodes, &patches.parent, triangles, rest.len());
        tree.covered.clear();
        // Grown entry by entry: kept at their size (about 15 MB at 256², up to twice that
        // with the room a growing vector leaves).
        patches.particle.shrink_to_fit();
        patches.reference.shrink_to_fit();
        patches
    }

    /// Covers the tree's nodes certified for the motion of each particle from `from` to
    /// `to`, with `reach` (see the module's notes). A node whose certificate failed is
    /// left uncovered, untested, for the next searches that `backoff` (one count a node,
    /// kept from search to search; zeros: test every node) counts out.
    pub(super) fn decide(
        &self,
        tree: &mut TriangleTree,
        triangles: &[[u32; 3]],
        [from, to]: [&[Vec3A]; 2],
        reach: f32,
        backoff: &mut Vec<u8>,
    ) {
        let least = reach * (1.0 + MARGIN);
        self.decide_by(tree, triangles, [from, to], |_| Some(least), backoff);
    }

    /// [`Patches::decide`] for the particles anywhere within `rooms` (each particle's, m)
    /// of `places`: each node for `thickness` and twice the widest room of its own
    /// particles (a node's pairs are of its particles alone), so that one particle whose
    /// box looks far ahead leaves the others' nodes to be certified. A node whose reach
    /// comes to the rest gap is not tried (no reach as wide certifies it).
    pub(super) fn decide_in_rooms(
        &self,
        tree: &mut TriangleTree,
        triangles: &[[u32; 3]],
        places: &[Vec3A],
        (thickness, rooms): (f32, &[f32]),
        backoff: &mut Vec<u8>,
    ) {
        let least = |i: usize| {
            let entries = &self.particle[self.start[i] as usize..self.start[i + 1] as usize];
            let room = (entries.iter()).fold(0.0f32, |m, &p| m.max(rooms[p as usize]));
            let reach = thickness + 2.0 * room;
            (reach < self.gap).then_some(reach * (1.0 + MARGIN))
        };
        self.decide_by(tree, triangles, [places, places], least, backoff);
    }

    /// [`Patches::decide`] with each node `i` certified for `least(i)` (`None`: not tried).
    fn decide_by(
        &self,
        tree: &mut TriangleTree,
        triangles: &[[u32; 3]],
        [from, to]: [&[Vec3A]; 2],
        least: impl Fn(usize) -> Option<f32> + Sync,
        backoff: &mut Vec<u8>,
    ) {
        // Each of the tree's subtrees (the nodes a certificate can cover) is one piece.
        // Taken out while the tree is read for each node's triangles, then put back.
        let mut covered = std::mem::take(&mut tree.covered);
        let (shape, subtrees) = (&*tree, &tree.subtrees);
        covered.clear();
        covered.resize(self.parent.len(), false);
        if backoff.len() != self.parent.len() {
            backoff.clear();
            backoff.resize(self.parent.len(), 0);
        }
        // Each subtree from its root down: a node under a certified one is covered with it.
        let (flags, counts) = (Disjoint::new(&mut covered), Disjoint::new(backoff));
        let work = |_: usize, piece: usize| {
            let range = subtrees[piece].0.clone();
            // SAFETY: the subtrees' ranges are disjoint.
            let (flags, counts) =
                unsafe { (flags.part(range.clone()), counts.part(range.clone())) };
            for i in range.clone() {
                let parent = self.parent[i] as usize;
                let (at, above) = (
                    i - range.start,
                    i != range.start && flags[parent - range.start],
                );
                let patch = (self.convex[i]).then(|| (triangles, shape.held(i)));
                flags[at] = above
                    || least(i).is_some_and(|least| {
                        tried(&mut counts[at], || {
                            self.certified(i, patch, [from, to], least)
                        })
                    });
            }
        };
        let parallel = self.particle.len() >= PARALLEL_ELEMENTS;
        Team::current().run_large_pieces_if(parallel, subtrees.len(), &work);
        tree.covered = covered;
    }

    /// Whether corner `c`'s ring is held by a node of `tree` covered for the motion last
    /// decided.
    pub(super) fn covers(&self, tree: &TriangleTree, c: usize) -> bool {
        let home = self.home[c];
        home != NONE && tree.covered.get(home as usize).copied().unwrap_or(false)
    }

    /// Whether no pair of node `i` comes within `least` along the motion: every particle
    /// starts (ends) within half of what the rest gap, shrunk by the least the maps along
    /// the motion stretch, leaves over `least` of where the map fitted to the starts (ends)
    /// puts its rest offset, carried with the middle of the starts (ends). The maps are
    /// least-squares fits; any maps would do. Or, where the node is one convex region of
    /// the cloth's plane (its triangles `patch`), every triangle keeps near the maps in
    /// how it turns ([`flat`]). Never for a node with no entries, nor where a distance is
    /// NaN.
    fn certified(
        &self,
        i: usize,
        patch: Option<Triangles<'_>>,
        motion: [&[Vec3A]; 2],
        least: f32,
    ) -> bool {
        let range = self.start[i] as usize..self.start[i + 1] as usize;
        self.holds(range, self.inverse[i], patch, motion, least)
    }

    /// Whether corner `c`'s ring keeps so near its rest shape along the motion from
    /// `from` to `to` that none of the corner's pairs comes within `reach` (as for a node:
    /// a ring is a patch too; its triangles, `around` of `triangles`, for their turns).
    pub(super) fn ring_holds(
        &self,
        c: usize,
        (triangles, around): Triangles<'_>,
        motion: [&[Vec3A]; 2],
        reach: f32,
    ) -> bool {
        let range = self.rings[c] as usize..self.rings[c + 1] as usize;
        let patch = (self.ring_convex[c]).then_some((triangles, around));
        self.holds(
            range,
            self.ring_inverse[c],
            patch,
            motion,
            reach * (1.0 + MARGIN),
        )
    }

    /// [`Patches::certified`] for the entries in `range`, whose inverse second moments
    /// are `inverse`; where the patch is convex in the cloth's plane (its triangles
    /// `patch`), by their turns too ([`flat`]).
    fn holds(
        &self,
        range: std::ops::Range<usize>,
        [xx, xy, yy]: [f32; 3],
        patch: Option<Triangles<'_>>,
        [from, to]: [&[Vec3A]; 2],
        least: f32,
    ) -> bool {
        if range.is_empty() {
            return false;
        }
        let (particle, reference) = (&self.particle[range.clone()], &self.reference[range]);
        let n = particle.len() as f32;
        // The motion comes in SSE lanes (`Vec3A`): the same operations in the same order
        // as with `Vec3`, so the same results, in fewer instructions.
        let at = |x: &[Vec3A], j: u32| x[j as usize];
        // The middles of the starts and of the ends, and the maps fitted to each: their
        // columns are sums over the particles weighed by the inverse second moments.
        let (mut first, mut last) = (Vec3A::ZERO, Vec3A::ZERO);
        let [mut p0, mut q0, mut p1, mut q1] = [Vec3A::ZERO; 4];
        for (&j, r) in particle.iter().zip(reference) {
            let (s, e) = (at(from, j), at(to, j));
            (first, last) = (first + s, last + e);
            let (a, b) = (xx * r.x + xy * r.y, xy * r.x + yy * r.y);
            (p0, q0, p1, q1) = (p0 + a * s, q0 + b * s, p1 + a * e, q1 + b * e);
        }
        let (first, last) = (first / n, last / n);
        // Along the motion the map runs from the starts' to the ends' (its third column,
        // the normal, held at the middle's): it shrinks no distance by more than the
        // middle's least stretch less half how far the map moves (Weyl).
        let Some((middle, shrink)) = fitted((0.5 * (p0 + p1)).into(), (0.5 * (q0 + q1)).into())
        else {
            return false;
        };
        let moved = 0.5 * ((p1 - p0).length_squared() + (q1 - q0).length_squared()).sqrt();
        let most = 0.5 * ((shrink - moved) * self.gap - least);
        if most.is_nan() || most <= 0.0 {
            return false;
        }
        let limit = most * most;
        let normal = middle.z_axis.into();
        let (start_map, end_map) = (
            glam::Mat3A::from_cols(p0, q0, normal),
            glam::Mat3A::from_cols(p1, q1, normal),
        );
        let near = (particle.iter().zip(reference)).all(|(&j, &r)| {
            let r = Vec3A::from(r);
            let start = (at(from, j) - first - start_map * r).length_squared();
            let end = (at(to, j) - last - end_map * r).length_squared();
            start <= limit && end <= limit
        });
        near || patch
            .zip(self.flat.as_ref())
            .is_some_and(|((triangles, tris), flat)| {
                // The least stretch along the motion, less what the rest gap needs to keep the
                // reach: how far each triangle's gradient may stray from the map.
                let room = shrink - moved - least / flat.gap(self.gap);
                room > 0.0
                    && flat.turns_within(tris, triangles, [from, to], [[p0, q0], [p1, q1]], room)
            })
    }

    /// Adds a patch's entries for its particles `held` at `rest` (none: not certified);
    /// returns their inverse second moments.
    fn add(&mut self, held: &[u32], rest: &[Vec3]) -> [f32; 3] {
        if held.is_empty() {
            return [0.0; 3];
        }
        let at = |j: u32| rest[j as usize];
        let middle = held.iter().map(|&j| at(j)).sum::<Vec3>() / held.len() as f32;
        let back = match &self.flat {
            Some(flat) => flat.back,
            None => {
                let [a, b, c] = anchor(held, rest).map(at);
                frame(a, b, c).transpose()
            }
        };
        let start = self.reference.len();
        (self.reference).extend(held.iter().map(|&j| back * (at(j) - middle)));
        self.particle.extend_from_slice(held);
        // The least-squares fit of the motion's middles by a linear map of the rest
        // shape's offsets in the frame's first two axes: the map's columns are sums over
        // the particles weighed by the inverse of the offsets' second moments. A rigid
        // motion is fitted exactly (its turn, found again).
        let r = &self.reference[start..];
        let (uu, uv, vv) = r.iter().fold((0.0, 0.0, 0.0), |(uu, uv, vv), o| {
            (uu + o.x * o.x, uv + o.x * o.y, vv + o.y * o.y)
        });
        let det = uu * vv - uv * uv;
        if det.abs() > f32::EPSILON * (uu * vv).max(f32::MIN_POSITIVE) {
            [vv / det, -uv / det, uu / det]
        } else {
            [0.0; 3]
        }
    }
}

/// Whether a node with backoff `count` is certified: not tested (`false`) while its count
/// waits, then `certified`; a failure leaves it out of the next 1, 3 or 7 searches after
/// one, two, or three or more in a row.
fn tried(count: &mut u8, certified: impl FnOnce() -> bool) -> bool {
    let (wait, failed) = (*count & WAITING, *count >> 4);
    if wait > 0 {
        *count -= 1;
        false
    } else if certified() {
        *count = 0;
        true
    } else {
        let failed = (failed + 1).min(3);
        *count = failed << 4 | ((1 << failed) - 1);
        false
    }
}

/// The linear map whose first two columns are `p` and `q` and whose third is their
/// normal scaled by the least the two stretch any direction between them, and that least
/// (`None` where they are parallel): it shrinks no distance by more than that least.
fn fitted(p: Vec3, q: Vec3) -> Option<(glam::Mat3, f32)> {
    let (a, b, c) = (p.dot(p), p.dot(q), q.dot(q));
    let least = 0.5 * (a + c) - (0.25 * (a - c) * (a - c) + b * b).sqrt();
    let normal = p.cross(q).normalize_or_zero();
    if least.is_nan() || least <= 0.0 || normal == Vec3::ZERO {
        return None;
    }
    let shrink = least.sqrt();
    Some((glam::Mat3::from_cols(p, q, shrink * normal), shrink))
}

/// Three of `held` (at `rest`) whose frame turns a node: the one nearest their middle,
/// the one farthest from it, and the one farthest from the line through those two.
fn anchor(held: &[u32], rest: &[Vec3]) -> [u32; 3] {
    let Some(&first) = held.first() else {
        return [0; 3];
    };
    let at = |j: u32| rest[j as usize];
    let middle = held.iter().map(|&j| at(j)).sum::<Vec3>() / held.len() as f32;
    let most = |key: &dyn Fn(Vec3) -> f32| {
        (held.iter().copied()).fold((first, f32::NEG_INFINITY), |(best, k), j| {
            let v = key(at(j));
            if v > k { (j, v) } else { (best, k) }
        })
    };
    let (a, _) = most(&|p| -p.distance_squared(middle));
    let (b, _) = most(&|p| p.distance_squared(at(a)));
    let (c, _) = most(&|p| (p - at(a)).cross(at(b) - at(a)).length_squared());
    [a, b, c]
}

/// Each corner's smallest node of at most [`TRIANGLES_PER_PIECE`] triangles holding
/// every triangle around it ([`NONE`]: none).
fn homes(
    tree: &TriangleTree,
    nodes: &[crate::sim::obstacle::Split],
    parent: &[u32],
    triangles: &[[u32; 3]],
    particles: usize,
) -> Vec<u32> {
    let mut leaf = vec![0u32; triangles.len()];
    let mut depth = vec![0u32; nodes.len()];
    for (i, node) in nodes.iter().enumerate() {
        if i > 0 {
            depth[i] = depth[parent[i] as usize] + 1;
        }
        if node.second == 0 {
            for &t in tree.held(i) {
                leaf[t as usize] = i as u32;
            }
        }
    }
    let common = |mut a: u32, mut b: u32| {
        while a != b {
            if depth[a as usize] >= depth[b as usize] {
                a = parent[a as usize];
            } else {
                b = parent[b as usize];
            }
        }
        a
    };
    let (start, around) = crate::mesh::triangles_around(particles, triangles);
    (0..particles)
        .map(|c| {
            let ring = &around[start[c] as usize..start[c + 1] as usize];
            let first = ring.first().map(|&t| leaf[t as usize]);
            let home = ring
                .iter()
                .fold(first, |h, &t| h.map(|h| common(h, leaf[t as usize])));
            home.filter(|&h| nodes[h as usize].count <= TRIANGLES_PER_PIECE)
                .unwrap_or(NONE)
        })
        .collect()
}

/// The least distance at `rest` between the sides of any pair of the cloth (a vertex and a
/// triangle it is not a corner of, two edges that share no particle), up to the longest
/// rest edge, rounded down: `corners` for the pairs of two triangles that share a corner,
/// and those of two that do not whose rest boxes, grown by half that edge, overlap (found
/// by a walk of the `tree`, fitted to them). Shared with the team; a pair whose sides'
/// boxes lie farther apart than the least yet is passed by.
fn rest_gap(
    tree: &mut TriangleTree,
    triangles: &[[u32; 3]],
    rest: &[Vec3],
    (owners, corners): (&Owners, f32),
) -> f32 {
    let cap = owners.longest;
    let grow = Vec3::splat(0.5 * cap);
    let boxes: Vec<(Vec3, Vec3)> = (triangles.iter())
        .map(|t| {
            let [a, b, c] = t.map(|i| rest[i as usize]);
            (a.min(b).min(c), a.max(b).max(c))
        })
        .collect();
    let (lo, hi): (Vec<Vec3>, Vec<Vec3>) = boxes.iter().map(|&(l, h)| (l - grow, h + grow)).unzip();
    tree.covered.clear();
    tree.fit_boxes(&lo, &hi);
    // The least yet, as the bits of a positive `f64` (which order as the numbers do).
    // Not below 0 (a corner's reference that overflowed reads -∞), where the bits would
    // not order as the numbers do.
    let least = AtomicU64::new(f64::from(cap.min(corners).max(0.0)).to_bits());
    let measure = |pair: Pair, mine: &mut f64| *mine = nearer(&pair, rest, *mine);
    let tree = &*tree;
    let work = |_: usize, piece: usize| {
        let mut mine = f64::from_bits(least.load(Ordering::Relaxed));
        tree.piece_pairs(piece, |a, b| {
            let (a, b) = (a as usize, b as usize);
            // Two triangles whose own boxes lie farther apart than the least yet have no
            // pair nearer (most of those the grown boxes meet).
            if boxes_apart_by(boxes[a], boxes[b], mine) {
                return;
            }
            owners.each_pair(triangles, a, b, |pair, _| measure(pair, &mut mine));
        });
        least.fetch_min(mine.to_bits(), Ordering::Relaxed);
    };
    let parallel = triangles.len() >= PARALLEL_ELEMENTS;
    Team::current().run_large_pieces_if(parallel, tree.pieces(), &work);
    shave(f64::from_bits(least.into_inner()))
}

#[cfg(test)]
mod tests;
