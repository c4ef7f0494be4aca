//! Linear air damping, mass-proportional: `f = −c·m·v`, so every free particle loses
//! velocity at the same rate `c` (1/s) whatever the mesh resolution.

use crate::cloth::{ClothModel, Real};
use crate::parallel::wide;
use crate::parallel::{each_part, within};
use crate::sim::forces::{Force, ForceTerm, Fused, SystemMatrix};
use crate::sim::kernels::Components;
use crate::sim::param_error::ParamError;
use crate::sim::params::Material;

use super::effect_kind::{ClothBox, EffectKind};

/// Air damping.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AirDamping {
    /// Rate, 1/s (0.5 when added in the app: a swinging cloth loses most of its motion
    /// within a few seconds).
    pub rate: f32,
}

impl Default for AirDamping {
    fn default() -> Self {
        Self { rate: 0.5 }
    }
}

impl AirDamping {
    /// As [`ForceTerm::add_forces_components`] for one range of particles: `mass`, `vel`
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
}

impl<R: Real> ForceTerm<R> for AirDamping {
    /// Adds `−c·m·v` (N).
    fn add_forces(
        &self,
        model: &ClothModel,
        _pos: &[R::V3],
        vel: &[R::V3],
        _t: f64,
        f: &mut [R::V3],
    ) {
        for ((f, v), &m) in f.iter_mut().zip(vel).zip(&model.mass) {
            *f -= *v * R::of_f32(self.rate * m);
        }
    }

    fn takes_components(&self) -> bool {
        R::VECTORISED
    }

    fn add_forces_components(
        &self,
        model: &ClothModel,
        _pos: &Components,
        vel: &Components,
        f: &mut Components,
    ) {
        let [f0, f1, f2] = f;
        each_part([f0, f1, f2], |range, f| {
            let v = vel.each_ref().map(|v| within(v, range.clone()));
            self.add_range(within(&model.mass, range), v, f);
        });
    }

    fn fused<'a>(&'a self, _model: &ClothModel) -> Fused<'a> {
        Fused::Pointwise
    }

    fn add_pointwise(&self, mass: &[f32], vel: [&[f32]; 3], f: [&mut [f32]; 3]) {
        self.add_range(mass, vel, f);
    }

    /// Adds `(∂f/∂v)·u = −c·m·u` to `out`.
    fn add_df_dv(
        &self,
        model: &ClothModel,
        _pos: &[R::V3],
        _vel: &[R::V3],
        u: &[R::V3],
        out: &mut [R::V3],
    ) {
        for ((o, u), &m) in out.iter_mut().zip(u).zip(&model.mass) {
            *o -= *u * R::of_f32(self.rate * m);
        }
    }

    /// Adds `∂f_i/∂v_i = −c·m_i·I` (N·s/m), its only non-zero derivative, to the system.
    fn add_to_system(
        &self,
        model: &ClothModel,
        _pos: &[R::V3],
        _vel: &[R::V3],
        sys: &mut SystemMatrix<R>,
    ) {
        for (p, &m) in model.mass.iter().enumerate() {
            sys.add_dv_diagonal(p, R::of_f32(-self.rate * m));
        }
    }
}

impl EffectKind for AirDamping {
    const NAME: &'static str = "air-damping";
    const TITLE: &'static str = "Air damping";
    const MANY: bool = false;
    const ADDABLE: bool = true;

    fn check(&self) -> Result<(), ParamError> {
        // Past a million per second a particle stops within a microsecond, and at 1e30
        // the solves' sums left what `f32` holds.
        ParamError::require(
            (0.0..=1e6).contains(&self.rate),
            "rate",
            self.rate,
            "is out of range (0 to 1e6 1/s)",
        )
    }

    fn force<R: Real>(
        &self,
        _model: &ClothModel,
        _material: &Material,
        _kept: &[Force<R>],
    ) -> Option<Force<R>> {
        Some(Force::of(Self::NAME, *self))
    }

    fn on_gpu(&self) -> Result<(), &'static str> {
        Ok(())
    }

    fn suggested(_cloth: &ClothBox) -> Self {
        Self::default()
    }
}
