//! Per-phase wall-clock timings of the stepper. Only phases that ran appear.

use std::time::{Duration, Instant};

/// Accumulated time per named phase, in first-run order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PhaseTimings {
    entries: Vec<(&'static str, Duration)>,
}

impl PhaseTimings {
    /// Adds `elapsed` to `phase`.
    pub fn add(&mut self, phase: &'static str, elapsed: Duration) {
        match self.entries.iter_mut().find(|(name, _)| *name == phase) {
            Some((_, total)) => *total += elapsed,
            None => self.entries.push((phase, elapsed)),
        }
    }

    /// Runs `f`, charging its time to `phase`.
    pub fn time<R>(&mut self, phase: &'static str, f: impl FnOnce() -> R) -> R {
        let start = Instant::now();
        let out = f();
        self.add(phase, start.elapsed());
        out
    }

    /// The phases and their totals.
    pub fn entries(&self) -> &[(&'static str, Duration)] {
        &self.entries
    }

    /// Returns the totals so far and starts again from zero.
    pub fn take(&mut self) -> PhaseTimings {
        std::mem::take(self)
    }
}
