//! Whether a team's sections pay for its helpers: timed windows of sections, and now and
//! then a window tried the other way.

use std::time::Duration;

/// Sections over which a team's time per section is measured.
pub(super) const WINDOW: u32 = 64;
/// Windows run the chosen way between two that try the other, after a switch; each probe
/// that loses doubles it, up to [`PROBE_EVERY_MOST`].
pub(super) const PROBE_EVERY: u32 = 8;
/// The most windows between two probes (at N = 64 about 2 000 substeps, a tenth of a second).
pub(super) const PROBE_EVERY_MOST: u32 = 64;

/// Whether a team's sections run shared with its helpers or on the caller alone, chosen by
/// timing. Now and then a window of [`WINDOW`] sections tries the other way, which is taken
/// when it took at least 10 % less time than the last window run the chosen way (a probe
/// that has used up that time ends early, lost). Probes come [`PROBE_EVERY`] windows after
/// a switch and ever more rarely while they lose; while sharing, they come only once its
/// windows have slowed (and at the start, and every 512 windows). Each costs the slower
/// way's time and the helpers' caches warmed again: at one probe in nine windows that
/// added about 3 µs to a 30 µs substep.
#[derive(Debug, Default)]
pub(super) struct Pace {
    /// The way chosen: the caller alone (the helpers did not pay when last tried).
    pub(super) alone: bool,
    /// The current window tries the way not chosen.
    probing: bool,
    /// Sections in the current window so far, and the time they took.
    pub(super) sections: u32,
    spent: Duration,
    /// Windows run the chosen way since the last probe, and how many come between probes
    /// now (0 until the first probe: [`PROBE_EVERY`]).
    since_probe: u32,
    probe_every: u32,
    /// Time per section of the last window run the chosen way.
    chosen: Option<Duration>,
    /// The shared way's fastest time per section lately (rising 1 % a window): a shared
    /// window 25 % slower than this has a busy machine behind it.
    quiet: Option<Duration>,
}

impl Pace {
    /// Whether the next section runs on the caller alone.
    pub(super) fn runs_alone(&self) -> bool {
        self.alone != self.probing
    }

    /// Counts a section that took `took`, run the way [`Pace::runs_alone`] said.
    pub(super) fn record(&mut self, took: Duration) {
        self.spent += took;
        self.sections += 1;
        // A clear win only: the two ways' times swing from window to window, and a switch
        // on noise would run the slower way until the next probe. A probe that has spent
        // what would lose already ends at once (the slower way costs only until then).
        let to_beat = self.chosen.map(|chosen| chosen * WINDOW * 9 / 10);
        let lost = self.probing && to_beat.is_some_and(|to_beat| self.spent >= to_beat);
        if self.sections < WINDOW && !lost {
            return;
        }
        let per_section = self.spent / WINDOW;
        (self.sections, self.spent) = (0, Duration::ZERO);
        if self.probing {
            self.probing = false;
            // A probe comes after a window run the chosen way, so it had a time to beat: a
            // probe that did not lose won.
            if lost {
                self.probe_every = (self.probe_every.max(PROBE_EVERY) * 2).min(PROBE_EVERY_MOST);
            } else {
                self.alone = !self.alone;
                self.chosen = Some(per_section);
                self.probe_every = PROBE_EVERY;
            }
        } else {
            self.chosen = Some(per_section);
            if !self.alone {
                let lately = self.quiet.map_or(per_section, |quiet| quiet * 101 / 100);
                self.quiet = Some(lately.min(per_section));
            }
            self.since_probe += 1;
            // Sharing is probed only once it has slowed (a quiet machine pays nothing for
            // probes), at the start, and now and then whatever the times say.
            let slowed = self.alone
                || self.probe_every == 0
                || self.since_probe >= 8 * PROBE_EVERY_MOST
                || self.quiet.is_some_and(|quiet| per_section * 4 > quiet * 5);
            if slowed && self.since_probe >= self.probe_every.max(PROBE_EVERY) {
                (self.since_probe, self.probing) = (0, true);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feeds `pace` one window of sections that take `micros` each, until it ends; returns
    /// whether they ran alone (the same for the whole window).
    fn window(pace: &mut Pace, micros: u64) -> bool {
        let alone = pace.runs_alone();
        for _ in 0..WINDOW {
            assert_eq!(pace.runs_alone(), alone, "a window runs one way");
            pace.record(Duration::from_micros(micros));
            if pace.sections == 0 {
                break;
            }
        }
        alone
    }

    /// A probe that cannot win any more ends early: here after the 18 µs sections have
    /// used up 90 % of a 10 µs window (32 of 64), and the team shares again.
    #[test]
    fn a_losing_probe_ends_as_soon_as_it_has_lost() {
        let mut pace = Pace::default();
        for _ in 0..PROBE_EVERY * WINDOW {
            pace.record(Duration::from_micros(10));
        }
        assert!(pace.runs_alone(), "probing");
        let mut sections = 0;
        while pace.runs_alone() {
            pace.record(Duration::from_micros(18));
            sections += 1;
        }
        assert_eq!(sections, 32);
        assert!(!pace.alone);
    }

    /// Story: the helpers pay in a quiet spell, stop paying in a busy one and pay again
    /// after it; the team follows within one probe each time, and a probe that loses
    /// changes nothing.
    #[test]
    fn a_team_runs_alone_while_its_helpers_do_not_pay_and_shares_again_when_they_do() {
        let mut pace = Pace::default();
        // Quiet: shared takes 10 µs a section, alone 18. The first probe (after eight
        // windows) loses, and while sharing keeps its pace no other comes.
        let probe_at = PROBE_EVERY as usize;
        let ways: Vec<bool> = (0..100)
            .map(|_| {
                let alone = pace.runs_alone();
                window(&mut pace, if alone { 18 } else { 10 })
            })
            .collect();
        let want: Vec<bool> = (0..100).map(|w| w == probe_at).collect();
        assert_eq!(ways, want, "one probe, at the start");
        // Busy: shared now takes 30 µs, alone 20. The team probes at once and goes alone,
        // probing sharing ever more rarely.
        let most = PROBE_EVERY_MOST as usize;
        let ways: Vec<bool> = (0..2 * most)
            .map(|_| {
                let alone = pace.runs_alone();
                window(&mut pace, if alone { 20 } else { 30 })
            })
            .collect();
        let first_alone = ways.iter().position(|&a| a).expect("goes alone");
        assert_eq!(first_alone, 1, "{ways:?}");
        let shared_probes = ways[first_alone..].iter().filter(|&&a| !a).count();
        assert!((1..=4).contains(&shared_probes), "{ways:?}");
        assert!(pace.alone);
        // Quiet again: sharing wins its next probe (at most PROBE_EVERY_MOST windows on),
        // and the team shares from then on, with no probe while it keeps its pace.
        let ways: Vec<bool> = (0..2 * most)
            .map(|_| {
                let alone = pace.runs_alone();
                window(&mut pace, if alone { 18 } else { 10 })
            })
            .collect();
        let first_shared = ways.iter().position(|&a| !a).expect("shares again");
        assert!(first_shared <= most, "{ways:?}");
        assert!(ways[first_shared..].iter().all(|&a| !a), "{ways:?}");
        assert!(!pace.alone, "{ways:?}");
    }

    /// Story: sharing keeps its pace, so the slow-down gate never opens, but running alone
    /// has become faster (the first probe lost); the probe that comes every
    /// `8 × PROBE_EVERY_MOST` windows whatever the times say finds it, and the team goes
    /// alone.
    #[test]
    fn a_steady_team_still_tries_alone_now_and_then() {
        let mut pace = Pace::default();
        let mut alone_from = None;
        for w in 0..600 {
            let alone = pace.runs_alone();
            if alone && w > PROBE_EVERY as usize && alone_from.is_none() {
                alone_from = Some(w);
            }
            // Alone loses the first probe (18 µs), and would win every later one (8 µs).
            let micros = match (alone, w <= PROBE_EVERY as usize) {
                (false, _) => 10,
                (true, true) => 18,
                (true, false) => 8,
            };
            window(&mut pace, micros);
        }
        let rechecked = PROBE_EVERY + 1 + 8 * PROBE_EVERY_MOST;
        assert_eq!(alone_from, Some(rechecked as usize));
        assert!(pace.alone);
    }
}
