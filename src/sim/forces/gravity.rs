//! Uniform gravity: `f = m·g`. Its derivatives are zero.

use glam::Vec3;

/// Uniform gravitational acceleration, m/s².
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gravity {
    pub g: Vec3,
}

impl Gravity {
    /// Adds `m·g` (N) to every particle's force.
    pub fn add_forces(&self, mass: &[f32], f: &mut [Vec3]) {
        for (f, &m) in f.iter_mut().zip(mass) {
            *f += m * self.g;
        }
    }
}
