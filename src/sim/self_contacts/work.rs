//! What self-contact did and costs: the work of the last resolve, and the phase that
//! times its setup for a cloth.

/// The phase that times self-contact's setup for a cloth ([`super::SelfContacts::prepare`],
/// and, among solids, the patches of their face passes, cut with it), when a stepper
/// takes self-collision on: once, before the substeps.
pub const SELF_SETUP: &str = "self-setup";

/// The phase that times self-contact's recheck after the solids moved the cloth again
/// ([`super::SelfContacts::settle`]).
pub const SELF_RECHECK: &str = "self-recheck";

/// The phase that times self-contact's upkeep between the contact effects: the positions
/// kept before the solids act, to flag what they moved (which rests on them), and after
/// self-contact, to tell whether the solids moved anything again (the recheck's start).
pub const SELF_UPKEEP: &str = "self-upkeep";

/// Work done by the last resolve: for cost checks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct SelfWork {
    /// Vertex–triangle and edge–edge pairs whose boxes over the substep overlap.
    pub candidates: u64,
    /// Pushes that kept a pair a thickness apart at the substep's end.
    pub contacts: u64,
    /// Searches of the whole tree (0 when the pairs found before still held, or only
    /// some triangles were searched again).
    pub searches: u64,
    /// Searches of only the triangles whose particles left their boxes.
    pub refreshes: u64,
    /// Triangles those searched again.
    pub refreshed: u64,
    /// Corners whose pairs' reference distances were measured again, their certificate
    /// having failed (see the module's notes).
    pub retaken: u64,
    /// Pairs whose motion was cut short because their sides could otherwise have met.
    pub impacts: u64,
    /// Pairs that prescribed motion (pins, handles) drove together, so no cut could keep
    /// them apart.
    pub forced: u64,
    /// [`SelfWork::forced`] added up since the solver was made, over the substeps that stand:
    /// the CPU stepper's guard sets it back with the state when it rolls a frame back.
    pub forced_total: u64,
}
