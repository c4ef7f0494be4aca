//! The hinges' forces eight at a time (`f32` only): each hinge's four points are gathered
//! into SIMD lanes, its angle, gradient and scale taken lane by lane, and its four forces
//! added back hinge by hinge in the model's order. The lanes do the scalar path's IEEE
//! operations in its order (`+`, `−`, `×`, `÷` and `√` are correctly rounded whether in a
//! lane or not), so the forces are the scalar path's to the bit but for the angle's
//! arctangent, which is [`f32x8::atan2`]'s (within a few units in the last place of
//! `f32::atan2`, see the test below).

use glam::Vec3;
use wide::f32x8;

use crate::sim::kernels::{LANES, Vec3x8, padded};

/// Adds every hinge's force `−2k·w·(θ − θ₀)·∂θ/∂x`, limited for slivers, to `f`: what
/// [`super::DihedralBending::add_forces`] adds, eight hinges at a time, for each hinge's
/// rest angle and weight, the stiffness `k` and the least wing `min_wing` (of its hinge's
/// length) whose force is not limited.
pub(super) fn add_forces(
    hinges: &[[u32; 4]],
    [rest, weight]: [&[f32]; 2],
    [k, min_wing]: [f32; 2],
    pos: &[Vec3],
    f: &mut [Vec3],
) {
    let (pi, tau) = (
        f32x8::splat(std::f32::consts::PI),
        f32x8::splat(std::f32::consts::TAU),
    );
    let (one, tiny) = (f32x8::splat(1.0), f32x8::splat(1e-24));
    let twice = f32x8::splat(-2.0 * k);
    for ((hinges, rest), weight) in (hinges.chunks(LANES))
        .zip(rest.chunks(LANES))
        .zip(weight.chunks(LANES))
    {
        let [x0, x1, a, b] = [0, 1, 2, 3].map(|k| Vec3x8::gather(pos, hinges, k));
        let (rest, weight) = (padded(rest), padded(weight));
        // `hinge_angle`, lane by lane.
        let e = x1 - x0;
        let len2 = e.dot(e);
        let na = e.cross(a - x0);
        let nb = (x0 - x1).cross(b - x1);
        let (na2, nb2) = (na.dot(na), nb.dot(nb));
        let degenerate = len2.simd_le(tiny) | na2.simd_le(tiny) | nb2.simd_le(tiny);
        let len = len2.sqrt();
        let theta = na.cross(nb).dot(e / len).atan2(na.dot(nb));
        let ga = -na * (len / na2);
        let gb = -nb * (len / nb2);
        let alpha_a = (a - x0).dot(e) / len2;
        let alpha_b = (b - x0).dot(e) / len2;
        let g0 = ga * (alpha_a - one) + gb * (alpha_b - one);
        let g1 = ga * -alpha_a - gb * alpha_b;
        // `wing_limit`.
        let largest = ga.dot(ga).sqrt().max(gb.dot(gb).sqrt());
        let cap = one / (f32x8::splat(min_wing) * len);
        let limit = largest.simd_gt(cap).select(cap / largest, one);
        // `angle_difference`.
        let d = theta - rest;
        let d = d.simd_gt(pi).select(d - tau, d);
        let d = d.simd_lt(-pi).select(d + tau, d);
        let scale = twice * weight * d * limit;
        let grads = [g0, g1, ga, gb].map(|g| (g * scale).unpack());
        let skip = degenerate.to_bitmask();
        for (lane, h) in hinges.iter().enumerate() {
            if skip & (1 << lane) == 0 {
                for (&i, g) in h.iter().zip(&grads) {
                    f[i as usize] += g[lane];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `f32x8::atan2` against `f64::atan2` rounded, over every quadrant, the axes and
    /// magnitudes from 1e-20 to 1e20: within 2 units in the last place, as `f32::atan2`.
    #[test]
    fn the_lanes_arctangent_is_within_two_units_in_the_last_place() {
        let mut worst = 0.0f64;
        let magnitudes = [1e-20f32, 1e-6, 0.01, 0.3, 1.0, 2.7, 100.0, 1e20];
        for k in 0..4096u32 {
            let angle = (k as f64 / 4096.0 - 0.5) * std::f64::consts::TAU;
            for &m in &magnitudes {
                let (y, x) = (
                    (m as f64 * angle.sin()) as f32,
                    (m as f64 * angle.cos()) as f32,
                );
                let lanes = f32x8::splat(y).atan2(f32x8::splat(x)).to_array()[0];
                let exact = (y as f64).atan2(x as f64);
                let ulp = (exact as f32).abs().max(f32::MIN_POSITIVE) * f32::EPSILON;
                worst = worst.max((lanes as f64 - exact).abs() / ulp as f64);
            }
        }
        assert!(worst <= 2.0, "{worst} units in the last place");
    }
}
