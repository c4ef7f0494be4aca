//! Self-contact: the cloth kept off itself. Two kinds of pair — a vertex against a triangle
//! it is not a corner of, an edge against an edge it shares no particle with — are found
//! by walking a tree of the triangles' boxes against itself, told apart by the substep's
//! motion ([`tree`]; which pairs of two triangles not told apart are kept, [`search`];
//! where they are kept, [`found`]; the pairs of triangles sharing a corner, passed by
//! while the corner's ring keeps its shape, [`certify`]), pushed a thickness apart at the
//! substep's end with friction, and then
//! checked along the whole motion by conservative continuous collision detection
//! ([`ccd`]): a pair whose sides could meet has its free particles' motion cut short where
//! they are still apart, round after round, until no pair can meet (after a few rounds
//! the cut is to the substep's start, where the cloth was free of intersections, so the
//! rounds end). A cloth that starts free of intersections so never gets one; only motion
//! that is prescribed (pins, handles) can force a pair through, and such pairs are
//! counted ([`SelfWork::forced`]).

mod ccd;
mod certify;
mod costs;
mod error;
mod found;
mod gap;
mod patches;
mod primitives;
mod rings;
mod search;
mod solver;
mod sweeps;
mod tree;
mod window;
mod work;

pub use error::ContactError;
pub(crate) use primitives::point_triangle_distance;
pub use search::owned_parts;
pub use solver::SelfContacts;
pub use work::{SELF_RECHECK, SELF_SETUP, SELF_UPKEEP, SelfWork};
