//! The cloth's structural and shear springs: the cloth itself, in every scene (its
//! stiffness and damping per kind are the material's).

use crate::cloth::{ClothModel, Real};
use crate::sim::forces::{Force, SpringForce};
use crate::sim::params::Material;

use super::effect_kind::{ClothBox, EffectKind};

/// The structural and shear springs (every spring before the bend springs).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ClothSprings;

/// The springs of `model` over `range` with the material's strengths, reusing a spring
/// term among `kept` over the same range (its regrouped runs) when there is one.
pub(super) fn spring_term<R: Real>(
    model: &ClothModel,
    material: &Material,
    kept: &[Force<R>],
    range: std::ops::Range<usize>,
) -> SpringForce {
    let (stiffness, damping) = (material.stiffness, material.damping);
    let mut s = (kept.iter())
        .filter_map(Force::springs)
        .find(|s| s.range() == range)
        .cloned()
        .unwrap_or_else(|| SpringForce::over(&model.springs, range, stiffness, damping));
    s.set_strengths(&model.springs, stiffness, damping);
    s
}

impl EffectKind for ClothSprings {
    const NAME: &'static str = "springs";
    const TITLE: &'static str = "Springs (structural, shear)";
    const MANY: bool = false;
    const ADDABLE: bool = false;

    fn force<R: Real>(
        &self,
        model: &ClothModel,
        material: &Material,
        kept: &[Force<R>],
    ) -> Option<Force<R>> {
        let range = 0..model.bend_start();
        Some(Force::of(
            Self::NAME,
            spring_term(model, material, kept, range),
        ))
    }

    fn on_gpu(&self) -> Result<(), &'static str> {
        Ok(())
    }

    fn suggested(_cloth: &ClothBox) -> Self {
        Self
    }
}
