//! Loops over arrays of points (`Vec3`, three floats each) read as plain floats, twelve
//! (four points) at a time in three SSE lanes (glam's `Vec4`): a `Vec3`'s own arithmetic
//! is scalar. Each float goes through the same IEEE operations in the same order as the
//! `Vec3` (or `Vec3A`) arithmetic it replaces, so the results are the same bits.

use glam::{Vec3, Vec3A, Vec4};

/// Floats in a step: four points, the least whole number of points that fills whole
/// vector lanes.
const STEP: usize = 12;

/// The first `n` points of `v` as floats.
fn floats(v: &[Vec3], n: usize) -> &[f32] {
    bytemuck::cast_slice(&v[..n])
}

/// `a` repeated along a step (x, y, z, x, y, z, …), as the step's three lanes.
fn repeated(a: Vec3) -> [Vec4; 3] {
    lanes(&std::array::from_fn(|k| a[k % 3]))
}

/// A step of floats as its three lanes (each one unaligned load).
fn lanes(x: &[f32; STEP]) -> [Vec4; 3] {
    bytemuck::cast::<_, [[f32; 4]; 3]>(*x).map(Vec4::from)
}

/// Sets `out[i] = x[i] − a − b` (in that order) for each point both have.
pub fn less_into(out: &mut [Vec3], x: &[Vec3], a: Vec3, b: Vec3) {
    let n = out.len().min(x.len());
    let out: &mut [f32] = bytemuck::cast_slice_mut(&mut out[..n]);
    let x = floats(x, n);
    let (a, b) = (repeated(a), repeated(b));
    let ((outs, out_rest), (xs, x_rest)) = (out.as_chunks_mut::<STEP>(), x.as_chunks::<STEP>());
    for (o, x) in outs.iter_mut().zip(xs) {
        for (k, x) in lanes(x).into_iter().enumerate() {
            (x - a[k] - b[k]).write_to_slice(&mut o[4 * k..]);
        }
    }
    for (k, (o, x)) in out_rest.iter_mut().zip(x_rest).enumerate() {
        *o = x - a[k / 4][k % 4] - b[k / 4][k % 4];
    }
}

/// Sets `out[i]` to whether the motion from `from[i]` to `to[i]`, grown by `g` along
/// every axis, leaves the box `boxes[0][i]..boxes[1][i]`, as [`leaves`] tells it, for each
/// point all five have.
pub fn outside(out: &mut [bool], [from, to]: [&[Vec3]; 2], boxes: [&[Vec3]; 2], g: f32) {
    let [lo, hi] = boxes;
    let n = (out.len().min(from.len()).min(to.len())).min(lo.len().min(hi.len()));
    let (s, e, lo, hi) = (floats(from, n), floats(to, n), floats(lo, n), floats(hi, n));
    let whole = n / 4 * 4;
    let [s, e, lo, hi] = [s, e, lo, hi].map(|x| x.as_chunks::<STEP>().0);
    let steps = (out[..whole].chunks_exact_mut(4).zip(s)).zip(e.iter().zip(lo.iter().zip(hi)));
    let g4 = Vec4::splat(g);
    for ((out, s), (e, (lo, hi))) in steps {
        let [s, e, lo, hi] = [lanes(s), lanes(e), lanes(lo), lanes(hi)];
        // Each float's bit: whether its axis keeps within the box.
        let inside = (0..3).fold(0u32, |bits, k| {
            let within = (s[k].min(e[k]) - g4).cmpge(lo[k]) & (s[k].max(e[k]) + g4).cmple(hi[k]);
            bits | within.bitmask() << (4 * k)
        });
        for (j, out) in out.iter_mut().enumerate() {
            *out = ((inside >> (3 * j)) & 7) != 7;
        }
    }
    for i in whole..n {
        out[i] = leaves(from[i], to[i], [boxes[0][i], boxes[1][i]], g);
    }
}

/// Whether the motion from `from` to `to`, grown by `g` along every axis, leaves the box
/// `lo..hi` (told lane-wise in `Vec3A`: a NaN coordinate leaves); [`outside`] tells four
/// at a time what this tells of one.
#[inline]
pub fn leaves(from: Vec3, to: Vec3, [lo, hi]: [Vec3; 2], g: f32) -> bool {
    let (s, p) = (Vec3A::from(from), Vec3A::from(to));
    !((s.min(p) - g).cmpge(lo.into()).all() && (s.max(p) + g).cmple(hi.into()).all())
}

/// Sets `before` to `now`, flagging in `moved` (resized to match) each point that
/// differed, as `!=` tells it (a NaN differs from itself; the zeros of both signs are
/// equal), four points at a time.
pub fn take_moves(before: &mut [Vec3], now: &[Vec3], moved: &mut Vec<bool>) {
    moved.clear();
    moved.resize(before.len().min(now.len()), false);
    take(before, now, |first, points, bits| {
        for (j, m) in moved[first..first + points].iter_mut().enumerate() {
            *m = (bits >> (3 * j)) & 7 != 0;
        }
    });
}

/// Sets `before` to `now` (the points both have); returns whether any differed, as `!=`
/// tells it ([`take_moves`] without the flags).
pub fn take_changes(before: &mut [Vec3], now: &[Vec3]) -> bool {
    let mut any = 0;
    take(before, now, |_, _, bits| any |= bits);
    any != 0
}

/// Sets `before` to `now` (the points both have), calling `differ(first, points, bits)`
/// for each four points (one past the last four) with the bits, three a point in order,
/// of their coordinates that differed.
#[inline(always)]
fn take(before: &mut [Vec3], now: &[Vec3], mut differ: impl FnMut(usize, usize, u32)) {
    let n = before.len().min(now.len());
    let whole = n / 4 * 4;
    let (b, x): (&mut [f32], _) = (bytemuck::cast_slice_mut(&mut before[..n]), floats(now, n));
    let (bs, xs) = (b.as_chunks_mut::<STEP>().0, x.as_chunks::<STEP>().0);
    for (k, (b, x)) in bs.iter_mut().zip(xs).enumerate() {
        differ(4 * k, 4, differing(b, x));
        *b = *x;
    }
    for i in whole..n {
        let (b, x) = (before[i], now[i]);
        let bits = (0..3).fold(0, |bits, k| bits | u32::from(b[k] != x[k]) << k);
        differ(i, 1, bits);
        before[i] = x;
    }
}

/// The floats of a step (as bits, in order) that differ between `a` and `b`.
#[inline(always)]
fn differing(a: &[f32; STEP], b: &[f32; STEP]) -> u32 {
    let (a, b) = (lanes(a), lanes(b));
    (0..3).fold(0, |bits, k| bits | a[k].cmpne(b[k]).bitmask() << (4 * k))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points spread over several metres, with coordinates of both signs and zeros of
    /// both signs, in numbers that leave every remainder of a step.
    fn points(n: usize) -> Vec<Vec3> {
        let mut rnd = crate::test_rng::uniform(5);
        (0..n)
            .map(|i| match i % 7 {
                0 => Vec3::new(0.0, -0.0, 1.0),
                _ => Vec3::new(rnd() - 0.5, rnd() * 3.0, -rnd()) * 4.0,
            })
            .collect()
    }

    #[test]
    fn points_less_two_offsets_are_what_vec3s_arithmetic_gives_to_the_bit() {
        let (a, b) = (Vec3::new(0.3, -1.7, 2.0e-3), Vec3::new(-1e-7, 0.25, 0.0));
        for n in [0, 1, 3, 4, 5, 11, 100, 4225] {
            let x = points(n);
            let mut out = vec![Vec3::splat(9.0); n];
            less_into(&mut out, &x, a, b);
            let want: Vec<Vec3> = x.iter().map(|&p| p - a - b).collect();
            let bits = |v: &[Vec3]| {
                v.iter()
                    .map(|p| p.to_array().map(f32::to_bits))
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(&out), bits(&want), "{n}");
        }
        // The shorter array sets how many.
        let (x, mut out) = (points(9), vec![Vec3::ZERO; 6]);
        less_into(&mut out, &x, a, b);
        assert_eq!(out[5], x[5] - a - b);
    }

    /// Taking the points flags each that differed as `!=` tells it (a NaN, even the same
    /// NaN, differs; the zeros of both signs do not), whatever the remainder of a step, and
    /// leaves the points taken.
    #[test]
    fn taking_points_flags_those_that_moved_as_not_equal_tells_it() {
        for n in [0, 1, 3, 4, 5, 6, 8, 11, 99, 4225] {
            let before = points(n);
            let mut now = before.clone();
            for (i, p) in now.iter_mut().enumerate() {
                match i % 5 {
                    1 => p.z += 1e-6,
                    2 if i % 3 == 0 => p.x = -p.x,
                    3 => *p = -*p * 0.0,
                    _ => {}
                }
            }
            if n > 6 {
                (now[6].y, now[4]) = (f32::NAN, Vec3::splat(f32::NAN));
            }
            if n > 7 {
                // `points` puts (0, −0, 1) there.
                now[7] = Vec3::new(-0.0, 0.0, 1.0);
            }
            let mut before_nan = before.clone();
            if n > 6 {
                before_nan[4] = Vec3::splat(f32::NAN);
            }
            // Past the last four points too: the zeros of both signs, and the same NaN.
            let last = n.saturating_sub(1);
            if n % 4 >= 2 && n > 4 {
                (before_nan[last], now[last]) =
                    (Vec3::new(0.0, -0.0, 0.0), Vec3::new(-0.0, 0.0, 0.0));
                (before_nan[last - 1], now[last - 1]) = (Vec3::NAN, Vec3::NAN);
            }
            let want: Vec<bool> = before_nan.iter().zip(&now).map(|(a, b)| a != b).collect();
            let (mut taken, mut moved) = (before_nan.clone(), vec![true; 2]);
            take_moves(&mut taken, &now, &mut moved);
            assert_eq!(moved, want, "{n}");
            let bits = |v: &[Vec3]| {
                v.iter()
                    .map(|p| p.to_array().map(f32::to_bits))
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(&taken), bits(&now), "{n}");
            let mut again = before_nan.clone();
            assert_eq!(take_changes(&mut again, &now), want.contains(&true), "{n}");
            assert_eq!(bits(&again), bits(&now), "{n}");
            if n > 7 {
                assert!(!moved[7], "the zeros of both signs are equal");
            }
            if n % 4 >= 2 && n > 4 {
                assert!(!moved[last] && moved[last - 1], "past the last four, {n}");
            }
            if n > 6 {
                assert!(moved[4] && moved[6], "a NaN differs, even from itself");
                assert!(want.iter().any(|&m| !m) && want.iter().filter(|&&m| m).count() > 2);
            }
        }
        // Nothing moved: nothing flagged, no change.
        let same = points(13);
        let (mut taken, mut moved) = (same.clone(), Vec::new());
        take_moves(&mut taken, &same, &mut moved);
        assert_eq!(moved, vec![false; 13]);
        assert!(!take_changes(&mut taken, &same));
    }

    /// Whether a motion grown by `g` leaves a box, as `Vec3A` tells it, for boxes around
    /// each motion grown by a little more or less than `g` along one axis or another, and
    /// for NaN coordinates.
    #[test]
    fn a_motion_leaves_its_box_where_vec3as_lanes_say_it_does() {
        use glam::Vec3A;
        let g = 0.01;
        let mut rnd = crate::test_rng::uniform(9);
        for n in [0, 1, 4, 6, 99] {
            let (from, to) = (points(n), points(n + 3));
            let mut to: Vec<Vec3> = to[3..].to_vec();
            if n > 5 {
                to[5].y = f32::NAN;
            }
            // Every third box just holds its motion (to the rounding), every third leaves
            // room, the others are a little off along random axes.
            let grown: Vec<[Vec3; 2]> = (from.iter().zip(&to).enumerate())
                .map(|(i, (&a, &b))| {
                    let mut wiggle = || Vec3::new(rnd(), rnd(), rnd()) * 0.004 - 0.002;
                    let room = [Vec3::ZERO, Vec3::splat(0.001), wiggle()][i % 3];
                    [a.min(b) - g - room, a.max(b) + g + room]
                })
                .collect();
            let (lo, hi): (Vec<Vec3>, Vec<Vec3>) = grown.iter().map(|&[l, h]| (l, h)).unzip();
            let mut out = vec![false; n];
            outside(&mut out, [&from, &to], [&lo, &hi], g);
            let want: Vec<bool> = (0..n)
                .map(|i| {
                    let (s, p) = (Vec3A::from(from[i]), Vec3A::from(to[i]));
                    let (l, h) = (Vec3A::from(lo[i]), Vec3A::from(hi[i]));
                    !((s.min(p) - g).cmpge(l).all() && (s.max(p) + g).cmple(h).all())
                })
                .collect();
            assert_eq!(out, want, "{n}");
            if n > 5 {
                assert!(out[5], "a NaN leaves");
                assert!(out.iter().any(|&o| !o) && out.iter().filter(|&&o| o).count() > 1);
            }
        }
    }
}
