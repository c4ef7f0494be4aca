//! The stability guard: what counts as a frame going wrong (limits derived from the scene),
//! what the guard may do about it (a policy that is plain data), and the record it keeps.

use glam::Vec3;

use crate::cloth::{ClothModel, ClothState, Real};
use crate::mesh::{SpringKind, bounds};

use super::diagnosis::Cause;
use super::effects::{Effect, Gravity};
use super::forces::ForceSet;
use super::guard_policy::GuardPolicy;
use super::integrator::{IntegratorKind, StepError};
use super::self_contacts::ContactError;
use crate::parallel::wide;

/// The limits a healthy frame stays within, derived from the scene.
///
/// The speed and kinetic-energy limits grow with how far the cloth has fallen below the
/// lowest point they counted on (the cloth's own bottom or the lowest collider under it):
/// gravity legitimately turns that height into motion, so a free fall of any length is never
/// taken for a blow-up, while a blow-up, whose speeds grow far faster than a fall's, is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuardLimits {
    /// m/s, before any fall below `floor` (fixed when the policy gives `max_speed`).
    pub speed: f32,
    /// Relative extension.
    pub strain: f32,
    /// Joules, before any fall below `floor`.
    pub kinetic_energy: f64,
    /// Unit vector against gravity (+y without gravity).
    pub up: Vec3,
    /// Height along `up` (m) of the lowest point the limits counted on.
    pub floor: f32,
    /// How the limits grow with the depth fallen below `floor`.
    fall: Fall,
}

/// What a fall below the floor adds to the limits.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Fall {
    /// |g|, m/s².
    gravity: f32,
    /// Mass of the free particles, kg.
    mass: f64,
    headroom: f32,
    /// The height the derived speed limit lets the cloth fall, m, and the rest of its
    /// speed (thrown, dragged, flung), m/s; `None` when the policy fixes the speed.
    derived_speed: Option<(f32, f32)>,
}

/// The bits of `f32::INFINITY`: a magnitude's bits at or above it are an infinity or NaN.
const INFINITY_BITS: u32 = 0x7f80_0000;

/// The largest magnitude among `values`, as IEEE bits without the sign (an integer
/// maximum: no order to keep, so the loop vectorises).
#[inline(always)]
fn largest_magnitude_bits(values: &[f32]) -> u32 {
    values
        .iter()
        .fold(0u32, |m, v| m.max(v.to_bits() & 0x7fff_ffff))
}

/// One pass over the state: what the checks need (measured here on the CPU, or by a
/// reduction on the device for the GPU backend).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// Every position and velocity is finite.
    pub finite: bool,
    /// Fastest particle, m/s.
    pub speed: f32,
    /// Kinetic energy, joules.
    pub joules: f64,
    /// Lowest particle's height along the limits' `up`, m.
    pub lowest: f32,
}

impl Motion {
    /// Measures `state` of `model`, heights along `up`.
    pub fn of(model: &ClothModel, state: &ClothState, up: Vec3) -> Self {
        let mut m = Motion {
            finite: true,
            speed: 0.0,
            joules: 0.0,
            lowest: f32::INFINITY,
        };
        let mut fastest = 0.0f32;
        for ((x, v), &mass) in state.pos.iter().zip(&state.vel).zip(&model.mass) {
            m.finite &= x.is_finite() && v.is_finite();
            let v2 = v.length_squared();
            fastest = fastest.max(v2);
            m.joules += 0.5 * mass as f64 * v2 as f64;
            m.lowest = m.lowest.min(up.dot(*x));
        }
        m.speed = fastest.sqrt();
        m
    }
}

impl GuardLimits {
    /// Limits for `state` of `model` under `gravity` with the spring terms of `forces`,
    /// among `effects` (their solids' lowest points and fastest surfaces, the fastest
    /// wind): the speeds and energy the scene can reach by falling, being thrown, being
    /// dragged or springing back from the stretch it has, and the larger of the stretch of
    /// a structural spring carrying the whole weight and the largest stretch it has, times
    /// the policy's headroom. `stepped` is `state`'s positions in the precision `forces`
    /// compute in (the energy stored in the springs is theirs).
    pub fn derive<R: Real>(
        policy: &GuardPolicy,
        model: &ClothModel,
        (state, stepped): (&ClothState, &[R::V3]),
        gravity: Vec3,
        forces: &ForceSet<R>,
        effects: &[Effect],
    ) -> Self {
        let g = gravity.length();
        let up = if g > 0.0 { -gravity / g } else { Vec3::Y };
        let (lo, hi) = bounds(&state.pos);
        let lowest = (state.pos.iter()).fold(f32::INFINITY, |m, x| m.min(up.dot(*x)));
        let lowest = if lowest.is_finite() { lowest } else { 0.0 };
        let mut bottom = lowest;
        let (mut surface, mut wind) = (0.0f32, 0.0f32);
        for share in effects.iter().map(|e| e.guard(up, state)) {
            if let Some(floor) = share.floor {
                bottom = bottom.min(floor);
            }
            surface = surface.max(share.surface_speed);
            wind = wind.max(share.flow_speed);
        }
        // The cloth can fall its own size plus down to the lowest thing below it.
        let height = (hi - lo).length() + (lowest - bottom).max(0.0);
        let fall = (2.0 * g * height).sqrt();
        let pushed = state.max_speed() + surface + wind;
        let free = || (model.mass.iter().zip(&model.inv_mass)).filter(|(_, w)| **w > 0.0);
        let mass: f64 = free().map(|(m, _)| *m as f64).sum();
        // What the frame starts with is the user's doing (a drag, an edit, the scene as
        // loaded), never the integrator's: the springs' stretch and the energy stored in it
        // count as reachable, and a stretched cloth let go can fling its lightest particle
        // at up to the speed that energy gives it.
        let elastic = stored_energy(model, forces, stepped);
        let lightest = free().map(|(m, _)| *m).fold(f32::INFINITY, f32::min);
        let flung = if lightest > 0.0 && lightest.is_finite() {
            (2.0 * elastic / lightest as f64).sqrt() as f32
        } else {
            0.0
        };
        let speed = policy
            .max_speed
            .unwrap_or(policy.headroom * (fall + pushed + flung) + 1.0);
        let available = state.kinetic_energy(model)
            + elastic
            + mass * g as f64 * height as f64
            + 0.5 * mass * (pushed as f64).powi(2);
        let weight = mass as f32 * g;
        Self {
            speed,
            strain: policy
                .max_strain
                .max(policy.headroom * weight_strain(model, forces, weight))
                .max(policy.headroom * model.springs.largest_strain(&state.pos)),
            kinetic_energy: policy.headroom as f64 * available + 1e-9,
            up,
            floor: bottom,
            fall: Fall {
                gravity: g,
                mass,
                headroom: policy.headroom,
                derived_speed: policy
                    .max_speed
                    .is_none()
                    .then_some((height, pushed + flung)),
            },
        }
    }

    /// The speed limit (m/s) once the cloth's lowest point is `depth` metres below the floor.
    pub fn speed_at(&self, depth: f32) -> f32 {
        match self.fall.derived_speed {
            Some((height, rest)) if depth > 0.0 => {
                let fall = (2.0 * self.fall.gravity * (height + depth)).sqrt();
                self.fall.headroom * (fall + rest) + 1.0
            }
            _ => self.speed,
        }
    }

    /// The kinetic-energy limit (J) once the cloth's lowest point is `depth` metres below
    /// the floor: the potential energy such a fall releases, with the headroom, is added.
    pub fn kinetic_energy_at(&self, depth: f32) -> f64 {
        let released = self.fall.mass * self.fall.gravity as f64 * depth.max(0.0) as f64;
        self.kinetic_energy + self.fall.headroom as f64 * released
    }

    /// How far `state`'s lowest particle is below the floor, m (0 above it).
    pub fn depth_of(&self, state: &ClothState) -> f32 {
        let lowest = (state.pos.iter()).fold(f32::INFINITY, |m, x| m.min(self.up.dot(*x)));
        (self.floor - lowest).max(0.0)
    }

    /// The limits one substep must keep, checked before anything reads positions to decide
    /// its work (contact detection), with the cloth at least `depth` metres below the floor
    /// (its depth at the frame's start; it only grows in a fall). A cheap bound first: the
    /// largest velocity component's magnitude times √3 is at least the fastest speed, and
    /// an integer maximum over the values' bits (order-free, so it vectorises) is at or
    /// above the bits of infinity for a non-finite one. Only when that bound alarms is the
    /// state measured exactly, for finiteness, speed and kinetic energy; the strain is left
    /// to [`check`] at the frame's end.
    pub fn check_substep(
        &self,
        model: &ClothModel,
        state: &ClothState,
        depth: f32,
    ) -> Option<Trouble> {
        let (vel, pos) = wide(|| {
            (
                largest_magnitude_bits(bytemuck::cast_slice(&state.vel)),
                largest_magnitude_bits(bytemuck::cast_slice(&state.pos)),
            )
        });
        // Slightly above √3, so rounding cannot put the bound under the speed.
        let bound = 1.7321 * f32::from_bits(vel);
        if vel < INFINITY_BITS && pos < INFINITY_BITS && bound <= self.speed_at(depth) {
            return None;
        }
        let motion = Motion::of(model, state, self.up);
        self.motion_trouble(&motion)
            .or_else(|| self.energy_trouble(&motion))
    }

    /// The limits with `trouble`'s speed or kinetic energy counted as reachable, for the
    /// frame that crossed them to be redone against: `headroom` × the speed reached in
    /// place of the thrown, dragged or flung part of the speed limit (so a deeper fall still
    /// adds to it), or `headroom` × the energy reached. `None` for what motion cannot explain
    /// (a non-finite state, a stretch, a solver's failure), for a speed the policy fixed,
    /// and under an `integrator` that gains energy at every step
    /// ([`IntegratorKind::gains_energy`]: a blow-up as slow as the step makes it).
    pub fn admitting(&self, trouble: &Trouble, integrator: IntegratorKind) -> Option<Self> {
        if integrator.gains_energy() {
            return None;
        }
        let mut raised = *self;
        match *trouble {
            Trouble::Speed { speed, .. } => {
                let (height, rest) = self.fall.derived_speed?;
                let rest = rest.max(speed);
                raised.fall.derived_speed = Some((height, rest));
                let fall = (2.0 * self.fall.gravity * height).sqrt();
                raised.speed = self.fall.headroom * (fall + rest) + 1.0;
            }
            Trouble::KineticEnergy { joules, .. } => {
                raised.kinetic_energy =
                    (self.fall.headroom as f64 * joules).max(self.kinetic_energy);
            }
            _ => return None,
        }
        Some(raised)
    }

    /// How far the lowest particle is below the floor, m (0 above it).
    fn depth(&self, motion: &Motion) -> f32 {
        (self.floor - motion.lowest).max(0.0)
    }

    fn motion_trouble(&self, motion: &Motion) -> Option<Trouble> {
        if !motion.finite {
            return Some(Trouble::NonFinite);
        }
        let limit = self.speed_at(self.depth(motion));
        (motion.speed > limit).then_some(Trouble::Speed {
            speed: motion.speed,
            limit,
        })
    }

    fn energy_trouble(&self, motion: &Motion) -> Option<Trouble> {
        let limit = self.kinetic_energy_at(self.depth(motion));
        (motion.joules > limit).then_some(Trouble::KineticEnergy {
            joules: motion.joules,
            limit,
        })
    }
}

/// The energy stored in the cloth at `pos`, joules: every conservative term's but gravity's
/// (the height the cloth can fall accounts for that), so the springs' and the hinges'.
fn stored_energy<R: Real>(model: &ClothModel, forces: &ForceSet<R>, pos: &[R::V3]) -> f64 {
    (forces.terms().iter())
        .filter(|t| t.get::<Gravity>().is_none())
        .map(|t| t.potential_energy(model, pos))
        .sum()
}

/// Relative stretch of the weakest structural spring (the smallest k·l) pulled by `weight`
/// newtons; 0 without structural springs of positive stiffness.
fn weight_strain<R: Real>(model: &ClothModel, forces: &ForceSet<R>, weight: f32) -> f32 {
    let s = &model.springs;
    let weakest = (forces.springs().flat_map(|t| t.each()))
        .filter(|&(e, _, _)| s.kind[e] == SpringKind::Structural)
        .map(|(e, k, _)| k * s.rest[e])
        .fold(f32::INFINITY, f32::min);
    if weakest.is_finite() && weakest > 0.0 {
        weight / weakest
    } else {
        0.0
    }
}

/// What went wrong in a frame.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Trouble {
    NonFinite,
    Speed { speed: f32, limit: f32 },
    Strain { strain: f32, limit: f32 },
    KineticEnergy { joules: f64, limit: f64 },
    Solver { detail: String },
}

impl std::fmt::Display for Trouble {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Trouble::NonFinite => write!(f, "a position or velocity became non-finite"),
            Trouble::Speed { speed, limit } => {
                write!(
                    f,
                    "a particle reached {speed:.1} m/s (limit {limit:.1} m/s)"
                )
            }
            Trouble::Strain { strain, limit } => write!(
                f,
                "a spring stretched by {:.0} % (limit {:.0} %)",
                100.0 * strain,
                100.0 * limit
            ),
            Trouble::KineticEnergy { joules, limit } => {
                write!(
                    f,
                    "kinetic energy reached {joules:.3e} J (limit {limit:.3e} J)"
                )
            }
            Trouble::Solver { detail } => write!(f, "{detail}"),
        }
    }
}

impl From<StepError> for Trouble {
    /// A spring self-contact found stretched past the limit is the strain the frame's end
    /// would have judged; anything else the step refused, a solver's trouble.
    fn from(e: StepError) -> Self {
        match e {
            StepError::Contact(ContactError::Stretched { strain, limit, .. }) => {
                Trouble::Strain { strain, limit }
            }
            e => Trouble::Solver {
                detail: e.to_string(),
            },
        }
    }
}

/// How far apart, as a fraction of the fastest particle's speed, the velocities at a
/// frame's end may be when the frame is stepped with the substeps in effect and with twice
/// as many, for its motion to count as resolved by the step.
pub const RESOLVED: f32 = 0.1;

/// Whether `coarse` and `fine`, the velocities at the end of one frame stepped with the
/// substeps in effect and with twice as many, agree as motion the step resolves does: every
/// particle's two velocities within [`RESOLVED`] of the fastest speed in either. A
/// first-order method's error halves with the step, so the two differ by about the coarse
/// one's error; an instability grows with the step instead, so the two differ by about its
/// size (the whip of a flag's corner at 62 m/s: 0.7 m/s apart; a cloth beyond its
/// integrator's step: its whole speed, or not finite).
pub fn resolved(coarse: &[Vec3], fine: &[Vec3]) -> bool {
    let finite = coarse.iter().chain(fine).all(|v| v.is_finite());
    let fastest = (coarse.iter().chain(fine)).fold(0.0f32, |m, v| m.max(v.length()));
    let apart = (coarse.iter().zip(fine)).fold(0.0f32, |m, (a, b)| m.max(a.distance(*b)));
    finite && coarse.len() == fine.len() && apart <= RESOLVED * fastest
}

/// The first limit `state` breaks, if any: non-finite, speed, strain, kinetic energy.
pub fn check(model: &ClothModel, state: &ClothState, limits: &GuardLimits) -> Option<Trouble> {
    limits.judge(&Motion::of(model, state, limits.up), || {
        model.springs.largest_strain(&state.pos)
    })
}

impl GuardLimits {
    /// The first limit a state with `motion` and the largest relative spring extension
    /// `strain` (asked for only once the motion passed) breaks, in [`check`]'s order.
    pub fn judge(&self, motion: &Motion, strain: impl FnOnce() -> f32) -> Option<Trouble> {
        if let Some(trouble) = self.motion_trouble(motion) {
            return Some(trouble);
        }
        let strain = strain();
        if strain > self.strain {
            return Some(Trouble::Strain {
                strain,
                limit: self.strain,
            });
        }
        self.energy_trouble(motion)
    }
}

/// What the guard did.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum GuardAction {
    /// Rolled back and redone with more substeps, which stay for now.
    Refined,
    /// Every refinement failed; redone with the fallback integrator, which stays.
    FellBack { integrator: IntegratorKind },
    /// A speed or kinetic-energy limit was crossed by motion the step resolves (the frame
    /// at twice the substeps agreed with it: [`resolved`]); the frame stands and the limits
    /// are raised to these, m/s and joules.
    Raised { speed: f32, joules: f64 },
    /// After a run of healthy frames the substeps came back down.
    Recovered,
    /// Nothing helped: the state is the last good one and the run stops.
    GaveUp,
}

/// One thing the guard did, for `simulate --json` and the app.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct GuardEvent {
    /// Simulated time of the frame it happened in, seconds.
    pub time: f64,
    /// What went wrong (absent for a recovery).
    pub reason: Option<String>,
    pub action: GuardAction,
    pub substeps_before: u32,
    pub substeps_after: u32,
}

impl std::fmt::Display for GuardEvent {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let why = self.reason.as_deref().unwrap_or("");
        let (a, b) = (self.substeps_before, self.substeps_after);
        match &self.action {
            GuardAction::Refined => write!(
                f,
                "t = {:.2} s: {why}; rolled back and redone with {b} substeps per frame (was {a})",
                self.time
            ),
            GuardAction::FellBack { integrator } => write!(
                f,
                "t = {:.2} s: {why}; more substeps did not help, so the frame was redone with {} at {b} substeps",
                self.time,
                integrator.label()
            ),
            GuardAction::Raised { speed, joules } => write!(
                f,
                "t = {:.2} s: {why}; twice the substeps agree, so it is the scene's motion: the frame stands, and the limits are now {speed:.1} m/s and {joules:.1} J",
                self.time
            ),
            GuardAction::Recovered => write!(
                f,
                "t = {:.2} s: the trouble has passed; substeps back down from {a} to {b} per frame",
                self.time
            ),
            GuardAction::GaveUp => write!(
                f,
                "t = {:.2} s: {why}; nothing saved the frame, the last good state is kept",
                self.time
            ),
        }
    }
}

/// A frame no try could make healthy; the state is left at the frame's start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "the simulation diverged at t = {time:.3} s ({reason}) even with {substeps} substeps per \
     frame{fallback}; the state was rolled back to the last good frame. {cause}"
)]
pub struct Diverged {
    pub time: f64,
    pub reason: String,
    pub substeps: u32,
    /// ", and with the fallback integrator" when it was tried.
    pub fallback: String,
    /// What the guard can see behind it, with what to do.
    pub cause: Cause,
}

/// What happened in a frame that succeeded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameOutcome {
    /// Advanced normally.
    Stepped,
    /// A try failed; the frame was redone with more substeps, which stay for now.
    Refined { from: u32, to: u32 },
    /// Refinement failed; the frame was redone with the fallback integrator, which stays.
    FellBack { integrator: IntegratorKind },
    /// The substeps came back down towards the request after a run of healthy frames.
    Recovered { from: u32, to: u32 },
}
