//! What the stability guard may do: its policy, plain data.

use super::integrator::IntegratorKind;
use super::param_error::ParamError;

/// What the guard may do. Part of [`super::SimParams`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GuardPolicy {
    /// Off: frames are never checked, rolled back or refined (default on).
    pub enabled: bool,
    /// Particle speed limit, m/s. `None` (default) derives it from the scene: `headroom` ×
    /// (free-fall speed over the scene's height + the fastest initial particle + the fastest
    /// collider surface + the wind) + 1 m/s.
    pub max_speed: Option<f32>,
    /// Smallest limit on the relative extension of a spring (default 1: twice its rest
    /// length; cloth stays within a few percent). The limit in force is raised to `headroom`
    /// times the stretch of a structural spring carrying the whole cloth's weight, so soft
    /// chains that really do stretch a lot are not mistaken for blow-ups, and to `headroom`
    /// times the largest stretch when the limits are derived (after a drag or an edit), so
    /// a cloth the user pulls hard is not either.
    pub max_strain: f32,
    /// Safety factor on the speed and kinetic-energy limits derived from the scene (default 4).
    pub headroom: f32,
    /// How many times a failing frame is redone, each time with twice the substeps
    /// (default 3: up to 8×).
    pub max_refinements: u32,
    /// The integrator tried, at the requested substeps, once every refinement failed
    /// (default implicit Euler, stable at any step for the springs); `None` gives up instead.
    pub fallback: Option<IntegratorKind>,
    /// Healthy frames after which raised substeps are halved back towards the request
    /// (default 60, one second at 60 fps; doubled each time a step back down fails soon).
    pub recover_after: u32,
    /// Frames a state must have stayed healthy before it becomes the rollback point
    /// (default 6).
    pub checkpoint_frames: u32,
}

impl Default for GuardPolicy {
    fn default() -> Self {
        Self {
            enabled: true,
            max_speed: None,
            max_strain: 1.0,
            headroom: 4.0,
            max_refinements: 3,
            fallback: Some(IntegratorKind::ImplicitEuler),
            recover_after: 60,
            checkpoint_frames: 6,
        }
    }
}

impl GuardPolicy {
    /// Checks the policy's numbers.
    ///
    /// # Errors
    /// [`ParamError`] naming the bad field.
    pub fn validate(&self) -> Result<(), ParamError> {
        if let Some(v) = self.max_speed
            && !(v.is_finite() && v > 0.0)
        {
            return Err(ParamError::new("guard.max_speed", v, "must be > 0 m/s"));
        }
        for (name, v) in [
            ("guard.max_strain", self.max_strain),
            ("guard.headroom", self.headroom),
        ] {
            ParamError::require(v.is_finite() && v > 0.0, name, v, "must be > 0")?;
        }
        if self.max_refinements > 10 {
            return Err(ParamError::new(
                "guard.max_refinements",
                self.max_refinements,
                "must be at most 10 (1024× the substeps)",
            ));
        }
        for (name, v) in [
            ("guard.recover_after", self.recover_after),
            ("guard.checkpoint_frames", self.checkpoint_frames),
        ] {
            if v == 0 {
                return Err(ParamError::new(name, v, "must be ≥ 1"));
            }
        }
        Ok(())
    }
}
