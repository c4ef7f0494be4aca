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
//! certified for the whole substep from those two. Every corner's first reference is its
//! rest shape (measured once per cloth, with the rest gap). Where the certificate fails
//! but the ring keeps near its rest shape ([`super::patches`]), the corner is closed and
//! goes back to its rest shape as its reference; where both fail, the reference is taken
//! again at the motion's end (the substep's, where the next one starts, or the end of the
//! window the pairs are judged over: any shape will do), and the corner's pairs are tested
//! one by one only if it fails still.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{Mat3, Vec3};

use super::primitives::nearer;
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
    /// Whether each corner's pairs must be tested one by one (its certificate failed; where
    /// the pairs are judged by the boxes, no covered patch holds its ring, or a refresh
    /// touched it).
    pub(super) open: Vec<bool>,
    /// Whether each corner was last closed by its ring keeping near its rest shape: its
    /// ring is tested first then (its rest shape as a reference, turned with the corner,
    /// mostly fails where the ring bends along with the cloth).
    ringed: Vec<bool>,
    /// The rest shape as a reference: each ring entry's particle less its corner at rest,
    /// in the corner's frame there, and each corner's least distance between the sides of
    /// its pairs at rest (rounded down; `+∞` for a corner without pairs). Every corner
    /// starts from it, and goes back to it where its ring keeps near its rest shape.
    rest: Vec<Vec3>,
    rest_apart: Vec<f32>,
}

impl Certificates {
    /// The certificates of the cloth of `triangles` with `owners`, each corner's reference
    /// its rest shape `rest` (measured by the team).
    pub(super) fn build(owners: &Owners, triangles: &[[u32; 3]], rest: &[Vec3]) -> Certificates {
        let rings = &owners.rings;
        let corners = rest.len();
        let mut certificates = Certificates {
            rest: vec![Vec3::ZERO; rings.ring.len()],
            rest_apart: vec![f32::INFINITY; corners],
            ..Certificates::default()
        };
        let (reference, apart) = (
            Disjoint::new(&mut certificates.rest),
            Disjoint::new(&mut certificates.rest_apart),
        );
        let work = |_: usize, piece: usize| {
            let first = piece * CORNERS_PER_PIECE;
            for c in first..(first + CORNERS_PER_PIECE).min(corners) {
                let range = rings.range(c);
                // SAFETY: each corner is one piece's, and its ring's entries its own.
                let (reference, apart) = unsafe { (reference.part(range), apart.at(c)) };
                if !owners.corner_pairs(c).is_empty() {
                    *apart = take(c, reference, (owners, triangles), rest);
                }
            }
        };
        let pieces = corners.div_ceil(CORNERS_PER_PIECE);
        Team::current().run_large_pieces_if(corners >= PARALLEL_ELEMENTS, pieces, &work);
        certificates
    }

    /// Opens every one of `corners` but those `closed` flags (where the pairs are judged by
    /// the boxes, the corners are certified by the patches alone, which hold for every
    /// place in the boxes).
    pub(super) fn open_unless(&mut self, corners: usize, closed: impl Fn(usize) -> bool) {
        self.open.clear();
        self.open.extend((0..corners).map(|c| !closed(c)));
    }

    /// Opens the corners `touched` flags.
    pub(super) fn reopen(&mut self, touched: &[bool]) {
        for (open, &touched) in self.open.iter_mut().zip(touched) {
            *open |= touched;
        }
    }

    /// The least distance at rest between the sides of any pair of two triangles that
    /// share a corner, rounded down (`+∞`: none).
    pub(super) fn least_at_rest(&self) -> f32 {
        self.rest_apart
            .iter()
            .copied()
            .fold(f32::INFINITY, f32::min)
    }

    /// Decides, for the motion of each particle from `from` to `to`, which corners' pairs
    /// could come within `thickness` (those it leaves [`Certificates::open`]); with `only`,
    /// only the corners it flags (the caller flags every corner that is, or has in its
    /// ring, a particle whose motion changed: the others' is as when they were last
    /// decided). The corners `covered` flags are closed as they are, and so are those
    /// whose reference fails where `near_rest` holds (their pairs are certified apart
    /// otherwise, for this motion: [`super::patches`]), before their reference is taken
    /// again. Returns how many references it took again.
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
            // From the rest shape, where it was measured for this cloth; from none (`-∞`)
            // otherwise.
            if self.rest_apart.len() == corners && self.rest.len() == rings.ring.len() {
                self.apart.clone_from(&self.rest_apart);
                self.reference.clone_from(&self.rest);
            } else {
                self.apart.clear();
                self.apart.resize(corners, f32::NEG_INFINITY);
                self.reference.clear();
                self.reference.resize(rings.ring.len(), Vec3::ZERO);
            }
            self.open.clear();
            self.open.resize(corners, true);
            self.ringed.clear();
            self.ringed.resize(corners, false);
        }
        let at_rest = (self.rest_apart.len() == corners).then_some((&self.rest, &self.rest_apart));
        let least = thickness * (1.0 + MARGIN);
        let retaken = AtomicU64::new(0);
        let (reference, apart, open, ringed) = (
            Disjoint::new(&mut self.reference),
            Disjoint::new(&mut self.apart),
            Disjoint::new(&mut self.open),
            Disjoint::new(&mut self.ringed),
        );
        let work = |_: usize, piece: usize| {
            let first = piece * CORNERS_PER_PIECE;
            let mut taken = 0;
            for c in first..(first + CORNERS_PER_PIECE).min(corners) {
                if only.is_some_and(|o| !o[c]) {
                    continue;
                }
                let range = rings.range(c);
                if covered(c) {
                    // SAFETY: each corner is one piece's.
                    *unsafe { open.at(c) } = false;
                    continue;
                }
                let rest = at_rest.map(|(r, a)| (&r[range.clone()], a[c]));
                // SAFETY: each corner is one piece's, and its ring's entries its own.
                let corner = unsafe {
                    let flags = (open.at(c), ringed.at(c));
                    (reference.part(range), apart.at(c), flags)
                };
                let motion = [from, to];
                let settled = || near_rest(c);
                taken += u64::from(decide_one(
                    c,
                    corner,
                    (owners, triangles),
                    motion,
                    least,
                    (settled, rest),
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
/// without a new reference where its reference fails but `settled` holds: its reference
/// is then its rest shape, where that was measured, `rest`; and where it was last closed
/// so, `ringed`, `settled` is tried first); returns whether the reference was taken again.
fn decide_one(
    c: usize,
    (reference, apart, (open, ringed)): (&mut [Vec3], &mut f32, (&mut bool, &mut bool)),
    (owners, triangles): (&Owners, &[[u32; 3]]),
    [from, to]: [&[Vec3]; 2],
    least: f32,
    (settled, rest): (impl Fn() -> bool, Option<(&[Vec3], f32)>),
) -> bool {
    let (ring, pairs) = (
        &owners.rings.ring[owners.rings.range(c)],
        owners.corner_pairs(c),
    );
    if pairs.is_empty() {
        *open = false;
        return false;
    }
    // Closed by its ring last time, and again: its reference (the rest shape) stands.
    let ring_first = *ringed;
    if ring_first && settled() {
        *open = false;
        return false;
    }
    *ringed = false;
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
    if certified(*apart, strayed(reference), least) {
        *open = false;
        return false;
    }
    if !ring_first && settled() {
        *ringed = true;
        // Its ring keeps near its rest shape: so will its rest shape fit the next
        // substeps (rather than a reference that failed, tried again every time).
        if let Some((rest, rest_apart)) = rest {
            reference.copy_from_slice(rest);
            *apart = rest_apart;
        }
        *open = false;
        return false;
    }
    // Taken again at the motion's end (where the next substep starts).
    *apart = take(c, reference, (owners, triangles), to);
    *open = !certified(*apart, strayed(reference), least);
    true
}

/// Takes corner `c`'s reference with its particles at `x`, in the frame of its first
/// triangle there; returns the least distance between the sides of its pairs (exact for
/// the rounded positions, rounded down to f32; `-∞` where the reference overflowed: it
/// certifies nothing).
fn take(
    c: usize,
    reference: &mut [Vec3],
    (owners, triangles): (&Owners, &[[u32; 3]]),
    x: &[Vec3],
) -> f32 {
    let ring = &owners.rings.ring[owners.rings.range(c)];
    let [a, b] = owners.rings.first[c].map(|i| i as usize);
    let back = frame(x[c], x[a], x[b]).transpose();
    for (&j, r) in ring.iter().zip(reference.iter_mut()) {
        *r = back * (x[j as usize] - x[c]);
    }
    let nearest = (owners.corner_pairs(c).iter()).fold(f64::INFINITY, |least, p| {
        nearer(&p.expand(triangles, &owners.edges), x, least)
    });
    if reference.iter().all(|r| r.is_finite()) {
        shave(nearest)
    } else {
        f32::NEG_INFINITY
    }
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
