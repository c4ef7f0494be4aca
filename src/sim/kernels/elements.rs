//! Forces that go an element at a time (a hinge, a triangle), shared with the team: each
//! piece of elements writes its elements' forces into slots of its own, then each member
//! adds its range of particles' slots in the elements' order. A particle's force is then
//! the sum, in the same order, that adding each element's force at its corners one element
//! after another gives, so the result is the same bits whoever runs which piece, and the
//! same as the one-thread loop (tested).

use std::ops::Range;

use glam::Vec3;

use super::components::Scratch;
use crate::parallel::{Disjoint, PARALLEL_ELEMENTS, Team, share};

/// An element's part of a slot that adds nothing: `x + (−0) = x` for every `x`, the zeros
/// of both signs included.
pub const NOTHING: Vec3 = Vec3::splat(-0.0);

/// Pieces of elements per team member: a member late for its share loses only the pieces
/// the others took meanwhile.
const PIECES_PER_MEMBER: usize = 4;

/// Elements in a piece are a multiple of this (the lanes the terms take them in).
const CHUNK: usize = super::vec3x8::LANES;

/// Where each particle's forces from its elements lie: `start[i]..start[i + 1]` of the
/// slots for particle `i`, in the elements' order, and the slot of each element's corner.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ElementForces<const N: usize> {
    start: Vec<u32>,
    /// The slot of corner `k` of element `e`: `slot[e][k]`.
    slot: Vec<[u32; N]>,
    scratch: Scratch<Vec<Vec3>>,
}

/// Where a piece of elements writes its elements' forces: each corner's into its particle's
/// next slot, so that each particle then adds a run of slots one after another.
pub struct Slots<'a, const N: usize> {
    slot: &'a [[u32; N]],
    out: &'a Disjoint<'a, Vec3>,
}

impl<const N: usize> Slots<'_, N> {
    /// Element `e`'s forces at its corners, in order ([`NOTHING`] for one that adds none).
    #[inline(always)]
    pub fn set(&mut self, e: usize, forces: [Vec3; N]) {
        for (&s, force) in self.slot[e].iter().zip(forces) {
            // SAFETY: every element's corner has a slot of its own, and each element is
            // one piece's.
            unsafe { *self.out.at(s as usize) = force };
        }
    }
}

impl<const N: usize> ElementForces<N> {
    /// For `elements` of `particles`, where they are enough to share: from
    /// [`PARALLEL_ELEMENTS`] on (`None` for fewer, which nothing shares).
    pub fn new(elements: &[[u32; N]], particles: usize) -> Option<Self> {
        if elements.len() < PARALLEL_ELEMENTS {
            return None;
        }
        let mut start = vec![0u32; particles + 1];
        for e in elements {
            for &i in e {
                start[i as usize + 1] += 1;
            }
        }
        for i in 0..particles {
            start[i + 1] += start[i];
        }
        let mut next = start.clone();
        let slot = (elements.iter())
            .map(|corners| {
                corners.map(|i| {
                    next[i as usize] += 1;
                    next[i as usize] - 1
                })
            })
            .collect();
        Some(Self {
            start,
            slot,
            scratch: Scratch::default(),
        })
    }

    /// Whether [`ElementForces::add_shared`] pays on the current team: where it has
    /// helpers.
    pub fn pays(&self) -> bool {
        Team::current().members() > 1
    }

    /// Adds the forces of the elements to `f`: `forces(range, slots)` sets every element's
    /// of those in `range` ([`Slots::set`], by its index in all), a piece at a time on the
    /// team; then each particle adds its slots in the elements' order.
    pub fn add_shared(
        &self,
        f: &mut [Vec3],
        forces: impl Fn(Range<usize>, &mut Slots<'_, N>) + Sync,
    ) {
        let mut scratch = self.scratch.lock();
        let elements = self.slot.len();
        scratch.resize(self.start.last().map_or(0, |&n| n as usize), NOTHING);
        let team = Team::current();
        let pieces = (team.members() * PIECES_PER_MEMBER).max(1);
        let chunks = elements.div_ceil(CHUNK);
        let out = Disjoint::new(&mut scratch[..]);
        team.run_pieces(pieces, &|_, p| {
            let c = share(chunks, pieces, p);
            let range = (c.start * CHUNK).min(elements)..(c.end * CHUNK).min(elements);
            forces(
                range,
                &mut Slots {
                    slot: &self.slot,
                    out: &out,
                },
            );
        });
        let (slots, start) = (&scratch[..], &self.start);
        let particles = Disjoint::new(f);
        let n = particles.len();
        team.run_pieces(pieces, &|_, p| {
            let range = share(n, pieces, p);
            // SAFETY: the pieces' particle ranges are disjoint.
            let f = unsafe { particles.part(range.clone()) };
            for (f, i) in f.iter_mut().zip(range) {
                for s in &slots[start[i] as usize..start[i + 1] as usize] {
                    *f += *s;
                }
            }
        });
    }
}
