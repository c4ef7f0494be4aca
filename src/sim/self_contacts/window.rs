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
/// [`LONGEST_WINDOW`]); one cut short by a search, by one half as long.
#[derive(Clone, Copy, Debug)]
pub(super) struct Window {
    pub(super) len: u32,
    pub(super) at: u32,
}

impl Default for Window {
    fn default() -> Self {
        Window { len: 1, at: 0 }
    }
}

impl Window {
    /// The window a whole search starts, after this one: where the cloth is `slow` (the
    /// pairs judged by the boxes alone), or the last pairs were not judged by the motion
    /// (`was_swept` false), one substep; otherwise twice as long as this one where it ran
    /// out, half where it was cut short.
    pub(super) fn next(self, slow: bool, was_swept: bool) -> Window {
        let len = match (slow, was_swept) {
            (false, true) if self.at >= self.len => (2 * self.len).min(LONGEST_WINDOW),
            (false, true) => (self.len / 2).max(1),
            _ => 1,
        };
        Window { len, at: 0 }
    }
}
