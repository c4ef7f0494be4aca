//! The guard's rescue of a frame that broke a limit: the replays from the rollback point,
//! with more substeps, then with the fallback integrator; the admission of motion the step
//! resolves; the record of what it did.

use crate::cloth::{ClothModel, ClothState, Real};

use super::super::guard::{Diverged, FrameOutcome, GuardAction, Trouble, resolved};
use super::super::guard_state::CpuSnapshot;
use super::super::precise_state::f32_view;
use super::CpuStepper;

impl<R: Real> CpuStepper<R> {
    /// Replays from the rollback point to `end` at the substeps in effect.
    fn replay(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState<R>,
        end: f64,
    ) -> Result<(), Trouble> {
        let from = self
            .guard
            .checkpoint
            .clone()
            .unwrap_or_else(|| self.frame_start.clone());
        self.restore(&from, state);
        self.integrator.invalidate();
        let frames = ((end - state.time) / self.dt as f64).round().max(1.0) as u32;
        for k in 1..=frames {
            let frame_end = if k == frames {
                end
            } else {
                from.state.time + k as f64 * self.dt as f64
            };
            self.try_frame(model, state, frame_end)?;
        }
        Ok(())
    }

    /// Puts `state` back at the rollback point `kept`, with what the run had counted there.
    fn restore(&mut self, kept: &CpuSnapshot<R>, state: &mut ClothState<R>) {
        state.clone_from(&kept.state);
        self.self_contacts.work.forced_total = kept.forced;
    }

    /// Puts `state` back at the frame's start; what the integrator kept is stale.
    fn back_to_frame_start(&mut self, state: &mut ClothState<R>) {
        let start = std::mem::take(&mut self.frame_start);
        self.restore(&start, state);
        self.frame_start = start;
        self.integrator.invalidate();
    }

    pub(super) fn record(
        &mut self,
        time: f64,
        reason: Option<&Trouble>,
        action: GuardAction,
        before: u32,
    ) {
        let after = self.substeps;
        self.guard.record(time, reason, action, (before, after));
    }

    /// A frame failed with `trouble`: roll back and redo it with more substeps, then with
    /// the fallback integrator; else restore the frame's start.
    pub(super) fn rescue(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState<R>,
        end: f64,
        trouble: Trouble,
    ) -> Result<FrameOutcome, Diverged> {
        if let Some(outcome) = self.admit(model, state, end, &trouble) {
            return Ok(outcome);
        }
        self.guard.failed_frame();
        let before = self.substeps;
        let mut last = trouble;
        let refinements = self.guard.policy.max_refinements;
        if self.replay_doubling(
            model,
            state,
            end,
            (before.saturating_mul(2), refinements),
            &mut last,
        ) {
            self.record(end, Some(&last), GuardAction::Refined, before);
            return Ok(FrameOutcome::Refined {
                from: before,
                to: self.substeps,
            });
        }
        let tried = self.substeps;
        let (mut fallback, mut fell_back) = (String::new(), None);
        if let Some(kind) = self.guard.policy.fallback
            && kind != self.integrator.kind()
        {
            let original = std::mem::replace(&mut self.integrator, kind.build());
            // At the requested substeps, then refined as the integrator asked for was.
            let tries = (self.requested, refinements + 1);
            if self.replay_doubling(model, state, end, tries, &mut last) {
                let action = GuardAction::FellBack { integrator: kind };
                self.record(end, Some(&last), action, before);
                return Ok(FrameOutcome::FellBack { integrator: kind });
            }
            self.integrator = original;
            fallback = format!(
                ", and with {} at up to {} substeps",
                kind.label(),
                self.substeps
            );
            fell_back = Some(kind);
        }
        self.back_to_frame_start(state);
        self.substeps = before;
        self.record(state.time, Some(&last), GuardAction::GaveUp, before);
        Err(Diverged {
            time: state.time,
            reason: last.to_string(),
            substeps: tried,
            fallback,
            cause: {
                let pos = f32_view(state, &mut self.view).pos.clone();
                self.diagnose(model, &pos, (tried, fell_back))
            },
        })
    }

    /// Replays to `end` at `from` substeps a frame, then at twice as many, `tries` times in
    /// all, until one stands (`true`; its substeps stay in effect); `last` is the last
    /// try's trouble. The substeps are the last tried where none stood.
    fn replay_doubling(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState<R>,
        end: f64,
        (from, tries): (u32, u32),
        last: &mut Trouble,
    ) -> bool {
        for k in 0..tries {
            self.substeps = if k == 0 {
                from
            } else {
                self.substeps.saturating_mul(2)
            };
            match self.replay(model, state, end) {
                Ok(()) => return true,
                Err(t) => *last = t,
            }
        }
        false
    }

    /// The frame that started at `frame_start` stood: the guard counts it healthy.
    pub(super) fn frame_stood(&mut self) {
        let start = std::mem::take(&mut self.frame_start);
        self.guard.healthy_frame(&start);
        self.frame_start = start;
    }

    /// A speed or kinetic-energy limit crossed: the frame redone from its start against the
    /// limits raised to admit what it reached ([`GuardLimits::admitting`](crate::sim::guard::GuardLimits::admitting)), with the
    /// substeps in effect and then with twice as many. Where both stand and their
    /// velocities agree ([`resolved`]), the motion is the scene's: the first stands, and so
    /// do the raised limits. A blow-up outgrows the raised limits within the frame, so its
    /// first redo stops where it crosses them. Else the state is left for the rescue.
    fn admit(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState<R>,
        end: f64,
        trouble: &Trouble,
    ) -> Option<FrameOutcome> {
        let limits = self.guard.limits?;
        let raised = limits.admitting(trouble, self.integrator.kind())?;
        self.guard.limits = Some(raised);
        let stood = self.redone(model, state, end, 1).and_then(|coarse| {
            let stood = (state.clone(), self.self_contacts.work.forced_total);
            let fine = self.redone(model, state, end, 2)?;
            resolved(&coarse, &fine).then_some(stood)
        });
        let Some((stood, forced)) = stood else {
            self.guard.limits = Some(limits);
            return None;
        };
        state.clone_from(&stood);
        self.self_contacts.work.forced_total = forced;
        self.integrator.invalidate();
        self.frame_stood();
        let (speed, joules) = (raised.speed, raised.kinetic_energy);
        let substeps = self.substeps;
        (self.guard).record(
            end,
            Some(trouble),
            GuardAction::Raised { speed, joules },
            (substeps, substeps),
        );
        Some(FrameOutcome::Stepped)
    }

    /// The frame ending at `end` redone from its start with `factor` × the substeps in
    /// effect, against the guard's limits: its end velocities where it stood.
    fn redone(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState<R>,
        end: f64,
        factor: u32,
    ) -> Option<Vec<glam::Vec3>> {
        self.back_to_frame_start(state);
        let substeps = self.substeps;
        self.substeps = substeps.saturating_mul(factor);
        let tried = self.try_frame(model, state, end);
        self.substeps = substeps;
        tried
            .ok()
            .map(|()| f32_view(state, &mut self.view).vel.clone())
    }

    /// After a healthy frame: maybe bring raised substeps back down.
    pub(super) fn maybe_recover(&mut self, end: f64) -> Option<FrameOutcome> {
        let before = self.substeps;
        self.substeps = self.guard.step_down(before, self.requested)?;
        self.record(end, None, GuardAction::Recovered, before);
        Some(FrameOutcome::Recovered {
            from: before,
            to: self.substeps,
        })
    }
}
