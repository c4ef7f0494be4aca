//! Effects are data: a scene lists the ones it uses and the stepper runs only those.

use super::collider::Collider;

/// One physical effect a scene can switch on. Forces take their strengths from
/// [`super::SimParams`]; colliders carry their own geometry.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Effect {
    Gravity,
    Springs,
    AirDamping,
    Collider(Collider),
}
