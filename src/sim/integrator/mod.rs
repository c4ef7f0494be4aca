//! Time integrators. All share one signature ([`Integrator`]); the UI and CLI pick one by
//! [`IntegratorKind`]. Each integrator owns its scratch buffers.

mod semi_implicit_euler;
mod velocity_verlet;

pub use semi_implicit_euler::SemiImplicitEuler;
pub use velocity_verlet::VelocityVerlet;

use crate::cloth::{ClothModel, ClothState};

use super::forces::ForceSet;
use super::timings::PhaseTimings;

/// What an integrator needs besides the state: the model, the forces, and where to charge
/// force-evaluation time.
pub struct StepContext<'a> {
    pub model: &'a ClothModel,
    pub forces: &'a ForceSet,
    pub timings: &'a mut PhaseTimings,
}

impl StepContext<'_> {
    /// Evaluates all forces into `acc`, charging the time to the "forces" phase.
    pub fn acceleration(
        &mut self,
        pos: &[glam::Vec3],
        vel: &[glam::Vec3],
        acc: &mut Vec<glam::Vec3>,
    ) {
        let (model, forces) = (self.model, self.forces);
        self.timings
            .time("forces", || forces.acceleration(model, pos, vel, acc));
    }
}

/// Advances a cloth state by one substep of `h` seconds.
///
/// Contract: afterwards `state.prev_pos` holds the positions before the step, `state.vel`
/// the velocities at the new time, `state.time` is advanced by `h`, and particles with
/// inverse mass 0 have not moved.
pub trait Integrator: Send {
    fn kind(&self) -> IntegratorKind;
    fn step(&mut self, ctx: &mut StepContext<'_>, state: &mut ClothState, h: f32);
}

/// The integrators a user can choose.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum IntegratorKind {
    /// Symplectic Euler: `v += a·h; x += v·h`. First order, one force evaluation, bounded
    /// energy error for conservative forces.
    SemiImplicitEuler,
    /// Velocity Verlet: `x += v·h + ½a·h²; v += ½(a + a')·h`. Second order, symplectic, one
    /// force evaluation per step (the new acceleration is reused by the next step).
    Verlet,
}

impl IntegratorKind {
    pub const ALL: [IntegratorKind; 2] =
        [IntegratorKind::SemiImplicitEuler, IntegratorKind::Verlet];

    /// The name the CLI accepts and JSON prints.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::SemiImplicitEuler => "semi-implicit-euler",
            IntegratorKind::Verlet => "verlet",
        }
    }

    /// Human-readable label for the UI.
    pub fn label(self) -> &'static str {
        match self {
            IntegratorKind::SemiImplicitEuler => "Semi-implicit Euler",
            IntegratorKind::Verlet => "Velocity Verlet",
        }
    }

    /// A fresh integrator of this kind.
    pub fn build(self) -> Box<dyn Integrator> {
        match self {
            IntegratorKind::SemiImplicitEuler => Box::new(SemiImplicitEuler::default()),
            IntegratorKind::Verlet => Box::new(VelocityVerlet::default()),
        }
    }
}

impl std::fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for IntegratorKind {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let wanted = s.trim().to_ascii_lowercase().replace('_', "-");
        Self::ALL
            .into_iter()
            .find(|k| k.name() == wanted || (wanted == "euler" && *k == Self::SemiImplicitEuler))
            .ok_or_else(|| {
                let names: Vec<_> = Self::ALL.iter().map(|k| k.name()).collect();
                format!(
                    "unknown integrator `{s}`; choose one of: {}",
                    names.join(", ")
                )
            })
    }
}
