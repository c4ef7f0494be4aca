//! The guard's running memory: the limits in force, the rollback point, and the counters
//! that bring raised substeps back down.

use crate::cloth::{ClothState, Real};

use super::guard::{GuardEvent, GuardLimits};
use super::guard_policy::GuardPolicy;

/// What the guard keeps between frames.
#[derive(Clone, Debug)]
pub struct GuardState<R: Real = f32> {
    pub policy: GuardPolicy,
    pub limits: Option<GuardLimits>,
    /// A state that stayed healthy for `checkpoint_frames` frames after it: where a failed
    /// frame rolls back to. `None` until the first frame after a reset or an outside change.
    pub checkpoint: Option<ClothState<R>>,
    /// The next checkpoint, and how many healthy frames it has aged.
    pub candidate: Option<(ClothState<R>, u32)>,
    /// A retired checkpoint's buffers, reused for the next candidate (no allocation per
    /// checkpoint in a long run).
    spare: Option<ClothState<R>>,
    /// Healthy frames since the substeps last changed.
    pub good_frames: u32,
    /// Healthy frames needed before stepping down (doubles after a step down that failed).
    pub recover_wait: u32,
    /// Whether the last change of substeps was a step down (so a quick failure backs off).
    pub stepped_down: bool,
    pub events: Vec<GuardEvent>,
}

impl<R: Real> GuardState<R> {
    pub fn new(policy: GuardPolicy) -> Self {
        Self {
            recover_wait: policy.recover_after,
            policy,
            limits: None,
            checkpoint: None,
            candidate: None,
            spare: None,
            good_frames: 0,
            stepped_down: false,
            events: Vec::new(),
        }
    }

    /// The history changed outside the stepper: old rollback points and limits are stale.
    pub fn forget_history(&mut self) {
        self.limits = None;
        self.checkpoint = None;
        self.candidate = None;
    }

    /// Records a healthy frame that started from `start`: ages the candidate, promotes it.
    pub fn healthy_frame(&mut self, start: &ClothState<R>) {
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
    fn copy_of(&mut self, state: &ClothState<R>) -> ClothState<R> {
        let mut copy = self.spare.take().unwrap_or_default();
        copy.clone_from(state);
        copy
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
