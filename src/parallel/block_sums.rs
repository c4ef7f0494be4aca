//! Loops that also sum: each fixed block of elements gives its partial sums, and the sums
//! add up over the blocks in their order, so they are the same bits on any number of
//! threads.

use super::disjoint::Disjoint;
use super::parts::PARALLEL_ELEMENTS;
use super::team::Team;

/// Blocks in a piece of a team section of [`sum_blocks`]: with the solve's blocks of 64
/// particles, about five hundred, a few microseconds of vector loops, so that a 64 × 64
/// cloth's loop is nine pieces for two members to share.
const PIECE_BLOCKS: usize = 8;

/// Runs `work(range, sums)` over `0..len`: once over the whole range, or, from
/// [`PARALLEL_ELEMENTS`] elements on, in pieces of whole blocks of `block` elements shared
/// by the current team (each piece run once, by whichever member takes it). `work` sets
/// `sums` (one entry per block of its range, the blocks counted from the range's start) to
/// each block's partial sums; the sums are added up over the blocks in order, from zero.
/// `partials` is the blocks' storage, kept between calls.
pub fn sum_blocks<const K: usize>(
    len: usize,
    block: usize,
    partials: &mut Vec<[f64; K]>,
    work: impl Fn(std::ops::Range<usize>, &mut [[f64; K]]) + Sync,
) -> [f64; K] {
    let block = block.max(1);
    let blocks = len.div_ceil(block);
    partials.resize(blocks, [0.0; K]);
    let team = Team::current();
    if len < PARALLEL_ELEMENTS || team.members() == 1 {
        work(0..len, &mut partials[..blocks]);
    } else {
        let out = Disjoint::new(&mut partials[..blocks]);
        team.run_pieces(blocks.div_ceil(PIECE_BLOCKS), &|_, k| {
            let piece = k * PIECE_BLOCKS..((k + 1) * PIECE_BLOCKS).min(blocks);
            let range = piece.start * block..(piece.end * block).min(len);
            // SAFETY: each piece runs once, so each block's sums have one writer.
            work(range, unsafe { out.part(piece) });
        });
    }
    partials[..blocks].iter().fold([0.0; K], |mut total, sums| {
        total.iter_mut().zip(sums).for_each(|(t, s)| *t += s);
        total
    })
}

/// Sets each of `sums` to `sum` of its block of a range of `len` elements, `block` each
/// (the blocks' ranges counted from the range's start): the inner loop of a
/// [`sum_blocks`] work.
#[inline(always)]
pub fn each_block<const K: usize>(
    len: usize,
    block: usize,
    sums: &mut [[f64; K]],
    sum: impl Fn(std::ops::Range<usize>) -> [f64; K],
) {
    for (k, out) in sums.iter_mut().enumerate() {
        *out = sum(k * block..((k + 1) * block).min(len));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    /// Every element is summed once, in blocks of the given size that do not depend on
    /// the team: the members' pieces are whole blocks, and the total is the blocks' sums
    /// added in order, to the bit (the second sum's rounding tells another order).
    #[test]
    fn sums_come_from_whole_blocks_added_in_order_on_any_team() {
        let pools = [1, 2, 3].map(|threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a pool")
        });
        for len in [
            0,
            1,
            63,
            64,
            65,
            PARALLEL_ELEMENTS - 1,
            PARALLEL_ELEMENTS + 4_001,
        ] {
            let block = 64;
            // Each block sums to 1 but the first, which holds 2^53: added in order, each 1
            // is a tie that rounds back to 2^53; added another way, the ones survive.
            let weight = |i: usize| {
                if i == 0 {
                    2f64.powi(53)
                } else {
                    1.0 / block as f64
                }
            };
            let in_order = (0..len.div_ceil(block))
                .map(|b| {
                    let r = b * block..((b + 1) * block).min(len);
                    [r.len() as f64, r.map(weight).sum::<f64>()]
                })
                .fold([0.0, 0.0], |[a, b], [x, y]| [a + x, b + y]);
            for pool in &pools {
                let ranges = Mutex::new(Vec::new());
                let mut partials = Vec::new();
                let got = pool.install(|| {
                    sum_blocks(len, block, &mut partials, |range, sums| {
                        assert_eq!(sums.len(), range.len().div_ceil(block));
                        ranges.lock().unwrap().push(range.clone());
                        each_block(range.len(), block, sums, |b| {
                            let r = range.start + b.start..range.start + b.end;
                            [r.len() as f64, r.map(weight).sum::<f64>()]
                        });
                    })
                });
                let threads = pool.current_num_threads();
                assert_eq!(got[0], len as f64, "{len} on {threads}");
                assert_eq!(
                    got[1].to_bits(),
                    in_order[1].to_bits(),
                    "{len} on {threads}"
                );
                let mut ranges = ranges.into_inner().unwrap();
                ranges.sort_by_key(|r| r.start);
                assert!(ranges.iter().all(|r| r.start % block == 0));
                assert!(ranges.windows(2).all(|w| w[0].end == w[1].start));
                let shared = len >= PARALLEL_ELEMENTS && threads > 1;
                assert_eq!(ranges.len() > 1, shared, "{len} on {threads}");
            }
        }
    }
}
