//! A cloth's springs, as flat arrays.

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
}
