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

    /// `−Σ m·g·x`, joules.
    pub fn potential_energy(&self, mass: &[f32], pos: &[Vec3]) -> f64 {
        -pos.iter()
            .zip(mass)
            .map(|(p, &m)| m as f64 * self.g.dot(*p) as f64)
            .sum::<f64>()
    }
}
