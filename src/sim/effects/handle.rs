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

    /// The fastest the cloth it carries can move, sampled over the motion: the
    /// translation's speed plus the spin times the reach, the farthest of its particles or
    /// of the cloth's from the pivot where the motion has it when the limits are derived.
    /// A cloth turned by a few particles near the pivot turns with them, its far edge at
    /// the spin times its own distance (counting only the handle's particles, a 1 m cloth
    /// spun by its middle third was refused at its start by a headroom of 2).
    fn guard(&self, _up: Vec3, cloth: &ClothState) -> GuardShare {
        let own = (self.rest.iter()).map(|r| r.distance(self.pivot));
        let pivot = self.motion.at(cloth.time).apply(self.pivot, self.pivot);
        let carried = (cloth.pos.iter()).map(|x| x.distance(pivot));
        let reach = own
            .chain(carried)
            .filter(|r| r.is_finite())
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

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::sim::motion::{AxisAngle, Ease, Keyframe};

    /// A handle of two particles 0.1 m either side of the origin, moving 1 m along x and
    /// turning 2 rad about y in its one second.
    fn turning_handle() -> Handle {
        let key = |time, translate, degrees| Keyframe {
            time,
            translate: Some(translate),
            rotate: Some(AxisAngle {
                axis: Vec3::Y,
                degrees,
            }),
            ease: Ease::Linear,
        };
        let motion = RigidMotion::new(&[
            key(0.0, Vec3::ZERO, 0.0),
            key(1.0, Vec3::X, 2.0f32.to_degrees()),
        ])
        .unwrap();
        Handle {
            particles: vec![0, 1],
            rest: vec![Vec3::new(-0.1, 0.0, 0.0), Vec3::new(0.1, 0.0, 0.0)],
            pivot: Vec3::ZERO,
            motion,
        }
    }

    /// The cloth a handle carries turns with it, so its surface speed is the translation's
    /// 1 m/s plus the spin times the farthest of the cloth's particles from the pivot
    /// (0.7 m: 2.4 m/s), where the motion has moved the pivot by the time the limits are
    /// derived (from where it was placed, the cloth's far particle is 1.2 m off: 3.4 m/s);
    /// counting the handle's own particles alone it was 1.2 m/s.
    #[test]
    fn a_handle_can_throw_the_cloth_it_carries_at_the_spin_times_the_cloths_reach() {
        let handle = turning_handle();
        let mut cloth = ClothState {
            pos: [-0.1, 0.1, 0.4, 0.7]
                .map(|x| Vec3::new(x, 0.0, 0.0))
                .to_vec(),
            vel: vec![Vec3::ZERO; 4],
            time: 0.0,
        };
        let speed = |cloth: &ClothState| handle.guard(Vec3::Y, cloth).surface_speed;
        assert!((speed(&cloth) - 2.4).abs() < 1e-5, "{}", speed(&cloth));
        // Half-way, everything half a metre along x: the pivot is there too.
        cloth.time = 0.5;
        cloth.pos.iter_mut().for_each(|x| *x += 0.5 * Vec3::X);
        assert!((speed(&cloth) - 2.4).abs() < 1e-5, "{}", speed(&cloth));
        // A cloth no wider than the handle: the handle's own reach.
        cloth.pos.truncate(2);
        assert!((speed(&cloth) - 1.2).abs() < 1e-5, "{}", speed(&cloth));
    }
}
