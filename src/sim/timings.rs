//! Per-phase wall-clock timings and call counts of the stepper. Only phases that ran appear.

use std::time::{Duration, Instant};

/// One phase's totals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phase {
    pub name: &'static str,
    pub time: Duration,
    pub calls: u64,
}

/// Accumulated time and calls per named phase, in first-run order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PhaseTimings {
    entries: Vec<Phase>,
}

impl PhaseTimings {
    /// Adds `calls` runs taking `elapsed` in all to `phase`.
    pub fn add_calls(&mut self, phase: &'static str, elapsed: Duration, calls: u64) {
        match self.entries.iter_mut().find(|p| p.name == phase) {
            Some(p) => {
                p.time += elapsed;
                p.calls += calls;
            }
            None => self.entries.push(Phase {
                name: phase,
                time: elapsed,
                calls,
            }),
        }
    }

    /// Adds one run of `elapsed` to `phase`.
    pub fn add(&mut self, phase: &'static str, elapsed: Duration) {
        self.add_calls(phase, elapsed, 1);
    }

    /// Runs `f`, charging its time to `phase`.
    pub fn time<R>(&mut self, phase: &'static str, f: impl FnOnce() -> R) -> R {
        let start = Instant::now();
        let out = f();
        self.add(phase, start.elapsed());
        out
    }

    /// The phases and their totals.
    pub fn phases(&self) -> &[Phase] {
        &self.entries
    }

    /// The phase called `name`, if it ran.
    pub fn get(&self, name: &str) -> Option<&Phase> {
        self.entries.iter().find(|p| p.name == name)
    }

    /// A phase's total time and calls (nothing for a phase that did not run).
    pub fn totals(&self, name: &str) -> (std::time::Duration, u64) {
        self.get(name)
            .map_or((std::time::Duration::ZERO, 0), |p| (p.time, p.calls))
    }

    /// Adds another set of timings to this one.
    pub fn merge(&mut self, other: &PhaseTimings) {
        for p in &other.entries {
            self.add_calls(p.name, p.time, p.calls);
        }
    }

    /// Returns the totals so far and starts again from zero.
    pub fn take(&mut self) -> PhaseTimings {
        std::mem::take(self)
    }
}
