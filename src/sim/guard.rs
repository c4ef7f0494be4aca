//! The stability guard's vocabulary: what a frame did, and the error of one no try could save.

/// How many times a diverging frame is retried, each time with twice the substeps.
pub const MAX_REFINEMENTS: u32 = 3;

/// A frame that could not be made stable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "simulation diverged at t = {time:.3} s even with {substeps} substeps per frame; \
     the state was rolled back to the last good frame. Lower the stiffness or the time step."
)]
pub struct Diverged {
    pub time: f64,
    pub substeps: u32,
}

/// What happened in a frame that succeeded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameOutcome {
    /// Advanced normally.
    Stepped,
    /// The first try diverged; the frame was redone with more substeps, which now stay.
    Refined { from: u32, to: u32 },
}
