//! Uniform gravity: `f = m·g`. Its derivatives are zero.

use glam::Vec3;

use crate::cloth::{ClothModel, Real, Vector};
use crate::parallel::wide;
use crate::parallel::{each_part, within};
use crate::sim::forces::{Force, ForceTerm, Fused};
use crate::sim::kernels::Components;
use crate::sim::param_error::ParamError;
use crate::sim::params::Material;

use super::effect_kind::{ClothBox, EffectKind};

/// Uniform gravitational acceleration.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Gravity {
    /// m/s² (default 9.81 down the y axis).
    pub acceleration: Vec3,
}

impl Default for Gravity {
    fn default() -> Self {
        Self {
            acceleration: Vec3::new(0.0, -9.81, 0.0),
        }
    }
}

impl Gravity {
    /// As [`ForceTerm::add_forces_components`] for one range of particles: `mass` and `f`
    /// are that range's.
    pub fn add_range(&self, mass: &[f32], f: [&mut [f32]; 3]) {
        wide(
            #[inline(always)]
            || {
                for (f, g) in f.into_iter().zip(self.acceleration.to_array()) {
                    for (f, &m) in f.iter_mut().zip(mass) {
                        *f += m * g;
                    }
                }
            },
        )
    }
}

impl<R: Real> ForceTerm<R> for Gravity {
    /// Adds `m·g` (N) to every particle's force.
    fn add_forces(
        &self,
        model: &ClothModel,
        _pos: &[R::V3],
        _vel: &[R::V3],
        _t: f64,
        f: &mut [R::V3],
    ) {
        let g = R::v3(self.acceleration);
        for (f, &m) in f.iter_mut().zip(&model.mass) {
            *f += g * R::of_f32(m);
        }
    }

    fn takes_components(&self) -> bool {
        R::VECTORISED
    }

    fn add_forces_components(
        &self,
        model: &ClothModel,
        _pos: &Components,
        _vel: &Components,
        f: &mut Components,
    ) {
        let [f0, f1, f2] = f;
        each_part([f0, f1, f2], |range, f| {
            self.add_range(within(&model.mass, range), f)
        });
    }

    fn fused<'a>(&'a self, _model: &ClothModel) -> Fused<'a> {
        Fused::Pointwise
    }

    fn add_pointwise(&self, mass: &[f32], _vel: [&[f32]; 3], f: [&mut [f32]; 3]) {
        self.add_range(mass, f);
    }

    /// `−Σ m·g·x`, joules.
    fn potential_energy(&self, model: &ClothModel, pos: &[R::V3]) -> f64 {
        let g = R::v3(self.acceleration);
        -pos.iter()
            .zip(&model.mass)
            .map(|(p, &m)| m as f64 * g.dot(*p).to_f64())
            .sum::<f64>()
    }
}

impl EffectKind for Gravity {
    const NAME: &'static str = "gravity";
    const TITLE: &'static str = "Gravity";
    const MANY: bool = false;
    const ADDABLE: bool = true;

    fn check(&self) -> Result<(), ParamError> {
        // A hundred thousand times the Earth's and more: speeds past what `f32` squares.
        ParamError::require(
            self.acceleration.is_finite() && self.acceleration.length() <= 1e6,
            "acceleration",
            self.acceleration,
            "is out of range (at most 1e6 m/s²)",
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
