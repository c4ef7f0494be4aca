//! Uniform gravity: `f = m·g`. Its derivatives are zero.

use glam::Vec3;

use crate::parallel::wide;
use crate::parallel::{each_part, within};
use crate::sim::kernels::Components;

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

    /// As [`Gravity::add_forces`] on forces stored one array per component.
    pub fn add_forces_components(&self, mass: &[f32], f: &mut Components) {
        let [f0, f1, f2] = f;
        each_part([f0, f1, f2], |range, f| {
            self.add_range(within(mass, range), f)
        });
    }

    /// As [`Gravity::add_forces_components`] for one range of particles: `mass` and `f` are
    /// that range's.
    pub fn add_range(&self, mass: &[f32], f: [&mut [f32]; 3]) {
        wide(
            #[inline(always)]
            || {
                for (f, g) in f.into_iter().zip(self.g.to_array()) {
                    for (f, &m) in f.iter_mut().zip(mass) {
                        *f += m * g;
                    }
                }
            },
        )
    }

    /// `−Σ m·g·x`, joules.
    pub fn potential_energy(&self, mass: &[f32], pos: &[Vec3]) -> f64 {
        -pos.iter()
            .zip(mass)
            .map(|(p, &m)| m as f64 * self.g.dot(*p) as f64)
            .sum::<f64>()
    }
}
