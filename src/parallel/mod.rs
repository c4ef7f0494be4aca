//! Execution, apart from physics: the thread team that runs a step's parallel sections,
//! the slices its members share, and loops compiled for wider vector units. Nothing here
//! knows what it computes.

mod block_sums;
mod disjoint;
mod pace;
mod parts;
mod ranges;
mod team;
mod wide;

pub use block_sums::{each_block, sum_blocks};
pub use disjoint::Disjoint;
pub use parts::{PARALLEL_ELEMENTS, each_part, each_part_from, fold_parts, within};
pub use ranges::share;
pub use team::Team;
pub use wide::{wide, wide_fma};
