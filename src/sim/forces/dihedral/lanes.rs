//! The hinges' forces eight at a time (`f32` only): each hinge's four points are gathered
//! into SIMD lanes, its angle, gradient and scale taken lane by lane, and its four forces
//! added back hinge by hinge in the model's order. The lanes do the scalar path's IEEE
//! operations in its order (`+`, `−`, `×`, `÷` and `√` are correctly rounded whether in a
//! lane or not), so the forces are the scalar path's to the bit but for the angle's
//! arctangent, which is [`f32x8::atan2`]'s (within a few units in the last place of
//! `f32::atan2`, see the test below).

use glam::Vec3;
use wide::f32x8;

/// Hinges a chunk holds: the lanes of an `f32x8`.
const LANES: usize = 8;

/// Eight points' coordinates, one point a lane.
#[derive(Clone, Copy)]
struct Points {
    x: f32x8,
    y: f32x8,
    z: f32x8,
}

impl Points {
    fn gather(pos: &[Vec3], hinges: &[[u32; 4]], corner: usize) -> Points {
        let [mut x, mut y, mut z] = [[0.0f32; LANES]; 3];
        for (lane, h) in hinges.iter().enumerate() {
            let p = pos[h[corner] as usize];
            (x[lane], y[lane], z[lane]) = (p.x, p.y, p.z);
        }
        Points {
            x: x.into(),
            y: y.into(),
            z: z.into(),
        }
    }

    fn sub(self, o: Points) -> Points {
        Points {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }

    fn add(self, o: Points) -> Points {
        Points {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }

    fn scale(self, s: f32x8) -> Points {
        Points {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    /// As `glam::Vec3::cross`.
    fn cross(self, o: Points) -> Points {
        Points {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }

    /// As `glam::Vec3::dot`.
    fn dot(self, o: Points) -> f32x8 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    fn neg(self) -> Points {
        Points {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }

    /// The eight points, one a lane.
    fn unpack(self) -> [Vec3; LANES] {
        let (x, y, z) = (self.x.to_array(), self.y.to_array(), self.z.to_array());
        std::array::from_fn(|lane| Vec3::new(x[lane], y[lane], z[lane]))
    }
}

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
        let [x0, x1, a, b] = [0, 1, 2, 3].map(|k| Points::gather(pos, hinges, k));
        let lanes = |v: &[f32]| {
            let mut l = [0.0f32; LANES];
            l[..v.len()].copy_from_slice(v);
            f32x8::from(l)
        };
        let (rest, weight) = (lanes(rest), lanes(weight));
        // `hinge_angle`, lane by lane.
        let e = x1.sub(x0);
        let len2 = e.dot(e);
        let na = e.cross(a.sub(x0));
        let nb = x0.sub(x1).cross(b.sub(x1));
        let (na2, nb2) = (na.dot(na), nb.dot(nb));
        let degenerate = len2.simd_le(tiny) | na2.simd_le(tiny) | nb2.simd_le(tiny);
        let len = len2.sqrt();
        let axis = Points {
            x: e.x / len,
            y: e.y / len,
            z: e.z / len,
        };
        let theta = na.cross(nb).dot(axis).atan2(na.dot(nb));
        let ga = na.neg().scale(len / na2);
        let gb = nb.neg().scale(len / nb2);
        let alpha_a = a.sub(x0).dot(e) / len2;
        let alpha_b = b.sub(x0).dot(e) / len2;
        let g0 = ga.scale(alpha_a - one).add(gb.scale(alpha_b - one));
        let g1 = ga.scale(-alpha_a).sub(gb.scale(alpha_b));
        // `wing_limit`.
        let largest = ga.dot(ga).sqrt().max(gb.dot(gb).sqrt());
        let cap = one / (f32x8::splat(min_wing) * len);
        let limit = largest.simd_gt(cap).select(cap / largest, one);
        // `angle_difference`.
        let d = theta - rest;
        let d = d.simd_gt(pi).select(d - tau, d);
        let d = d.simd_lt(-pi).select(d + tau, d);
        let scale = twice * weight * d * limit;
        let grads = [g0, g1, ga, gb].map(|g| g.scale(scale).unpack());
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
