//! One force term of a scene: a closed set, each variant in its own file.

use glam::Vec3;

use crate::cloth::ClothModel;

use super::air_damping::AirDamping;
use super::dihedral::DihedralBending;
use super::gravity::Gravity;
use super::jacobian::{JacobianMode, SystemMatrix};
use super::springs::SpringForce;
use super::wind::Wind;
use crate::sim::kernels::Components;
use crate::sim::kernels::TwoPasses;

/// How a term takes part in the fused path ([`Force::fused`]).
pub enum Fused<'a> {
    /// Each particle's force is its own: any range of particles at a time.
    Pointwise,
    /// Pairs of particles: every block's sums first, then per range of particles.
    TwoPasses(TwoPasses<'a>),
    /// Needs the vectors whole.
    No,
}

/// A force term. Each yields forces in newtons; the springs and air damping also give
/// their derivatives for implicit methods, which treat the others explicitly.
#[derive(Clone, Debug, PartialEq)]
pub enum Force {
    Gravity(Gravity),
    /// The structural and shear springs.
    Springs(SpringForce),
    /// The bend springs (a scene that bends by springs).
    BendSprings(SpringForce),
    AirDamping(AirDamping),
    Bending(DihedralBending),
    Wind(Wind),
}

impl Force {
    /// The term's phase name in timings.
    pub fn phase(&self) -> &'static str {
        match self {
            Force::Gravity(_) => "gravity",
            Force::Springs(_) => "springs",
            Force::AirDamping(_) => "air-damping",
            Force::Bending(_) | Force::BendSprings(_) => "bending",
            Force::Wind(_) => "wind",
        }
    }

    /// Adds this term's forces at `(pos, vel)` and time `t` to `f`, newtons.
    pub fn add_forces(
        &self,
        model: &ClothModel,
        pos: &[Vec3],
        vel: &[Vec3],
        t: f64,
        f: &mut [Vec3],
    ) {
        match self {
            Force::Gravity(g) => g.add_forces(&model.mass, f),
            Force::Springs(s) | Force::BendSprings(s) => s.add_forces(&model.springs, pos, vel, f),
            Force::AirDamping(d) => d.add_forces(&model.mass, vel, f),
            Force::Bending(b) => b.add_forces(model, pos, f),
            Force::Wind(w) => w.add_forces(model, pos, vel, t, f),
        }
    }

    /// Whether [`Force::add_forces_components`] evaluates this term: gravity, the springs
    /// and air damping do; dihedral bending and wind need the vectors whole. None of these
    /// terms depends on time, and semi-implicit Euler relies on it when it takes a frame's
    /// substeps together on component arrays (the clock is set once per batch): a term
    /// that reads the time must not take components.
    pub fn takes_components(&self) -> bool {
        matches!(
            self,
            Force::Gravity(_) | Force::Springs(_) | Force::BendSprings(_) | Force::AirDamping(_)
        )
    }

    /// As [`Force::add_forces`] with positions, velocities and forces stored one array per
    /// component (the same bits); a term that does not [take
    /// components](Force::takes_components) adds nothing and returns false.
    pub fn add_forces_components(
        &self,
        model: &ClothModel,
        pos: &Components,
        vel: &Components,
        f: &mut Components,
    ) -> bool {
        match self {
            Force::Gravity(g) => g.add_forces_components(&model.mass, f),
            Force::Springs(s) | Force::BendSprings(s) => {
                s.add_forces_components(&model.springs, pos, vel, f)
            }
            Force::AirDamping(d) => d.add_forces_components(&model.mass, vel, f),
            Force::Bending(_) | Force::Wind(_) => return false,
        }
        true
    }

    /// How the fused path ([`ForceSet::fused_components`](super::ForceSet::fused_components))
    /// evaluates this term: per particle over any range, in two passes (springs), or not at
    /// all (the terms that do not [take components](Force::takes_components)).
    pub fn fused<'a>(&'a self, model: &ClothModel) -> Fused<'a> {
        match self {
            Force::Gravity(_) | Force::AirDamping(_) => Fused::Pointwise,
            Force::Springs(s) | Force::BendSprings(s) => {
                Fused::TwoPasses(s.two_passes(&model.springs))
            }
            Force::Bending(_) | Force::Wind(_) => Fused::No,
        }
    }

    /// Adds a pointwise term's forces on one range of particles (`mass`, `vel` and `f` are
    /// that range's) to `f`, the same bits as [`Force::add_forces_components`] there; the
    /// other terms add nothing.
    pub fn add_pointwise(&self, mass: &[f32], vel: [&[f32]; 3], f: [&mut [f32]; 3]) {
        match self {
            Force::Gravity(g) => g.add_range(mass, f),
            Force::AirDamping(d) => d.add_range(mass, vel, f),
            _ => {}
        }
    }

    /// Potential energy at `pos`, joules; zero for dissipative and driving terms.
    pub fn potential_energy(&self, model: &ClothModel, pos: &[Vec3]) -> f64 {
        match self {
            Force::Gravity(g) => g.potential_energy(&model.mass, pos),
            Force::Springs(s) | Force::BendSprings(s) => s.potential_energy(&model.springs, pos),
            Force::Bending(b) => b.potential_energy(model, pos),
            Force::AirDamping(_) | Force::Wind(_) => 0.0,
        }
    }

    /// Adds `(∂f/∂x)·u` to `out` (N/m × m) for the terms that give derivatives.
    pub fn add_df_dx(
        &self,
        model: &ClothModel,
        pos: &[Vec3],
        vel: &[Vec3],
        u: &[Vec3],
        mode: JacobianMode,
        out: &mut [Vec3],
    ) {
        if let Force::Springs(s) | Force::BendSprings(s) = self {
            s.add_df_dx(&model.springs, pos, vel, u, mode, out);
        }
    }

    /// Adds `(∂f/∂v)·u` to `out` (N·s/m × m/s) for the terms that give derivatives.
    pub fn add_df_dv(
        &self,
        model: &ClothModel,
        pos: &[Vec3],
        vel: &[Vec3],
        u: &[Vec3],
        out: &mut [Vec3],
    ) {
        match self {
            Force::Springs(s) | Force::BendSprings(s) => {
                s.add_df_dv(&model.springs, pos, vel, u, out)
            }
            Force::AirDamping(d) => d.add_df_dv(&model.mass, u, out),
            Force::Gravity(_) | Force::Bending(_) | Force::Wind(_) => {}
        }
    }

    /// Adds this term's derivative blocks (definite form) to the implicit system.
    pub fn add_to_system(
        &self,
        model: &ClothModel,
        pos: &[Vec3],
        vel: &[Vec3],
        sys: &mut SystemMatrix,
    ) {
        match self {
            Force::Springs(s) | Force::BendSprings(s) => {
                s.add_to_system(&model.springs, pos, vel, sys)
            }
            Force::AirDamping(d) => d.add_to_system(&model.mass, sys),
            Force::Gravity(_) | Force::Bending(_) | Force::Wind(_) => {}
        }
    }
}
