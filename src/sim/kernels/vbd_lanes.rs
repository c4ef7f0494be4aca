//! Vertex block descent's particle step, one particle at a time or, for a group of eight of
//! one colour, eight at a time in AVX2 lanes with the same IEEE operations in the same order
//! (the same bits either way).

use std::ops::Range;

use glam::Vec3;

use crate::cloth::{Real, Vector};
use crate::parallel::Disjoint;

#[cfg(target_arch = "x86_64")]
use super::lanes::{LANES, Row, V3, add, dot, load_rows, scale, store_rows, sub};
use super::vbd_stencil::{GROUP, Stencil};

/// A particle's position at the start of the step, its displacement this step, its inverse
/// mass and its mass: eight f32 in this order (the AVX2 sweep loads a particle as one 32-byte
/// row).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
pub struct Particle<R: Real = f32> {
    pub pos: R::V3,
    pub disp: R::V3,
    pub inv_mass: R,
    pub mass: R,
}

// SAFETY: `Particle` is eight f32, `repr(C, align(32))`.
#[cfg(target_arch = "x86_64")]
unsafe impl Row for Particle {}

/// The step's numbers: `h`, `h²` and `1/h`.
#[derive(Clone, Copy, Debug)]
pub struct StepLength<R: Real = f32> {
    pub h: R,
    pub h2: R,
    pub inv_h: R,
}

impl<R: Real> StepLength<R> {
    pub fn new(h: R) -> Self {
        Self {
            h,
            h2: h * h,
            inv_h: R::ONE / h,
        }
    }
}

/// Below this a spring's length counts as zero (no direction): the spring is left out.
const TINY: f32 = 1e-9;

/// Moves the particles `order[range]` (of one colour) by their Newton steps, in order;
/// eight at a time where they make a group and the CPU has AVX2.
///
/// # Safety
/// The range lies in one colour of `stencil`, which was built for `particles.len()`
/// particles; `inertial` is as long; no other thread uses these particles or reads them, or
/// writes any particle they are linked to, meanwhile.
pub unsafe fn descend_range(
    stencil: &Stencil,
    particles: &Disjoint<'_, Particle>,
    inertial: &[Vec3],
    range: Range<usize>,
    step: StepLength,
    eights: bool,
) {
    let mut i = range.start;
    #[cfg(target_arch = "x86_64")]
    if eights && std::arch::is_x86_feature_detected!("avx2") {
        while i + GROUP <= range.end && stencil.group_at(i) {
            // SAFETY: the CPU has AVX2; the rest is the caller's contract.
            unsafe { descend_eight_avx2(stencil, particles, inertial, i, step) };
            i += GROUP;
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = eights;
    for i in i..range.end {
        // SAFETY: the caller's contract.
        unsafe { descend(stencil, particles, inertial, i, step) };
    }
}

/// As [`descend_range`] one particle at a time, in any precision (the `f64` path; in `f32`
/// the same bits as [`descend_range`]).
///
/// # Safety
/// As [`descend_range`].
pub unsafe fn descend_range_plain<R: Real>(
    stencil: &Stencil,
    particles: &Disjoint<'_, Particle<R>>,
    inertial: &[R::V3],
    range: Range<usize>,
    step: StepLength<R>,
) {
    for i in range {
        // SAFETY: the caller's contract.
        unsafe { descend(stencil, particles, inertial, i, step) };
    }
}

/// The Newton step of the `i`-th particle `p` in the sweep's order with every other particle
/// held: `dₚ ← dₚ − Hₚ⁻¹·gₚ`, with the gradient `gₚ = mₚ(dₚ − ŷₚ) − h²·Σ fₛ` and the
/// Hessian block `Hₚ = mₚ·I + Σ (h²k·(n nᵀ + max(0, 1 − L/l)·(I − n nᵀ)) + h·c·n nᵀ)` over
/// its springs `s` (`fₛ`: the spring's pull on `p`, its dashpot acting on `d/h`). A pinned
/// particle, or one whose block is not positive definite, stays.
///
/// # Safety
/// As [`descend_range`].
#[inline(always)]
unsafe fn descend<R: Real>(
    stencil: &Stencil,
    particles: &Disjoint<'_, Particle<R>>,
    inertial: &[R::V3],
    i: usize,
    StepLength { h, h2, inv_h }: StepLength<R>,
) {
    let p = stencil.order[i] as usize;
    let read = |q: usize| {
        assert!(q < particles.len());
        // SAFETY: in bounds; no other thread writes it (the caller's contract).
        unsafe { *particles.as_ptr().add(q) }
    };
    let me = read(p);
    if me.inv_mass == R::ZERO {
        return;
    }
    let (x, d) = (me.pos, me.disp);
    let mut g = (d - inertial[p]) * me.mass;
    let (zero, one, tiny) = (R::ZERO, R::ONE, R::of_f32(TINY));
    // The block's upper triangle: xx, yy, zz, xy, xz, yz.
    let mut hs = [me.mass, me.mass, me.mass, zero, zero, zero];
    for l in stencil.links_at(i) {
        let other = read(stencil.other[l] as usize);
        let moved = other.disp - d;
        let u = (other.pos - x) + moved;
        let len = u.length();
        let live = len > tiny;
        let len = if live { len } else { tiny };
        let (k, c) = if live {
            (R::of_f32(stencil.k[l]), R::of_f32(stencil.c[l]))
        } else {
            (zero, zero)
        };
        let rest = R::of_f32(stencil.rest[l]);
        let inv_len = one / len;
        let n = u * inv_len;
        let pull = k * (len - rest) + (c * inv_h) * n.dot(moved);
        g -= n * (h2 * pull);
        let hk = h2 * k;
        let transverse = hk * (one - rest * inv_len).max(zero);
        let along = (hk - transverse) + h * c;
        let (an, n) = ((n * along).to_array(), n.to_array());
        hs[0] += transverse + an[0] * n[0];
        hs[1] += transverse + an[1] * n[1];
        hs[2] += transverse + an[2] * n[2];
        hs[3] += an[0] * n[1];
        hs[4] += an[0] * n[2];
        hs[5] += an[1] * n[2];
    }
    let [xx, yy, zz, xy, xz, yz] = hs;
    // The inverse by cofactors (the block is symmetric).
    let (c00, c01, c02) = (yy * zz - yz * yz, xz * yz - xy * zz, xy * yz - xz * yy);
    let (c11, c12, c22) = (xx * zz - xz * xz, xy * xz - xx * yz, xx * yy - xy * xy);
    let det = (xx * c00 + xy * c01) + xz * c02;
    if !(det > zero && det < R::of_f32(f32::INFINITY)) {
        return;
    }
    let [gx, gy, gz] = g.to_array();
    let s = R::V3::new(
        (c00 * gx + c01 * gy) + c02 * gz,
        (c01 * gx + c11 * gy) + c12 * gz,
        (c02 * gx + c12 * gy) + c22 * gz,
    );
    // SAFETY: `p` is in bounds (read above) and this thread's alone.
    unsafe { particles.at(p).disp = d - s / det };
}

/// [`descend`] for the group of eight at `order[i..i + 8]`, one particle per lane: the same
/// IEEE operations in the same order (no fused multiply-add). Lanes whose particle has
/// fewer links run its group's padded links, which add zero; a lane that does not move
/// stores what it loaded.
///
/// # Safety
/// As [`descend_range`]; `order[i..i + 8]` is a group, and the CPU has AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn descend_eight_avx2(
    stencil: &Stencil,
    particles: &Disjoint<'_, Particle>,
    inertial: &[Vec3],
    i: usize,
    StepLength { h, h2, inv_h }: StepLength,
) {
    use std::arch::x86_64::*;
    let n_particles = particles.len();
    let own = &stencil.order[i..i + LANES];
    assert!(
        own.iter()
            .all(|&p| (p as usize) < n_particles && (p as usize) < inertial.len())
    );
    let set = _mm256_set1_ps;
    let (zero, one, tiny) = (_mm256_setzero_ps(), set(1.0), set(TINY));
    let (h, h2, inv_h) = (set(h), set(h2), set(inv_h));
    // SAFETY: in bounds (checked); this thread's alone (the caller's contract).
    let [x0, x1, x2, d0, d1, d2, w, mass] = unsafe { load_rows(particles, own) };
    let (x, d): (V3, V3) = ([x0, x1, x2], [d0, d1, d2]);
    let column = |k: usize| {
        let values: [f32; LANES] = std::array::from_fn(|l| inertial[own[l] as usize][k]);
        // SAFETY: eight f32.
        unsafe { _mm256_loadu_ps(values.as_ptr()) }
    };
    let y = [column(0), column(1), column(2)];
    let mut g = scale(mass, sub(d, y));
    let mut hs = [mass, mass, mass, zero, zero, zero];
    let first = stencil.spans[i].first as usize;
    for slot in 0..stencil.group_slots(i) {
        let at = first + slot * LANES;
        let others = &stencil.other[at..at + LANES];
        assert!(others.iter().all(|&q| (q as usize) < n_particles));
        let (rest, k, c) = (
            &stencil.rest[at..at + LANES],
            &stencil.k[at..at + LANES],
            &stencil.c[at..at + LANES],
        );
        // SAFETY: in bounds (checked); no other thread writes them (the caller's contract);
        // each slice holds eight f32.
        let ([ox, oy, oz, odx, ody, odz, _, _], rest, k, c) = unsafe {
            (
                load_rows(particles, others),
                _mm256_loadu_ps(rest.as_ptr()),
                _mm256_loadu_ps(k.as_ptr()),
                _mm256_loadu_ps(c.as_ptr()),
            )
        };
        let moved = sub([odx, ody, odz], d);
        let u = add(sub([ox, oy, oz], x), moved);
        let len = _mm256_sqrt_ps(dot(u, u));
        let live = _mm256_cmp_ps::<_CMP_GT_OQ>(len, tiny);
        let len = _mm256_blendv_ps(tiny, len, live);
        let (k, c) = (
            _mm256_blendv_ps(zero, k, live),
            _mm256_blendv_ps(zero, c, live),
        );
        let inv_len = _mm256_div_ps(one, len);
        let n = scale(inv_len, u);
        let pull = _mm256_add_ps(
            _mm256_mul_ps(k, _mm256_sub_ps(len, rest)),
            _mm256_mul_ps(_mm256_mul_ps(c, inv_h), dot(n, moved)),
        );
        g = sub(g, scale(_mm256_mul_ps(h2, pull), n));
        let hk = _mm256_mul_ps(h2, k);
        let stretch = _mm256_sub_ps(one, _mm256_mul_ps(rest, inv_len));
        let transverse = _mm256_mul_ps(hk, _mm256_max_ps(stretch, zero));
        let along = _mm256_add_ps(_mm256_sub_ps(hk, transverse), _mm256_mul_ps(h, c));
        let an = scale(along, n);
        for axis in 0..3 {
            let own_term = _mm256_mul_ps(an[axis], n[axis]);
            hs[axis] = _mm256_add_ps(hs[axis], _mm256_add_ps(transverse, own_term));
        }
        hs[3] = _mm256_add_ps(hs[3], _mm256_mul_ps(an[0], n[1]));
        hs[4] = _mm256_add_ps(hs[4], _mm256_mul_ps(an[0], n[2]));
        hs[5] = _mm256_add_ps(hs[5], _mm256_mul_ps(an[1], n[2]));
    }
    let [xx, yy, zz, xy, xz, yz] = hs;
    let (mul, minus) = (_mm256_mul_ps, _mm256_sub_ps);
    let c00 = minus(mul(yy, zz), mul(yz, yz));
    let c01 = minus(mul(xz, yz), mul(xy, zz));
    let c02 = minus(mul(xy, yz), mul(xz, yy));
    let c11 = minus(mul(xx, zz), mul(xz, xz));
    let c12 = minus(mul(xy, xz), mul(xx, yz));
    let c22 = minus(mul(xx, yy), mul(xy, xy));
    let det = _mm256_add_ps(_mm256_add_ps(mul(xx, c00), mul(xy, c01)), mul(xz, c02));
    let row = |a: __m256, b: __m256, c: __m256| {
        _mm256_add_ps(_mm256_add_ps(mul(a, g[0]), mul(b, g[1])), mul(c, g[2]))
    };
    let s = [row(c00, c01, c02), row(c01, c11, c12), row(c02, c12, c22)];
    let moves = _mm256_and_ps(
        _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GT_OQ>(det, zero),
            _mm256_cmp_ps::<_CMP_LT_OQ>(det, set(f32::INFINITY)),
        ),
        _mm256_cmp_ps::<_CMP_NEQ_UQ>(w, zero),
    );
    let new = |axis: usize| {
        let moved = _mm256_sub_ps(d[axis], _mm256_div_ps(s[axis], det));
        _mm256_blendv_ps(d[axis], moved, moves)
    };
    let columns = [x0, x1, x2, new(0), new(1), new(2), w, mass];
    // SAFETY: as the load above.
    unsafe { store_rows(particles, own, columns) };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::constraints::DistanceConstraints;

    /// A 24 × 24 grid's 12-neighbour springs over randomly moved particles, among them a
    /// pinned one, two at one point and a non-finite one.
    fn scene() -> (Stencil, Vec<Particle>, Vec<Vec3>) {
        let mut seed = 0x9e37_79b9_u32;
        let mut random = move || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed as f32 / u32::MAX as f32 - 0.5
        };
        let side = 24;
        let mut c = DistanceConstraints::default();
        for i in 0..side {
            for j in 0..side {
                for (di, dj) in [(0, 1), (1, 0), (1, 1), (1, -1), (0, 2), (2, 0)] {
                    let (ni, nj) = (i + di, j + dj);
                    if ni < side && (0..side).contains(&nj) {
                        c.a.push((i * side + j) as u32);
                        c.b.push((ni * side + nj) as u32);
                        c.rest.push(0.04 * (1.0 + 0.2 * random()));
                        c.compliance.push(1e-3 * (1.0 + random()));
                        c.damping.push(0.02 * (1.0 + random()));
                    }
                }
            }
        }
        let n = (side * side) as usize;
        let mut particles: Vec<Particle> = (0..n)
            .map(|p| Particle {
                pos: Vec3::new((p % 24) as f32 * 0.04, (p / 24) as f32 * 0.04, 0.0)
                    + 0.01 * Vec3::new(random(), random(), random()),
                disp: 1e-3 * Vec3::new(random(), random(), random()),
                inv_mass: 1e4,
                mass: 1e-4,
            })
            .collect();
        particles[30].inv_mass = 0.0;
        particles[41].pos = particles[40].pos;
        particles[41].disp = particles[40].disp;
        particles[77].pos.x = f32::NAN;
        let inertial = (0..n).map(|_| 1e-3 * Vec3::new(random(), random(), random()));
        (Stencil::new(&c, n), particles, inertial.collect())
    }

    #[test]
    fn a_sweep_eight_at_a_time_gives_the_same_bits_as_one_at_a_time() {
        let (stencil, start, inertial) = scene();
        let step = StepLength::new(1.0 / 600.0);
        let sweep = |eights: bool| {
            let mut particles = start.clone();
            let rows = Disjoint::new(&mut particles);
            for colour in &stencil.colours {
                // SAFETY: one thread; the range is one colour; lengths match.
                unsafe { descend_range(&stencil, &rows, &inertial, colour.clone(), step, eights) };
            }
            // Any NaN counts as the same value (IEEE leaves its sign and payload open).
            let bits = |v: Vec3| {
                v.to_array()
                    .map(|x| if x.is_nan() { 0 } else { x.to_bits() })
            };
            particles.iter().map(|p| bits(p.disp)).collect::<Vec<_>>()
        };
        let (one_by_one, eights) = (sweep(false), sweep(true));
        assert_eq!(one_by_one, eights);
        let moved = |p: usize| one_by_one[p] != start[p].disp.to_array().map(f32::to_bits);
        assert!(
            moved(0) && moved(300) && moved(41),
            "the sweep moved particles"
        );
        assert!(!moved(30), "a pinned particle stays");
        let groups = (0..stencil.order.len())
            .filter(|&i| stencil.group_at(i))
            .count();
        assert!(groups >= 40, "{groups} groups of eight: the lanes ran");
    }
}
