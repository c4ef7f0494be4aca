//! Linear air damping, mass-proportional: `f = −c·m·v`, so every free particle loses
//! velocity at the same rate `c` (1/s) whatever the mesh resolution.

use glam::Vec3;

use super::jacobian::SystemMatrix;
use crate::parallel::wide;
use crate::parallel::{each_part, within};
use crate::sim::kernels::Components;

/// Air damping rate, 1/s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AirDamping {
    pub rate: f32,
}

impl AirDamping {
    /// Adds `−c·m·v` (N).
    pub fn add_forces(&self, mass: &[f32], vel: &[Vec3], f: &mut [Vec3]) {
        for ((f, v), &m) in f.iter_mut().zip(vel).zip(mass) {
            *f -= (self.rate * m) * *v;
        }
    }

    /// As [`AirDamping::add_forces`] with velocities and forces stored one array per
    /// component.
    pub fn add_forces_components(&self, mass: &[f32], vel: &Components, f: &mut Components) {
        let [f0, f1, f2] = f;
        each_part([f0, f1, f2], |range, f| {
            let v = vel.each_ref().map(|v| within(v, range.clone()));
            self.add_range(within(mass, range), v, f);
        });
    }

    /// As [`AirDamping::add_forces_components`] for one range of particles: `mass`, `vel`
    /// and `f` are that range's.
    pub fn add_range(&self, mass: &[f32], vel: [&[f32]; 3], f: [&mut [f32]; 3]) {
        wide(
            #[inline(always)]
            || {
                for (f, v) in f.into_iter().zip(vel) {
                    for ((f, v), &m) in f.iter_mut().zip(v).zip(mass) {
                        *f -= (self.rate * m) * *v;
                    }
                }
            },
        )
    }

    /// Adds `∂f_i/∂v_i = −c·m_i·I` (N·s/m), its only non-zero derivative, to the system.
    pub fn add_to_system(&self, mass: &[f32], sys: &mut SystemMatrix) {
        for (p, &m) in mass.iter().enumerate() {
            sys.add_dv_diagonal(p, -self.rate * m);
        }
    }

    /// Adds `(∂f/∂v)·u` to `out`.
    pub fn add_df_dv(&self, mass: &[f32], u: &[Vec3], out: &mut [Vec3]) {
        for ((o, u), &m) in out.iter_mut().zip(u).zip(mass) {
            *o -= (self.rate * m) * *u;
        }
    }
}
