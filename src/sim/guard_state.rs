//! The guard's running memory: the limits in force, the rollback point, and the counters
//! that bring raised substeps back down.

use crate::cloth::{ClothState, Real};

use super::guard::{GuardAction, GuardEvent, GuardLimits, Trouble};
use super::guard_policy::GuardPolicy;

/// A copy of a cloth's state the guard can roll back to: [`CpuSnapshot`] on the CPU, a
/// buffer on the device for the GPU backend.
pub trait Snapshot: Default {
    /// Makes `self` a copy of `from`, reusing `self`'s storage.
    fn copy_from(&mut self, from: &Self);
}

/// A rollback point of the CPU stepper: the state, and what the run had counted by then
/// that a rollback must take back with it (the pairs prescribed motion forced: a frame rolled
/// back and redone counts only the pairs of the try that stands).
#[derive(Clone, Debug, Default)]
pub struct CpuSnapshot<R: Real = f32> {
    pub state: ClothState<R>,
    pub forced: u64,
}

impl<R: Real> Snapshot for CpuSnapshot<R> {
    fn copy_from(&mut self, from: &Self) {
        self.state.clone_from(&from.state);
        self.forced = from.forced;
    }
}

/// What the guard keeps between frames, with rollback points of type `S`.
#[derive(Clone, Debug)]
pub struct GuardState<S = CpuSnapshot> {
    pub policy: GuardPolicy,
    pub limits: Option<GuardLimits>,
    /// A state that stayed healthy for `checkpoint_frames` frames after it: where a failed
    /// frame rolls back to. `None` until the first frame after a reset or an outside change.
    pub checkpoint: Option<S>,
    /// The next checkpoint, and how many healthy frames it has aged.
    pub candidate: Option<(S, u32)>,
    /// A retired checkpoint's buffers, reused for the next candidate (no allocation per
    /// checkpoint in a long run).
    spare: Option<S>,
    /// Healthy frames since the substeps last changed.
    pub good_frames: u32,
    /// Healthy frames needed before stepping down (doubles after a step down that failed).
    pub recover_wait: u32,
    /// Whether the last change of substeps was a step down (so a quick failure backs off).
    pub stepped_down: bool,
    pub events: Vec<GuardEvent>,
}

impl<S: Snapshot> GuardState<S> {
    pub fn new(policy: GuardPolicy) -> Self {
        let mut guard = Self {
            policy,
            limits: None,
            checkpoint: None,
            candidate: None,
            spare: None,
            good_frames: 0,
            recover_wait: 0,
            stepped_down: false,
            events: Vec::new(),
        };
        guard.restart();
        guard
    }

    /// New parameters: a new `policy` starts the guard afresh; either way the limits and
    /// rollback points belong to the old parameters.
    pub fn reconfigure(&mut self, policy: &GuardPolicy) {
        if self.policy != *policy {
            *self = Self::new(policy.clone());
        }
        self.forget_history();
    }

    /// The run starts over: the history is forgotten and the counters start as a new
    /// guard's (the unread events and the spare rollback point's buffers are kept).
    pub fn restart(&mut self) {
        self.forget_history();
        self.good_frames = 0;
        self.recover_wait = self.policy.recover_after;
        self.stepped_down = false;
    }

    /// The history changed outside the stepper: old rollback points and limits are stale.
    pub fn forget_history(&mut self) {
        self.limits = None;
        self.checkpoint = None;
        self.candidate = None;
    }

    /// Records a healthy frame that started from `start`: ages the candidate, promotes it.
    pub fn healthy_frame(&mut self, start: &S) {
        self.good_frames += 1;
        let age_needed = self.policy.checkpoint_frames;
        match &mut self.candidate {
            Some((_, age)) if *age + 1 >= age_needed => {
                let (state, _) = self.candidate.take().unwrap_or_default();
                self.spare = self.checkpoint.replace(state);
            }
            Some((_, age)) => *age += 1,
            None => self.candidate = Some((self.copy_of(start), 0)),
        }
        if self.checkpoint.is_none() {
            self.checkpoint = Some(self.copy_of(start));
        }
    }

    /// `state` copied into the spare buffers when there are some.
    fn copy_of(&mut self, state: &S) -> S {
        let mut copy = self.spare.take().unwrap_or_default();
        copy.copy_from(state);
        copy
    }

    /// After a healthy frame at `substeps` per frame: the count to come back down to, when
    /// they were raised above `requested` and enough healthy frames have passed since.
    pub fn step_down(&mut self, substeps: u32, requested: u32) -> Option<u32> {
        if substeps <= requested || self.good_frames < self.recover_wait {
            return None;
        }
        self.good_frames = 0;
        self.stepped_down = true;
        Some((substeps / 2).max(requested))
    }

    /// Records what the guard did in the frame ending at `time` (seconds), for what reason,
    /// and the substeps per frame before and after.
    pub fn record(
        &mut self,
        time: f64,
        reason: Option<&Trouble>,
        action: GuardAction,
        (before, after): (u32, u32),
    ) {
        self.events.push(GuardEvent {
            time,
            reason: reason.map(ToString::to_string),
            action,
            substeps_before: before,
            substeps_after: after,
        });
    }

    /// A frame failed: if it came soon after a step down, wait longer before the next one.
    pub fn failed_frame(&mut self) {
        if self.stepped_down && self.good_frames < self.recover_wait {
            self.recover_wait = (self.recover_wait * 2).min(3600);
        }
        self.stepped_down = false;
        self.good_frames = 0;
        self.candidate = None;
    }
}
