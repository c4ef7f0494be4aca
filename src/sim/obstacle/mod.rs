//! Obstacles of any shape: triangle surfaces the cloth may not pass, with the tree that
//! finds what a particle's move comes near, and the frames of one that deforms.

mod coarse;
mod edges;
mod geometry;
mod sequence;
mod surface;
mod tips;
mod tree;

pub use coarse::{ClothSpan, Dips, Reached, prism};
#[cfg(test)]
pub(crate) use edges::unit_cube;
pub use edges::{Clearance, EdgeHit, LOOK, LOOK_DEFORMING, SharpEdges};
pub(crate) use geometry::{closest_weights, segments_closest};
pub use sequence::{Moment, Sequence, SurfaceClock};
pub use surface::{Caught, Fitted, Gathered, Surface};
pub use tips::Tips;
pub use tree::{Near, Nearest, TriangleTree};
pub(crate) use tree::{Split, split_triangles_at_medians};
