//! How a cloth resists bending: springs between the vertices opposite each interior edge
//! (the material's bend stiffness), or discrete-shells hinges on the dihedral angle.

use crate::cloth::{ClothModel, Real};
use crate::sim::forces::{DihedralBending, Force};
use crate::sim::param_error::ParamError;
use crate::sim::params::Material;

use super::cloth_springs::spring_term;
use super::effect_kind::{ClothBox, EffectKind};

/// Dihedral stiffness when none is given, N·m.
pub const DEFAULT_DIHEDRAL_STIFFNESS: f32 = 2e-3;

fn default_dihedral_stiffness() -> f32 {
    DEFAULT_DIHEDRAL_STIFFNESS
}

/// How a cloth resists bending (`model = "springs"` or `"dihedral"` in scene files).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "model", rename_all = "kebab-case", deny_unknown_fields)]
pub enum BendingModel {
    /// Springs between the vertices opposite each interior edge, of the material's bend
    /// stiffness (N/m).
    Springs,
    /// Dihedral-angle bending (discrete shells) with this stiffness, N·m (default
    /// [`DEFAULT_DIHEDRAL_STIFFNESS`]).
    Dihedral {
        #[serde(default = "default_dihedral_stiffness")]
        stiffness: f32,
    },
}

impl EffectKind for BendingModel {
    const NAME: &'static str = "bending";
    const TITLE: &'static str = "Bending";
    const MANY: bool = false;
    const ADDABLE: bool = true;

    fn check(&self) -> Result<(), ParamError> {
        match *self {
            BendingModel::Dihedral { stiffness }
                if !(stiffness.is_finite() && stiffness >= 0.0) =>
            {
                Err(ParamError::new("stiffness", stiffness, "must be ≥ 0 N·m"))
            }
            BendingModel::Springs | BendingModel::Dihedral { .. } => Ok(()),
        }
    }

    fn force<R: Real>(
        &self,
        model: &ClothModel,
        material: &Material,
        kept: &[Force<R>],
    ) -> Option<Force<R>> {
        Some(match *self {
            BendingModel::Springs => {
                let range = model.bend_start()..model.springs.len();
                Force::of(Self::NAME, spring_term(model, material, kept, range))
            }
            BendingModel::Dihedral { stiffness } => {
                let mut b = (kept.iter())
                    .find_map(Force::get::<DihedralBending>)
                    .cloned()
                    .unwrap_or_else(|| DihedralBending::new(model, stiffness));
                b.set_stiffness(stiffness);
                Force::of(Self::NAME, b)
            }
        })
    }

    fn on_gpu(&self) -> Result<(), &'static str> {
        match self {
            BendingModel::Springs | BendingModel::Dihedral { .. } => Ok(()),
        }
    }

    fn suggested(_cloth: &ClothBox) -> Self {
        BendingModel::Springs
    }
}
