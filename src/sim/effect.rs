//! Effects are data: a scene lists the ones it uses and the stepper runs only those.

use super::collider::Collider;
use super::forces::Wind;
use super::self_collision::{SelfCollision, TooThick, shortest_edge};
use crate::cloth::ClothModel;

/// How a cloth resists bending.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BendingModel {
    /// Springs between the vertices opposite each interior edge, of the bend stiffness in
    /// [`super::SimParams::stiffness`] (N/m).
    Springs,
    /// Dihedral-angle bending (discrete shells) with this stiffness, N·m.
    Dihedral { stiffness: f32 },
}

/// One physical effect a scene can switch on. Gravity, the springs and air damping take
/// their strengths from [`super::SimParams`]; the others carry their own.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Effect {
    Gravity,
    /// The cloth's structural and shear springs.
    Springs,
    AirDamping,
    Bending(BendingModel),
    Wind(Wind),
    SelfCollision(SelfCollision),
    Collider(Collider),
}

impl Effect {
    /// The name of the effect's phase in timings (`simulate --json`'s `phases`).
    pub fn phase(&self) -> &'static str {
        match self {
            Effect::Gravity => "gravity",
            Effect::Springs => "springs",
            Effect::AirDamping => "air-damping",
            Effect::Bending(_) => "bending",
            Effect::Wind(_) => "wind",
            Effect::SelfCollision(_) => "self-collision",
            Effect::Collider(c) => c.phase(),
        }
    }
}

/// The wind among `effects`, if any.
pub fn wind_of(effects: &[Effect]) -> Option<Wind> {
    effects.iter().find_map(|e| match e {
        Effect::Wind(w) => Some(*w),
        _ => None,
    })
}

/// Checks every self-collision among `effects` against `model`'s shortest rest edge.
///
/// # Errors
/// [`TooThick`] for a thickness at or above it.
pub fn thickness_fits(effects: &[Effect], model: &ClothModel) -> Result<(), TooThick> {
    let edge = shortest_edge(model);
    effects.iter().try_for_each(|e| match e {
        Effect::SelfCollision(s) => s.fits(edge),
        _ => Ok(()),
    })
}

/// The colliders among `effects`, in order.
pub fn colliders_of(effects: &[Effect]) -> Vec<Collider> {
    effects
        .iter()
        .filter_map(|e| match e {
            Effect::Collider(c) => Some(*c),
            _ => None,
        })
        .collect()
}
