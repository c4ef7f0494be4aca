//! Corners certified apart by the cloth's own motion. The pairs of two triangles that share
//! a corner are most of those a search meets (four in five on a grid), and where the cloth
//! moves fast their boxes always overlap; yet they come near only where the cloth folds
//! sharply at that corner. Every particle of a corner's pairs lies on one of the corner's
//! triangles (its ring), and a pair's distance does not change when the ring moves
//! rigidly, and changes by at most what its two sides stray from a rigid motion. So each
//! pair's distance stays above the least of them when last measured (the reference) less
//! twice the farthest any ring particle is from where the reference, turned and carried
//! with the corner, puts it. Any turn will do: the one used is the frame of the corner's
//! first triangle in the middle of the substep, so that turning with the cloth costs
//! nothing. Along the substep's straight-line motion each ring particle's offset from that
//! place is linear in time, so its largest is at the substep's start or end: a corner is
//! certified for the whole substep from those two. Where the certificate fails, the
//! reference is taken again at the motion's end (the substep's, where the next one starts,
//! or the end of the window the pairs are judged over: any shape will do), and the
//! corner's pairs are tested one by one only if it fails still.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{Mat3, Vec3};

use super::primitives::distance;
use super::search::Owners;
use crate::parallel::{Disjoint, PARALLEL_ELEMENTS, Team};

/// The share of the thickness by which a certificate must clear it: for the rounding of
/// the positions in the frame the search works in (the pairs' own tests keep none).
pub(super) const MARGIN: f32 = 0.01;

/// The references and what they certify.
#[derive(Clone, Debug, Default)]
pub(super) struct Certificates {
    /// Each ring entry's particle less its corner at the corner's reference, in the
    /// corner's frame there.
    reference: Vec<Vec3>,
    /// Each corner's least distance between the sides of its pairs at its reference, m
    /// (`-∞`: none taken).
    apart: Vec<f32>,
    /// Whether each corner's pairs must be tested one by one (its certificate failed).
    pub(super) open: Vec<bool>,
}

impl Certificates {
    /// Forgets every reference (the model changed).
    pub(super) fn forget(&mut self) {
        self.apart.clear();
    }

    /// Decides, for the motion of each particle from `from` to `to`, which corners' pairs
    /// could come within `thickness` (those it leaves [`Certificates::open`]); with `only`,
    /// only the corners that are, or have in their ring, a particle it flags (the others'
    /// motion is as when they were last decided). The corners `covered` flags are closed as
    /// they are, and so are those whose reference fails where `near_rest` holds (their
    /// pairs are certified apart otherwise, for this motion: [`super::patches`]), before
    /// their reference is taken again. Returns how many references it took again.
    pub(super) fn decide(
        &mut self,
        owners: &Owners,
        triangles: &[[u32; 3]],
        [from, to]: [&[Vec3]; 2],
        thickness: f32,
        only: Option<&[bool]>,
        [covered, near_rest]: [&(dyn Fn(usize) -> bool + Sync); 2],
    ) -> u64 {
        let rings = &owners.rings;
        let corners = from.len();
        if self.apart.len() != corners || self.reference.len() != rings.ring.len() {
            self.apart.clear();
            self.apart.resize(corners, f32::NEG_INFINITY);
            self.reference.clear();
            self.reference.resize(rings.ring.len(), Vec3::ZERO);
            self.open.clear();
            self.open.resize(corners, true);
        }
        let least = thickness * (1.0 + MARGIN);
        let retaken = AtomicU64::new(0);
        let (reference, apart, open) = (
            Disjoint::new(&mut self.reference),
            Disjoint::new(&mut self.apart),
            Disjoint::new(&mut self.open),
        );
        let work = |_: usize, piece: usize| {
            let first = piece * CORNERS_PER_PIECE;
            let mut taken = 0;
            for c in first..(first + CORNERS_PER_PIECE).min(corners) {
                let range = rings.range(c);
                let ring = &rings.ring[range.clone()];
                if only.is_some_and(|o| !o[c] && ring.iter().all(|&j| !o[j as usize])) {
                    continue;
                }
                if covered(c) {
                    // SAFETY: each corner is one piece's.
                    *unsafe { open.at(c) } = false;
                    continue;
                }
                // SAFETY: each corner is one piece's, and its ring's entries its own.
                let corner = unsafe { (reference.part(range), apart.at(c), open.at(c)) };
                let motion = [from, to];
                let settled = || near_rest(c);
                taken += u64::from(decide_one(
                    c,
                    corner,
                    (owners, triangles),
                    motion,
                    least,
                    settled,
                ));
            }
            retaken.fetch_add(taken, Ordering::Relaxed);
        };
        let (parallel, pieces) = (
            corners >= PARALLEL_ELEMENTS,
            corners.div_ceil(CORNERS_PER_PIECE),
        );
        Team::current().run_large_pieces_if(parallel, pieces, &work);
        retaken.into_inner()
    }
}

/// Corners decided in one piece of [`Certificates::decide`].
const CORNERS_PER_PIECE: usize = 256;

/// Decides corner `c`, with its reference, least distance and whether it is open (closed
/// without a new reference where its reference fails but `settled` holds); returns
/// whether the reference was taken again.
fn decide_one(
    c: usize,
    (reference, apart, open): (&mut [Vec3], &mut f32, &mut bool),
    (owners, triangles): (&Owners, &[[u32; 3]]),
    [from, to]: [&[Vec3]; 2],
    least: f32,
    settled: impl Fn() -> bool,
) -> bool {
    let (ring, pairs) = (
        &owners.rings.ring[owners.rings.range(c)],
        owners.corner_pairs(c),
    );
    if pairs.is_empty() {
        *open = false;
        return false;
    }
    let [a, b] = owners.rings.first[c].map(|i| i as usize);
    let middle = |i: usize| 0.5 * (from[i] + to[i]);
    let turn = frame(middle(c), middle(a), middle(b));
    // The farthest a ring particle is, at the substep's start or end, from where the
    // reference puts it, turned with the corner's frame in the middle of the substep
    // (finite positions and references give a finite distance or +∞, never a NaN).
    let strayed = |reference: &[Vec3]| {
        let mut most = 0.0f32;
        for (&j, &r) in ring.iter().zip(reference) {
            let (j, r) = (j as usize, turn * r);
            let start = (from[j] - from[c] - r).length_squared();
            let end = (to[j] - to[c] - r).length_squared();
            most = most.max(start).max(end);
        }
        most.sqrt()
    };
    if certified(*apart, strayed(reference), least) || settled() {
        *open = false;
        return false;
    }
    // Taken again at the motion's end (where the next substep starts), in its frame
    // there; the distances are exact for the rounded positions, and rounded down to f32.
    let back = frame(to[c], to[a], to[b]).transpose();
    for (&j, r) in ring.iter().zip(reference.iter_mut()) {
        *r = back * (to[j as usize] - to[c]);
    }
    let nearest = (pairs.iter())
        .map(|p| {
            let pair = p.expand(triangles, &owners.edges);
            distance(&pair, pair.ids().map(|i| to[i].as_dvec3()))
        })
        .fold(f64::INFINITY, f64::min);
    // A reference that overflowed certifies nothing.
    let finite = reference.iter().all(|r| r.is_finite());
    *apart = if finite {
        shave(nearest)
    } else {
        f32::NEG_INFINITY
    };
    *open = !certified(*apart, strayed(reference), least);
    true
}

/// Whether pairs `apart` at the reference, their particles `strayed` from it, stay at
/// least `least` apart (not where either is NaN).
fn certified(apart: f32, strayed: f32, least: f32) -> bool {
    apart - 2.0 * strayed >= least
}

/// An orthonormal frame of the triangle (`c`, `a`, `b`): along `a − c`, across it in the
/// triangle's plane, and along the normal; where the triangle has no area, no turn at all
/// (any turn keeps the bound, this one only keeps it tight).
pub(super) fn frame(c: Vec3, a: Vec3, b: Vec3) -> Mat3 {
    let along = (a - c).normalize_or_zero();
    let normal = (a - c).cross(b - c).normalize_or_zero();
    if along == Vec3::ZERO || normal == Vec3::ZERO {
        return Mat3::IDENTITY;
    }
    Mat3::from_cols(along, normal.cross(along), normal)
}

/// `d` rounded down to an `f32`.
pub(super) fn shave(d: f64) -> f32 {
    let f = d as f32;
    if f64::from(f) > d { f.next_down() } else { f }
}

#[cfg(test)]
mod tests;
