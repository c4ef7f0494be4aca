//! What every contact pass after a substep shares: where the substep's start and end are,
//! and what the integrator keeps that the contacts change (`contacts.rs` runs the passes).

/// What the integrator keeps that a contact changes, which the contacts then update, in
/// the words `Contacts::attach_solve` bound.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Memory {
    None,
    /// Implicit Euler's first guess, whose flag is this word of its solve: a contact that
    /// moves a particle leaves the guess no history.
    Guess(u32),
    /// VBD's last accelerations, from this word of its stencil, four a particle: a contact
    /// adds its change of velocity over the substep.
    Accelerations(u32),
}

/// Where a substep's start and end are for the contacts.
#[derive(Clone, Copy, Debug)]
pub(super) enum Start {
    /// The start in `particles[i]`, the end in the other (semi-implicit Euler).
    In(usize),
    /// The start in the copy `Contacts::keep_start` made, the end in `particles[i]`
    /// (XPBD and VBD, which write their end over their start).
    Kept(usize),
}
