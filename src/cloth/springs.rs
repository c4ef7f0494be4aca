//! A cloth's springs, as flat arrays.

use glam::Vec3;

use crate::mesh::SpringKind;

/// Springs as flat arrays (structure of arrays), in a deterministic order: the mesh's
/// sorted unique edges first, then the quads' second diagonals, then the bend pairs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Springs {
    pub a: Vec<u32>,
    pub b: Vec<u32>,
    /// Rest length, metres.
    pub rest: Vec<f32>,
    pub kind: Vec<SpringKind>,
}

impl Springs {
    pub fn len(&self) -> usize {
        self.a.len()
    }

    pub fn is_empty(&self) -> bool {
        self.a.is_empty()
    }

    /// How many springs are of `kind`.
    pub fn count(&self, kind: SpringKind) -> usize {
        self.kind.iter().filter(|&&k| k == kind).count()
    }

    /// The largest relative extension of any spring with its ends at `pos` (0 when none is
    /// stretched; a spring of zero rest length counts from 10⁻¹² m).
    pub fn largest_strain(&self, pos: &[Vec3]) -> f32 {
        (self.a.iter().zip(&self.b).zip(&self.rest))
            .map(|((&a, &b), &rest)| {
                pos[a as usize].distance(pos[b as usize]) / rest.max(1e-12) - 1.0
            })
            .fold(0.0f32, f32::max)
    }
}
