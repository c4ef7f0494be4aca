//! Loops over arrays of points (`Vec3`, three floats each) read as plain floats, twelve
//! (four points) at a time, so that the compiler runs them in vector lanes: a `Vec3`'s
//! own arithmetic is scalar. Each float goes through the same IEEE operations in the same
//! order as the `Vec3` arithmetic it replaces, so the results are the same bits.

use glam::Vec3;

/// Floats in a step: four points, the least whole number of points that fills whole
/// vector lanes.
const STEP: usize = 12;

/// `a` repeated along a step (x, y, z, x, y, z, …).
fn repeated(a: Vec3) -> [f32; STEP] {
    std::array::from_fn(|k| a[k % 3])
}

/// Sets `out[i] = x[i] − a − b` (in that order) for each point both have.
pub fn less_into(out: &mut [Vec3], x: &[Vec3], a: Vec3, b: Vec3) {
    let n = out.len().min(x.len());
    let out: &mut [f32] = bytemuck::cast_slice_mut(&mut out[..n]);
    let x: &[f32] = bytemuck::cast_slice(&x[..n]);
    let (a, b) = (repeated(a), repeated(b));
    let (mut outs, mut xs) = (out.chunks_exact_mut(STEP), x.chunks_exact(STEP));
    for (o, x) in (&mut outs).zip(&mut xs) {
        for k in 0..STEP {
            o[k] = x[k] - a[k] - b[k];
        }
    }
    let rest = outs.into_remainder().iter_mut().zip(xs.remainder());
    for (k, (o, x)) in rest.enumerate() {
        *o = x - a[k] - b[k];
    }
}

/// The box of `points` (its least and greatest coordinates), or `None` for no point.
/// Where a coordinate is NaN the box is not a box (as with any order of comparisons).
pub fn bounds(points: &[Vec3]) -> Option<(Vec3, Vec3)> {
    let first = *points.first()?;
    let x: &[f32] = bytemuck::cast_slice(points);
    let (mut lo, mut hi) = (repeated(first), repeated(first));
    let mut steps = x.chunks_exact(STEP);
    for x in &mut steps {
        for k in 0..STEP {
            lo[k] = if lo[k] < x[k] { lo[k] } else { x[k] };
            hi[k] = if hi[k] > x[k] { hi[k] } else { x[k] };
        }
    }
    for (k, &x) in steps.remainder().iter().enumerate() {
        lo[k] = lo[k].min(x);
        hi[k] = hi[k].max(x);
    }
    let fold = |v: [f32; STEP], pick: fn(f32, f32) -> f32| {
        Vec3::from_array(std::array::from_fn(|axis| {
            (axis..STEP).step_by(3).map(|k| v[k]).fold(v[axis], pick)
        }))
    };
    Some((fold(lo, f32::min), fold(hi, f32::max)))
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

    #[test]
    fn the_bounds_are_the_least_and_greatest_coordinates() {
        assert_eq!(bounds(&[]), None);
        for n in [1, 2, 4, 5, 13, 4225] {
            let x = points(n);
            let lo = x.iter().fold(Vec3::INFINITY, |lo, &p| lo.min(p));
            let hi = x.iter().fold(Vec3::NEG_INFINITY, |hi, &p| hi.max(p));
            assert_eq!(bounds(&x), Some((lo, hi)), "{n}");
        }
    }
}
