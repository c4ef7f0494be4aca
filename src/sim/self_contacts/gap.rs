//! Two things told apart along their straight motion from their extents at its two ends.
//! Each particle runs straight from its start to its end in the same time, so at a share
//! `t` of the motion a set of them (a node of the tree, a triangle, a pair's side) lies
//! within `(1 − t)` times its extent at the start plus `t` times its extent at the end,
//! along any axis; and the gap between two such extents runs straight from the one at the
//! start to the one at the end. Where, in the same direction, both are at least some
//! distance, the two keep that far apart all along. The tree's nodes, two triangles along
//! a line, and a pair's sides' boxes are all told apart so.

use std::ops::Sub;

use glam::{DVec3, Vec3A};

/// A number, or a vector of them told apart coordinate by coordinate.
pub(super) trait Extent: Copy + Sub<Output = Self> {
    /// The lesser (each coordinate's).
    fn least(self, other: Self) -> Self;
    /// The larger (each coordinate's).
    fn most(self, other: Self) -> Self;
}

/// [`Extent`] for types whose own `min` and `max` are the lesser and the larger.
macro_rules! extent_by_min_max {
    ($($t:ty),*) => {$(
        impl Extent for $t {
            #[inline(always)]
            fn least(self, other: Self) -> Self {
                self.min(other)
            }
            #[inline(always)]
            fn most(self, other: Self) -> Self {
                self.max(other)
            }
        }
    )*};
}

extent_by_min_max!(f32, f64, DVec3, Vec3A);

/// The gap between two extents `a` and `b` (`[lo, hi]` each) that run straight from
/// `start` to `end` along the motion, that holds all along it: the larger of the gap from
/// `a` up to `b` and that from `b` up to `a`, each the lesser of the start's and the
/// end's (see the module's notes). Negative where they may overlap.
#[inline(always)]
pub(super) fn gap_at_both_ends<T: Extent>(start: [[T; 2]; 2], end: [[T; 2]; 2]) -> T {
    let ([[alo, ahi], [blo, bhi]], [[aend_lo, aend_hi], [bend_lo, bend_hi]]) = (start, end);
    let up = (blo - ahi).least(bend_lo - aend_hi);
    let down = (alo - bhi).least(aend_lo - bend_hi);
    up.most(down)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two spans on a line, each end of each running straight from where it starts to
    /// where it ends: wherever the gap at both ends says they are apart, they are at least
    /// that far apart at each of 33 points along the motion; and a vector's gap is each
    /// coordinate's own.
    #[test]
    fn the_gap_at_both_ends_holds_all_along_the_motion() {
        let mut rnd = crate::test_rng::uniform(11);
        let mut span = || {
            let lo = f64::from(rnd());
            [lo, lo + 0.3 * f64::from(rnd())]
        };
        let mut apart = 0;
        for _ in 0..2000 {
            let (start, end) = ([span(), span()], [span(), span()]);
            let gap = gap_at_both_ends(start, end);
            let at = |t: f64| {
                let [a, b] =
                    [0, 1].map(|s| [0, 1].map(|k| start[s][k] + t * (end[s][k] - start[s][k])));
                (b[0] - a[1]).max(a[0] - b[1])
            };
            if gap > 0.0 {
                apart += 1;
                let least = (0..=32)
                    .map(|k| at(f64::from(k) / 32.0))
                    .fold(f64::INFINITY, f64::min);
                assert!(least >= gap - 1e-12, "{least} apart along, {gap} told");
            }
            let vector = |x: [[f64; 2]; 2]| x.map(|s| s.map(|v| DVec3::new(v, 2.0 * v, 0.5)));
            let gaps = gap_at_both_ends(vector(start), vector(end));
            assert_eq!([gaps.x, gaps.y, gaps.z], [gap, 2.0 * gap, 0.0]);
        }
        assert!(apart > 400, "{apart} apart");
    }
}
