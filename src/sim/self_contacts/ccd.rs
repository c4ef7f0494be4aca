//! Continuous collision detection, conservatively: how far along a substep's straight-line
//! motion a pair can go and stay apart. Additive CCD (Li et al., "Codimensional Incremental
//! Potential Contact", 2021) in f64: from a distance d, no point of either side can close
//! the gap faster than the sum of the sides' largest relative displacements, so the pair
//! may advance by a fraction of d over that sum with certainty; repeated until the motion
//! ends or the gap has nearly closed.

use glam::DVec3;

use super::primitives::{Pair, apart_by_planes, distance};

/// Advances stop when the gap above the separation kept has shrunk to this share of what
/// it was at the start: the motion is cut there.
const STOP: f64 = 0.1;

/// Each advance closes at most this share of the gap above the separation kept.
const ADVANCE: f64 = 0.9;

/// Advances at most: a pair still approaching after these is cut where it has got to.
const MAX_ADVANCES: usize = 64;

/// The largest fraction in [0, 1] of the motion from `from` by `moves` (the pair's four
/// particles) over which its sides stay more than `keep` apart — or, where they start
/// closer than twice `keep`, more than half the distance they start at. 1 when the whole
/// motion is safe; pairs that start touching (distance 0) are left alone (1): nothing
/// can be promised for them.
pub fn safe_fraction(pair: &Pair, from: [DVec3; 4], moves: [DVec3; 4], keep: f64) -> f64 {
    let k = pair.first_side();
    // Each side stays within the box of its particles' starts and ends: sides whose boxes
    // are more than `keep` apart along an axis stay apart (most pairs end here).
    let swept = |r: std::ops::Range<usize>| {
        r.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), i| {
            let to = from[i] + moves[i];
            (lo.min(from[i]).min(to), hi.max(from[i]).max(to))
        })
    };
    let ((alo, ahi), (blo, bhi)) = (swept(0..k), swept(k..4));
    if (blo - ahi).max(alo - bhi).max_element() > keep {
        return 1.0;
    }
    let speed = closing_bound(pair, moves);
    if speed == 0.0 {
        return 1.0;
    }
    // Nor where the sides' planes or lines start farther apart than the motion can close
    // down to `keep` (most of a stack's pairs; strictly, as the distance is asked below).
    if apart_by_planes(pair, from, (keep + speed) * (1.0 + 1e-9)) {
        return 1.0;
    }
    let d0 = distance(pair, from);
    if d0 <= 0.0 {
        return 1.0;
    }
    let keep = keep.min(0.5 * d0);
    if d0 - speed > keep {
        return 1.0;
    }
    let stop = keep + STOP * (d0 - keep);
    let (mut t, mut d) = (0.0f64, d0);
    for _ in 0..MAX_ADVANCES {
        let step = ADVANCE * (d - keep) / speed;
        if t + step >= 1.0 {
            return 1.0;
        }
        t += step;
        d = distance(pair, std::array::from_fn(|i| from[i] + t * moves[i]));
        if d <= stop {
            break;
        }
    }
    t
}

/// How far the pair's sides can close on each other over the motion `moves` (the pair's
/// four particles) at most: only relative motion matters, so the mean is taken out, and
/// no point of a side moves farther than the side's farthest particle.
pub fn closing_bound(pair: &Pair, moves: [DVec3; 4]) -> f64 {
    let k = pair.first_side();
    let mean = moves.iter().copied().sum::<DVec3>() / 4.0;
    let reach =
        |r: std::ops::Range<usize>| r.map(|i| (moves[i] - mean).length()).fold(0.0f64, f64::max);
    reach(0..k) + reach(k..4)
}
