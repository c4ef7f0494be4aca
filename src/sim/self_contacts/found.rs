//! The pairs a search keeps: each member of the team appends to its own buffer, and each
//! piece of a search records where its pairs went, so that read piece by piece they come
//! in the same order however the pieces were shared out.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::parallel::{Disjoint, Team};

use super::primitives::StoredPair;

/// Where one piece of a search put its pairs: `members[member][start..end]`.
#[derive(Clone, Copy, Debug, Default)]
struct Segment {
    member: u32,
    start: u32,
    end: u32,
}

/// The pairs, as each member of the team found them, and where each piece put its own.
/// A member's buffer is its segments end to end, in the order it ran them.
#[derive(Clone, Debug, Default)]
pub(super) struct Found {
    members: Vec<Vec<StoredPair>>,
    segments: Vec<Segment>,
    /// Segments by member, then by start (for [`Found::retain`]).
    order: Vec<u32>,
}

impl Found {
    /// The pairs as stored, in order.
    pub(super) fn stored(&self) -> impl Iterator<Item = &StoredPair> {
        self.segments.iter().flat_map(|&s| self.segment(s))
    }

    /// The pairs of segment `s`.
    fn segment(&self, s: Segment) -> &[StoredPair] {
        &self.members[s.member as usize][s.start as usize..s.end as usize]
    }

    /// Forgets every pair (the buffers are kept).
    pub(super) fn clear(&mut self) {
        self.members.iter_mut().for_each(Vec::clear);
        self.segments.clear();
    }

    /// Runs `search(piece, out)` for each piece in `0..pieces` — shared with the team's
    /// helpers when `parallel` — each appending its pairs to `out`; they follow the pairs
    /// already kept, piece after piece. Returns the sum of what the pieces returned (the
    /// pairs of triangles they tested: the same however the pieces were shared out).
    pub(super) fn extend(
        &mut self,
        pieces: usize,
        parallel: bool,
        search: &(dyn Fn(usize, &mut Vec<StoredPair>) -> u64 + Sync),
    ) -> u64 {
        let team = Team::current();
        (self.members).resize_with(team.members().max(1), Vec::new);
        let first = self.segments.len();
        (self.segments).resize(first + pieces, Segment::default());
        let (found, segments) = (
            Disjoint::new(&mut self.members),
            Disjoint::new(&mut self.segments[first..]),
        );
        let total = AtomicU64::new(0);
        let work = |member: usize, piece: usize| {
            // SAFETY: a member takes only its own buffer, and each piece is run once and
            // writes only its own segment.
            let (out, segment) = unsafe { (found.at(member), segments.at(piece)) };
            let start = out.len();
            total.fetch_add(search(piece, out), Ordering::Relaxed);
            *segment = Segment {
                member: member as u32,
                start: start as u32,
                end: out.len() as u32,
            };
        };
        team.run_large_pieces_if(parallel, pieces, &work);
        self.segments.retain(|s| s.start != s.end);
        total.into_inner()
    }

    /// How many pairs there are.
    pub(super) fn len(&self) -> usize {
        self.segments
            .iter()
            .map(|s| (s.end - s.start) as usize)
            .sum()
    }

    /// Calls `visit` with each piece's pairs, shared with the team's helpers when
    /// `parallel` (in no set order then: for work whose result does not depend on it).
    pub(super) fn share(&self, parallel: bool, visit: &(dyn Fn(&[StoredPair]) + Sync)) {
        let piece = |_: usize, piece: usize| visit(self.segment(self.segments[piece]));
        Team::current().run_large_pieces_if(parallel, self.segments.len(), &piece);
    }

    /// Keeps only the pairs for which `keep` is true, in their order.
    pub(super) fn retain(&mut self, keep: impl Fn(StoredPair) -> bool) {
        self.order.clear();
        self.order.extend(0..self.segments.len() as u32);
        let segments = &self.segments;
        (self.order).sort_unstable_by_key(|&s| {
            let s = segments[s as usize];
            (s.member, s.start)
        });
        let mut at = (usize::MAX, 0);
        for &s in &self.order {
            let segment = &mut self.segments[s as usize];
            let member = segment.member as usize;
            if at.0 != member {
                at = (member, 0);
            }
            let buffer = &mut self.members[member];
            let start = at.1;
            for i in segment.start as usize..segment.end as usize {
                if keep(buffer[i]) {
                    buffer[at.1] = buffer[i];
                    at.1 += 1;
                }
            }
            (segment.start, segment.end) = (start as u32, at.1 as u32);
        }
        // Each member's buffer ends where its last segment now does.
        for (member, buffer) in self.members.iter_mut().enumerate() {
            let end = (self.segments.iter())
                .filter(|s| s.member as usize == member)
                .map(|s| s.end as usize)
                .max()
                .unwrap_or(0);
            buffer.truncate(end);
        }
        self.segments.retain(|s| s.start != s.end);
    }
}
