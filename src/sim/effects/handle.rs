//! A handle: particles carried exactly along a keyframed rigid motion (moving pins). A scene
//! file gives them as `[[handles]]`; the scene makes each an effect of its particles.

use glam::Vec3;

use super::effect_kind::{ClothBox, ContactPass, EffectKind, GuardShare};
use crate::cloth::ClothState;
use crate::sim::motion::RigidMotion;
use crate::sim::self_contacts::ContactError;

/// Particles that follow a rigid motion about `pivot`: after every substep each is where
/// the motion puts its place at the start, moving as the motion moves it. A particle the
/// user has freed (the *Pins* switch off, or unpinned by hand) is left to the cloth.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Handle {
    pub particles: Vec<u32>,
    /// Where each was at the start, metres.
    pub rest: Vec<Vec3>,
    pub pivot: Vec3,
    pub motion: RigidMotion,
}

impl Handle {
    /// Puts every handled particle that is pinned (inverse mass 0) where the motion has it at
    /// `state.time`, with the motion's velocity there. Returns how many it placed.
    pub fn place(&self, inv_mass: &[f32], state: &mut ClothState) -> usize {
        let pose = self.motion.at(state.time);
        let mut placed = 0;
        for (&p, &rest) in self.particles.iter().zip(&self.rest) {
            let p = p as usize;
            if inv_mass.get(p).is_none_or(|&w| w != 0.0) || p >= state.pos.len() {
                continue;
            }
            let at = pose.apply(self.pivot, rest);
            state.pos[p] = at;
            state.vel[p] = pose.velocity_at(self.pivot, at);
            placed += 1;
        }
        placed
    }
}

impl EffectKind for Handle {
    const NAME: &'static str = "handle";
    const TITLE: &'static str = "Handle (moving pins)";
    const MANY: bool = true;
    const ADDABLE: bool = false;

    fn is_contact(&self) -> bool {
        true
    }

    /// Places the handled particles where the motion has them at the substep's end.
    fn resolve(&self, pass: &mut ContactPass<'_>) -> Result<usize, ContactError> {
        Ok(self.place(&pass.model.inv_mass, pass.state))
    }

    /// The fastest a handled particle moves: sampled over the motion.
    fn guard(&self, _up: Vec3) -> GuardShare {
        let reach = (self.rest.iter())
            .map(|r| r.distance(self.pivot))
            .fold(0.0f32, f32::max);
        let end = self.motion.end();
        let surface_speed = (0..=256)
            .map(|i| self.motion.at(end * i as f64 / 256.0))
            .map(|pose| pose.velocity.length() + pose.spin.length() * reach)
            .fold(0.0f32, f32::max);
        GuardShare {
            surface_speed,
            ..GuardShare::default()
        }
    }

    fn on_gpu(&self) -> Result<(), &'static str> {
        Ok(())
    }

    fn suggested(_cloth: &ClothBox) -> Self {
        Self::default()
    }
}
