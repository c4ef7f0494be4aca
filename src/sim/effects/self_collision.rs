//! Self-collision: every particle is kept a thickness away from each triangle it is not a
//! corner of (the solver is `sim/self_contacts.rs`), with friction between layers.

use crate::cloth::ClothModel;
use crate::sim::param_error::ParamError;
use crate::sim::self_contacts::ContactError;

use super::effect_kind::{ClothBox, ContactPass, EffectKind};

/// The cloth's thickness against itself and its friction.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SelfCollision {
    /// Particles are kept this far from every triangle they are not a corner of, metres
    /// (below the cloth's shortest rest edge, which [`SelfCollision::fits`] checks; a
    /// quarter of it is a good start).
    pub thickness: f32,
    /// Coulomb friction between layers (dimensionless).
    pub friction: f32,
}

/// A self-collision thickness the cloth cannot take: at or above its shortest rest edge,
/// every particle would start inside its neighbours' triangles and be pushed off them.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error(
    "self-collision `thickness` = {} m is not below the cloth's shortest rest edge, {} m: \
     every particle would start in contact with its neighbours' triangles and be pushed off \
     them; use at most a quarter of the edge ({} m)",
    significant(*thickness),
    significant(*edge),
    significant(0.25 * edge)
)]
pub struct TooThick {
    /// The thickness asked for, metres.
    pub thickness: f32,
    /// The cloth's shortest rest edge, metres.
    pub edge: f32,
}

/// `x` to three significant digits, without trailing zeros (0.0416666 → "0.0417").
fn significant(x: f32) -> String {
    if !(x.is_finite() && x > 0.0) {
        return x.to_string();
    }
    let decimals = (2 - x.log10().floor() as i32).max(0) as usize;
    let text = format!("{x:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

impl SelfCollision {
    /// Checks the thickness against a cloth whose shortest rest edge is `edge` metres.
    ///
    /// # Errors
    /// [`TooThick`] when the thickness is at or above the edge.
    pub fn fits(&self, edge: f32) -> Result<(), TooThick> {
        if self.thickness >= edge {
            return Err(TooThick {
                thickness: self.thickness,
                edge,
            });
        }
        Ok(())
    }
}

/// The shortest rest length among the cloth's mesh edges, metres (infinite without edges).
pub fn shortest_edge(model: &ClothModel) -> f32 {
    (model.edge_rest_lengths().iter()).fold(f32::INFINITY, |m, &r| m.min(r))
}

impl Default for SelfCollision {
    fn default() -> Self {
        Self {
            thickness: 0.01,
            friction: 0.3,
        }
    }
}

impl EffectKind for SelfCollision {
    const NAME: &'static str = "self-collision";
    const TITLE: &'static str = "Self-collision";
    const MANY: bool = false;
    const ADDABLE: bool = true;

    fn check(&self) -> Result<(), ParamError> {
        ParamError::require(
            self.thickness.is_finite() && self.thickness > 0.0,
            "thickness",
            self.thickness,
            "must be positive metres",
        )?;
        ParamError::require(
            self.friction.is_finite() && self.friction >= 0.0,
            "friction",
            self.friction,
            "must be ≥ 0",
        )
    }

    fn is_contact(&self) -> bool {
        true
    }

    fn resolve(&self, pass: &mut ContactPass<'_>) -> Result<usize, ContactError> {
        let (model, start) = (pass.model, pass.start);
        let settings = [self.thickness, self.friction];
        (pass.self_contacts).resolve(settings, model, start, pass.state)
    }

    fn on_gpu(&self) -> Result<(), &'static str> {
        Ok(())
    }

    /// Well under the shortest edge (a quarter of it, at most 5 cm), so neighbours are not
    /// pushed apart.
    fn suggested(cloth: &ClothBox) -> Self {
        SelfCollision {
            thickness: (0.25 * cloth.shortest_edge).min(0.05),
            ..SelfCollision::default()
        }
    }
}
