//! How long the pairs judged by the motion hold: the windows of the whole searches.

/// Where the pairs are judged by the motion, each whole search judges them along the
/// particles' motion carried on at its velocity for a window of up to this many substeps,
/// so that they hold for the substeps after while each particle stays within
/// the allowance of that path (see [`Window`]).
pub(super) const LONGEST_WINDOW: u32 = 2;

/// How long the pairs judged by the motion hold. A search judges them along each
/// particle's path over a window of `len` substeps: its motion in the substep searched,
/// carried on at the same velocity (in the frame that moves with the cloth's mean motion,
/// where the cloth's own deceleration moves no particle). They hold at the window's
/// substep `at` while each particle's start and end lie within the allowance (and the
/// slack of what the pairs are needed for) of where the path puts them then: along the
/// substep a particle is then within as much of its path, so a pair's distance falls
/// short of its foreseen one by at most twice that. A window that ran out before the
/// whole tree had to be searched again is followed by one twice as long (up to
/// [`LONGEST_WINDOW`]); one cut short by a search, by one half as long, and by a few of
/// one substep before a longer one is tried again ([`WAIT`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Window {
    pub(super) len: u32,
    pub(super) at: u32,
    /// Windows of one substep still to come before a longer one is tried again.
    wait: u32,
}

impl Default for Window {
    fn default() -> Self {
        Window {
            len: 1,
            at: 0,
            wait: 0,
        }
    }
}

/// Windows of one substep that follow a window cut short before a longer one is tried
/// again. Where `crumple` lands every particle strays from its path within a substep (the
/// cloth's waves move each 0.7–2 mm off it), so a longer window only widens the search it
/// is cut short by; where the motion smooths out, the longer ones hold again. Trying
/// again at once cost 4 % more of the first second's self-contact at 64², and `fast-fold`
/// 5 % more; 8 did as well as 3.
const WAIT: u32 = 3;

impl Window {
    /// The window a whole search starts, after this one: where the cloth is `slow` (the
    /// pairs judged by the boxes alone), or the last pairs were not judged by the motion
    /// (`was_swept` false), one substep; otherwise twice as long as this one where it ran
    /// out (after [`WAIT`] windows of one substep, where one was cut short), half where it
    /// was cut short.
    pub(super) fn next(self, slow: bool, was_swept: bool) -> Window {
        let ran_out = self.at >= self.len;
        let (len, wait) = match (slow, was_swept) {
            (false, true) if ran_out && self.wait > 0 => (1, self.wait - 1),
            (false, true) if ran_out => ((2 * self.len).min(LONGEST_WINDOW), 0),
            (false, true) => ((self.len / 2).max(1), WAIT),
            _ => (1, 0),
        };
        Window { len, at: 0, wait }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lengths of the windows that follow `first`, each run to its end (`at` = `len`)
    /// but the `cut` ones, cut short after their first substep.
    fn lengths(first: Window, cut: &[usize], count: usize) -> Vec<u32> {
        let mut window = first;
        (0..count)
            .map(|k| {
                window.at = if cut.contains(&k) { 0 } else { window.len };
                window = window.next(false, true);
                window.len
            })
            .collect()
    }

    /// A window that runs out is followed by one twice as long (up to the longest); one
    /// cut short by one half as long, and by [`WAIT`] windows of one substep before a
    /// longer one is tried again; slow, or after pairs judged by the boxes, one substep.
    #[test]
    fn a_window_cut_short_is_followed_by_short_ones_for_a_while() {
        let start = Window::default();
        assert_eq!(lengths(start, &[], 3), [2, 2, 2]);
        assert_eq!(lengths(start, &[1], 7), [2, 1, 1, 1, 1, 2, 2]);
        assert_eq!(lengths(start, &[1, 3], 8), [2, 1, 1, 1, 1, 1, 1, 2]);
        let long = Window {
            len: 2,
            at: 2,
            wait: 0,
        };
        assert_eq!(long.next(true, true).len, 1);
        assert_eq!(long.next(false, false).len, 1);
    }
}
