//! The constraint view of the springs, for position-based integrators.

/// Distance constraints `|x_b − x_a| = rest`, flat arrays in the springs' order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DistanceConstraints {
    pub a: Vec<u32>,
    pub b: Vec<u32>,
    /// Rest length, metres.
    pub rest: Vec<f32>,
    /// Compliance `1/k`, m/N (0 would be inextensible).
    pub compliance: Vec<f32>,
    /// The spring's dashpot, N·s/m, for constraint damping.
    pub damping: Vec<f32>,
}

impl DistanceConstraints {
    pub fn len(&self) -> usize {
        self.a.len()
    }

    pub fn is_empty(&self) -> bool {
        self.a.is_empty()
    }
}
