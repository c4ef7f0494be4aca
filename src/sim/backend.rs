//! The step-backend seam: [`crate::scene::Simulation`] advances through this interface,
//! whatever computes the steps (the CPU stepper today, a GPU stepper beside it).

use crate::cloth::{ClothModel, ClothState};

use super::effects::Effect;
use super::guard::{Diverged, FrameOutcome, GuardEvent};
use super::integrator::{IntegratorKind, StepError, StepReport};
use super::params::{Changes, SimParams};
use super::stats::StepStats;
use super::timings::PhaseTimings;

/// Something that advances a cloth state through time.
pub trait StepBackend: Send {
    /// Short name for the UI and reports ("cpu", "gpu").
    fn name(&self) -> &'static str;

    /// Applies new parameters and effects to the running backend; `changes` says which
    /// parts are new ([`Changes::all`] for a backend that has seen none), and only what
    /// depends on them is redone (the substeps the guard raised stay unless the requested
    /// count changed; timings and statistics stay). The state is not the caller's to hand
    /// over here: a backend that holds a copy of it keeps stepping that copy until
    /// [`StepBackend::invalidate`].
    fn configure(
        &mut self,
        model: &ClothModel,
        params: &SimParams,
        effects: &[Effect],
        changes: Changes,
    );

    /// The state or the model changed outside stepping (reset, pins, density, a drag):
    /// whatever was kept from earlier steps is dropped.
    fn invalidate(&mut self);

    /// The run starts over from a state of its own (a reset): as
    /// [`StepBackend::invalidate`], and whatever of the run steers how later frames are
    /// stepped is dropped too (substeps the guard raised, its counters and events, the
    /// contacts' search memory), so that the run steps as a new backend would. By default
    /// only `invalidate`.
    fn restart(&mut self) {
        self.invalidate();
    }

    /// Pinned `particle` (the held one of a grab) was moved outside the substeps, from
    /// `from` to where the state has it: the next [`StepBackend::frame`] takes that move
    /// as part of its first substep's motion, so that the contacts see it (self-contact
    /// cuts what it would cross and counts the pairs it forces). It holds for that call
    /// alone (or the next [`StepBackend::substep`]). By default nothing: the move is not
    /// seen.
    fn moved_outside(&mut self, _particle: u32, _from: glam::Vec3) {}

    /// One frame of `params.step.dt` seconds, under the stability guard.
    ///
    /// # Errors
    /// [`Diverged`] when no try succeeded; `state` is then the frame's start state.
    fn frame(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
    ) -> Result<FrameOutcome, Diverged>;

    /// One substep without the guard (tests, tools that inspect every substep).
    ///
    /// # Errors
    /// The integrator's [`StepError`].
    fn substep(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
    ) -> Result<StepReport, StepError>;

    /// Substeps per frame in effect (the guard may have raised the requested count).
    fn substeps(&self) -> u32;

    /// Length of the substep in effect, seconds.
    fn substep_length(&self) -> f32;

    /// Wall time per phase since the last call; resets it.
    fn take_timings(&mut self) -> PhaseTimings;

    /// Work counters since the last call; resets them.
    fn take_stats(&mut self) -> StepStats;

    /// What the stability guard did since the last call (nothing, for a backend without one).
    fn take_guard_events(&mut self) -> Vec<GuardEvent> {
        Vec::new()
    }

    /// The integrator in effect (the guard's fallback may have replaced the requested one).
    fn integrator(&self) -> IntegratorKind;

    /// The work of the last self-collision pass, when the scene has self-collision.
    fn self_collision_work(&self) -> Option<super::self_contacts::SelfWork> {
        None
    }

    /// The pairs of the cloth prescribed motion forced together (self-contact could cut
    /// no particle of theirs) over the substeps that stand, when the scene has
    /// self-collision: [`SelfWork::forced_total`](super::self_contacts::SelfWork) by
    /// default.
    fn forced_pairs(&self) -> Option<u64> {
        self.self_collision_work().map(|w| w.forced_total)
    }

    /// Makes `state` and a copy the backend keeps elsewhere (a GPU buffer) agree: the copy
    /// is read back when it stepped since they last agreed, or replaced by `state` when
    /// that is the newer one (after [`StepBackend::invalidate`] or
    /// [`StepBackend::configure`]). Backends that step `state` in place have nothing to do.
    ///
    /// # Errors
    /// [`StepError::Device`] when the copy could not be read; `state` is then unchanged.
    fn sync(&mut self, _model: &ClothModel, _state: &mut ClothState) -> Result<(), StepError> {
        Ok(())
    }

    /// The positions in the precision the backend steps them in, widened to `f64`, into
    /// `out`; false, with `out` untouched, when the caller's state holds them all (an `f32`
    /// backend, or a state changed since the backend stepped it).
    fn positions_f64(&self, _out: &mut Vec<glam::DVec3>) -> bool {
        false
    }

    /// Whether the backend's own copy has stepped past `state` (a [`StepBackend::sync`]
    /// would read it back).
    fn state_behind(&self) -> bool {
        false
    }

    /// CPU threads that may step the cloth: the members of the team the current rayon pool
    /// picks ([`crate::parallel::Team::current`], at most 16; a cloth too small to share steps
    /// on the caller alone) for a backend that steps on the CPU; a backend that only records
    /// and submits a device's work uses the one thread that calls it.
    fn cpu_threads(&self) -> usize {
        crate::parallel::Team::current().members()
    }
}
