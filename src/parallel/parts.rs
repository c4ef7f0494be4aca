//! Cutting loops into parts for a team's members: equal shares, whole cache lines.

use super::disjoint::Disjoint;
use super::ranges::{clamped, share};
use super::team::Team;

/// Elements (particles) from which [`each_part`] shares its loop out between the team's
/// members: 64 × 64 particles (the spring blocks go parallel from here too). On the 2-core
/// virtual machine this was measured on, the 64 × 64 bench cloth's median frame took 18 %
/// less on two threads than on one once the caller could run a share its helper was late
/// for (implicit Euler's step 13 % less); below that size the data moving between the
/// cores' caches cost more than the second core gained.
pub const PARALLEL_ELEMENTS: usize = 4096;

/// Calls `part(range, slices)` with `arrays` cut at `range`, for ranges that cover
/// `0..len` (`len` the shortest array's length): one range per member of the current team,
/// run in parallel, from [`PARALLEL_ELEMENTS`] elements on; else the one range `0..len`
/// here. Ranges are whole cache lines (16 `f32`s, two lines of `f64`s) long but the last.
/// For loops in which each element's work is its own, so the result is the same however
/// they are cut.
pub fn each_part<T: Send, const K: usize>(
    arrays: [&mut [T]; K],
    part: impl Fn(std::ops::Range<usize>, [&mut [T]; K]) + Sync,
) {
    each_part_from(PARALLEL_ELEMENTS, arrays, part);
}

/// [`each_part`] for a loop whose elements cost enough that sharing it pays from `from`
/// elements on (a mesh obstacle's particles: a walk of its tree each) rather than from
/// [`PARALLEL_ELEMENTS`].
pub fn each_part_from<T: Send, const K: usize>(
    from: usize,
    arrays: [&mut [T]; K],
    part: impl Fn(std::ops::Range<usize>, [&mut [T]; K]) + Sync,
) {
    let len = arrays.iter().map(|a| a.len()).min().unwrap_or(0);
    let team = Team::current();
    if len < from || team.members() == 1 {
        part(0..len, arrays.map(|a| &mut a[..len]));
        return;
    }
    let arrays = arrays.map(Disjoint::new);
    let members = team.members();
    team.run(&|i| {
        let range = member_range(len, members, i);
        // SAFETY: the members' ranges are disjoint (shares of whole lines).
        let mine = std::array::from_fn(|k| unsafe { arrays[k].part(range.clone()) });
        part(range, mine);
    });
}

/// Member `i`'s range of `0..len` in [`each_part`]: its share of the whole cache lines (16
/// `f32`s) of `len` elements.
fn member_range(len: usize, members: usize, i: usize) -> std::ops::Range<usize> {
    const LINE: usize = 16;
    let lines = share(len.div_ceil(LINE), members, i);
    (lines.start * LINE).min(len)..(lines.end * LINE).min(len)
}

/// The most members [`fold_parts`] takes results from (a team of more folds alone).
const MOST_FOLDED: usize = 16;

/// `part(range)` over the ranges [`each_part`] cuts `0..len` into (so a member reads the
/// elements it writes in the loops beside), joined with `join` in the ranges' order: for
/// loops that only read, whose result does not depend on how they are cut (a least, a
/// greatest, a count). `None` for no element.
pub fn fold_parts<R: Send>(
    len: usize,
    part: impl Fn(std::ops::Range<usize>) -> R + Sync,
    join: impl Fn(R, R) -> R,
) -> Option<R> {
    let team = Team::current();
    let members = team.members();
    if len == 0 {
        return None;
    }
    if len < PARALLEL_ELEMENTS || members == 1 || members > MOST_FOLDED {
        return Some(part(0..len));
    }
    let mut results: [Option<R>; MOST_FOLDED] = std::array::from_fn(|_| None);
    let slots = Disjoint::new(&mut results[..members]);
    team.run(&|i| {
        let range = member_range(len, members, i);
        if !range.is_empty() {
            // SAFETY: each member writes only its own slot.
            unsafe { *slots.at(i) = Some(part(range)) };
        }
    });
    results.into_iter().flatten().reduce(join)
}

/// `slice[range]`, cut short where `slice` ends: for arrays read beside those that
/// [`each_part`] cuts, which may be shorter.
pub fn within<T>(slice: &[T], range: std::ops::Range<usize>) -> &[T] {
    &slice[clamped(range, slice.len())]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    #[test]
    fn each_part_cuts_every_array_alike_into_whole_lines_one_per_member() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .expect("a pool of 3");
        for len in [0, 5, PARALLEL_ELEMENTS - 1, PARALLEL_ELEMENTS + 37] {
            // The shorter array sets the length; the longer one's tail is left alone.
            let (mut a, mut b) = (vec![0.0f32; len], vec![0.0f32; len + 5]);
            let parts = Mutex::new(Vec::new());
            pool.install(|| {
                each_part([&mut a, &mut b], |range, [a, b]| {
                    assert_eq!((a.len(), b.len()), (range.len(), range.len()));
                    for (k, (a, b)) in a.iter_mut().zip(b.iter_mut()).enumerate() {
                        *a += (range.start + k) as f32;
                        *b += 1.0;
                    }
                    parts.lock().unwrap().push(range);
                })
            });
            assert!(a.iter().enumerate().all(|(i, &x)| x == i as f32), "{len}");
            assert!(b[..len].iter().all(|&x| x == 1.0) && b[len..].iter().all(|&x| x == 0.0));
            let mut parts = parts.into_inner().unwrap();
            parts.sort_by_key(|r| r.start);
            let members = if len >= PARALLEL_ELEMENTS { 3 } else { 1 };
            assert_eq!(parts.len(), members, "{len}");
            assert!(
                parts
                    .iter()
                    .all(|r| r.start % 16 == 0 && !r.is_empty() || len == 0)
            );
            assert!(parts.windows(2).all(|w| w[0].end == w[1].start));
            assert_eq!((parts[0].start, parts[members - 1].end), (0, len));
        }
    }

    /// The ranges folded are `each_part`'s (one a member from its size on), joined in
    /// order; no element, no result.
    #[test]
    fn fold_parts_joins_each_members_part_in_order() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .expect("a pool of 3");
        for len in [0, 5, PARALLEL_ELEMENTS - 1, PARALLEL_ELEMENTS + 37] {
            let join = |mut a: Vec<std::ops::Range<usize>>, b| {
                a.extend(b);
                a
            };
            let parts = pool.install(|| fold_parts(len, |r| vec![r], join));
            let Some(parts) = parts else {
                assert_eq!(len, 0);
                continue;
            };
            let members = if len >= PARALLEL_ELEMENTS { 3 } else { 1 };
            assert_eq!(parts.len(), members, "{len}");
            assert!(parts.windows(2).all(|w| w[0].end == w[1].start));
            assert_eq!((parts[0].start, parts[members - 1].end), (0, len));
            // The same ranges as `each_part`'s.
            let cut = Mutex::new(Vec::new());
            let mut x = vec![0u8; len];
            pool.install(|| each_part([&mut x], |r, _| cut.lock().unwrap().push(r)));
            let mut cut = cut.into_inner().unwrap();
            cut.sort_by_key(|r| r.start);
            assert_eq!(cut, parts, "{len}");
        }
    }

    #[test]
    fn within_cuts_a_range_short_where_the_slice_ends() {
        let s = [1, 2, 3, 4, 5];
        assert_eq!(within(&s, 1..3), &[2, 3]);
        assert_eq!(within(&s, 3..9), &[4, 5]);
        assert!(within(&s, 7..9).is_empty());
    }
}
