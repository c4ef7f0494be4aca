//! What every force term computes ([`ForceTerm`]), implemented by each term's type:
//! gravity, air damping and wind in their effects' files, the springs and the dihedral
//! hinges in this folder.

use crate::cloth::{ClothModel, Real};
use crate::sim::kernels::{Components, TwoPasses};
use crate::sim::params::Material;

use super::jacobian::{JacobianMode, SystemMatrix};

/// How a term takes part in the fused path ([`ForceTerm::fused`]).
pub enum Fused<'a> {
    /// Each particle's force is its own: any range of particles at a time.
    Pointwise,
    /// Pairs of particles: every block's sums first, then per range of particles.
    TwoPasses(TwoPasses<'a>),
    /// Needs the vectors whole.
    No,
}

/// What a force term computes, in precision `R` (each term's type implements it for both).
/// Each yields forces in newtons; a term that gives no derivatives is treated explicitly by
/// implicit methods.
pub trait ForceTerm<R: Real = f32>: std::any::Any + Send + Sync + std::fmt::Debug {
    /// Adds its forces at `(pos, vel)` and time `t` to `f`, newtons.
    fn add_forces(&self, model: &ClothModel, pos: &[R::V3], vel: &[R::V3], t: f64, f: &mut [R::V3]);

    /// Whether [`ForceTerm::add_forces_components`] evaluates it (in `f32` only: the
    /// component kernels are the vectorised path). No term that takes components may
    /// depend on time: semi-implicit Euler takes a frame's substeps together on component
    /// arrays, with the clock set once per batch.
    fn takes_components(&self) -> bool {
        false
    }

    /// As [`ForceTerm::add_forces`] with positions, velocities and forces stored one array
    /// per component (the same bits); called only where it [takes
    /// components](ForceTerm::takes_components).
    fn add_forces_components(
        &self,
        _model: &ClothModel,
        _pos: &Components,
        _vel: &Components,
        _f: &mut Components,
    ) {
    }

    /// How the fused path ([`ForceSet::fused_components`](super::ForceSet::fused_components))
    /// evaluates it: per particle over any range, in two passes (springs), or not at all.
    fn fused<'a>(&'a self, _model: &ClothModel) -> Fused<'a> {
        Fused::No
    }

    /// Adds a pointwise term's forces on one range of particles (`mass`, `vel` and `f` are
    /// that range's), the same bits as [`ForceTerm::add_forces_components`] there.
    fn add_pointwise(&self, _mass: &[f32], _vel: [&[f32]; 3], _f: [&mut [f32]; 3]) {}

    /// Takes the material's new strengths in place (the springs do); a term whose strength
    /// is its effect's own keeps it.
    fn retune(&mut self, _model: &ClothModel, _material: &Material) {}

    /// Potential energy at `pos`, joules; zero for dissipative and driving terms.
    fn potential_energy(&self, _model: &ClothModel, _pos: &[R::V3]) -> f64 {
        0.0
    }

    /// Adds `(∂f/∂x)·u` to `out` (N/m × m); none by default (treated explicitly).
    fn add_df_dx(
        &self,
        _model: &ClothModel,
        _pos: &[R::V3],
        _vel: &[R::V3],
        _u: &[R::V3],
        _mode: JacobianMode,
        _out: &mut [R::V3],
    ) {
    }

    /// Adds `(∂f/∂v)·u` to `out` (N·s/m × m/s); none by default.
    fn add_df_dv(
        &self,
        _model: &ClothModel,
        _pos: &[R::V3],
        _vel: &[R::V3],
        _u: &[R::V3],
        _out: &mut [R::V3],
    ) {
    }

    /// Adds its derivative blocks (definite form) to the implicit system; none by default.
    fn add_to_system(
        &self,
        _model: &ClothModel,
        _pos: &[R::V3],
        _vel: &[R::V3],
        _sys: &mut SystemMatrix<R>,
    ) {
    }
}
