//! XPBD's projection of distance constraints, one at a time or, for a colour whose
//! constraints share no particle, eight at a time in AVX2 lanes with the same IEEE
//! operations in the same order (the same bits either way).

use std::ops::Range;

use crate::cloth::{Real, Vector};
use crate::parallel::Disjoint;
use crate::sim::constraints::DistanceConstraints;

#[cfg(target_arch = "x86_64")]
use super::lanes::{LANES, Row, V3, add, dot, load_rows, scale, store_rows, sub};

/// A particle's predicted position and its displacement this step, and its inverse mass:
/// eight f32 in this order (the AVX2 sweep loads and stores a particle as one 32-byte row).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct Moved<R: Real = f32> {
    pub predicted: R::V3,
    pub displacement: R::V3,
    pub inv_mass: R,
    pub pad: R,
}

/// Each constraint's compliance and damping as the projection uses them at step `h`:
/// `α̃ = α/h²` and `γ = α·c/h` (in constraint order; kept while `h` and the constraints
/// stay).
#[derive(Default)]
pub struct Scaled<R: Real = f32> {
    pub h: Option<R>,
    pub alpha: Vec<R>,
    pub gamma: Vec<R>,
}

impl<R: Real> Scaled<R> {
    /// Recomputed for step `h` when it or the constraints changed.
    pub fn update(&mut self, c: &DistanceConstraints, h: R) {
        if self.h == Some(h) && self.alpha.len() == c.len() {
            return;
        }
        let of = R::of_f32;
        self.alpha = c.compliance.iter().map(|&a| of(a) / (h * h)).collect();
        let with_damping = c.compliance.iter().zip(&c.damping);
        self.gamma = (with_damping.map(|(&a, &damping)| of(a * damping) / h)).collect();
        self.h = Some(h);
    }
}

/// Projects constraints `range` in order; when `independent` (no two of them share a
/// particle) and the CPU has AVX2, eight at a time, one per SIMD lane, with the same IEEE
/// operations in the same order as `project` (no fused multiply-add): the same bits
/// either way.
///
/// # Safety
/// Every constraint's particles are in `moved`; no other thread may use these constraints'
/// particles or multipliers meanwhile; `lambda` and `s`'s arrays are at least as long as `c`.
pub unsafe fn project_range(
    c: &DistanceConstraints,
    s: &Scaled,
    range: Range<usize>,
    independent: bool,
    moved: &Disjoint<'_, Moved>,
    lambda: &Disjoint<'_, f32>,
) {
    let mut rest = range;
    #[cfg(target_arch = "x86_64")]
    if independent && std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above); the rest is the caller's
        // contract.
        rest = unsafe { project_eights_avx2(c, s, rest, moved, lambda) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = independent;
    for k in rest {
        // SAFETY: the caller's contract.
        unsafe { project(c, s, k, moved, lambda) };
    }
}

/// As [`project_range`] one constraint at a time, in any precision (the `f64` path; in
/// `f32` the same bits as [`project_range`]).
///
/// # Safety
/// As [`project_range`].
pub unsafe fn project_range_plain<R: Real>(
    c: &DistanceConstraints,
    s: &Scaled<R>,
    range: Range<usize>,
    moved: &Disjoint<'_, Moved<R>>,
    lambda: &Disjoint<'_, R>,
) {
    for k in range {
        // SAFETY: the caller's contract.
        unsafe { project(c, s, k, moved, lambda) };
    }
}

/// Projects the whole groups of eight at the start of `range` (no two of whose constraints
/// share a particle), each in one pass of AVX2 instructions: the particles' rows loaded
/// and transposed into one register per quantity, the projection of [`project`] lane by
/// lane, and the columns transposed back and stored (a lane that does not move stores what it
/// loaded). Returns the constraints left over.
///
/// # Safety
/// As [`project_range`], and the CPU supports AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn project_eights_avx2(
    c: &DistanceConstraints,
    s: &Scaled,
    range: Range<usize>,
    moved: &Disjoint<'_, Moved>,
    lambda: &Disjoint<'_, f32>,
) -> Range<usize> {
    use std::arch::x86_64::*;
    let end = (range.end.min(c.len()).min(lambda.len()))
        .min(s.alpha.len())
        .min(s.gamma.len());
    let (zero, one, tiny) = (
        _mm256_setzero_ps(),
        _mm256_set1_ps(1.0),
        _mm256_set1_ps(1e-9),
    );
    let sign = _mm256_set1_ps(-0.0);
    let mut k = range.start;
    while k + LANES <= end {
        let group = k..k + LANES;
        let (a, b) = (&c.a[group.clone()], &c.b[group.clone()]);
        // SAFETY: every particle is in bounds, and this group's own (the caller's contract).
        let (ca, cb) = unsafe { (load_columns(moved, a), load_columns(moved, b)) };
        let (pa, dxa, wa) = (ca.predicted, ca.displacement, ca.inv_mass);
        let (pb, dxb, wb) = (cb.predicted, cb.displacement, cb.inv_mass);
        // SAFETY: `k + 8 ≤ end ≤ lambda.len()`; this thread alone uses these multipliers.
        let lambda_k = unsafe { lambda.part(group.clone()) };
        // SAFETY: each slice holds eight f32.
        let (rest, alpha, gamma, lam) = unsafe {
            (
                _mm256_loadu_ps(c.rest[group.clone()].as_ptr()),
                _mm256_loadu_ps(s.alpha[group.clone()].as_ptr()),
                _mm256_loadu_ps(s.gamma[group.clone()].as_ptr()),
                _mm256_loadu_ps(lambda_k.as_ptr()),
            )
        };
        let d = sub(pb, pa);
        let len = _mm256_sqrt_ps(dot(d, d));
        let w = _mm256_add_ps(wa, wb);
        // `project` returns when `wa + wb == 0` or `len <= 1e-9`: a lane moves otherwise.
        let moves = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_NEQ_UQ>(w, zero),
            _mm256_cmp_ps::<_CMP_NLE_UQ>(len, tiny),
        );
        // A lane that does not move computes too (perhaps 0/0); the blends below drop it.
        let n = scale(_mm256_div_ps(one, len), d);
        let rate = dot(n, sub(dxb, dxa));
        let constraint = _mm256_sub_ps(len, rest);
        let numerator = _mm256_sub_ps(
            _mm256_sub_ps(_mm256_xor_ps(constraint, sign), _mm256_mul_ps(alpha, lam)),
            _mm256_mul_ps(gamma, rate),
        );
        let denominator = _mm256_add_ps(_mm256_mul_ps(_mm256_add_ps(one, gamma), w), alpha);
        let dl = _mm256_div_ps(numerator, denominator);
        let keep = |old: V3, new: V3| [0, 1, 2].map(|i| _mm256_blendv_ps(old[i], new[i], moves));
        let lam = _mm256_blendv_ps(lam, _mm256_add_ps(lam, dl), moves);
        let (da, db) = (
            scale(_mm256_mul_ps(wa, dl), n),
            scale(_mm256_mul_ps(wb, dl), n),
        );
        let ca = Columns {
            predicted: keep(pa, sub(pa, da)),
            displacement: keep(dxa, sub(dxa, da)),
            ..ca
        };
        let cb = Columns {
            predicted: keep(pb, add(pb, db)),
            displacement: keep(dxb, add(dxb, db)),
            ..cb
        };
        // SAFETY: as the loads above; every a is stored before any b, so a constraint of a
        // particle with itself ends as `project` leaves it.
        unsafe {
            _mm256_storeu_ps(lambda_k.as_mut_ptr(), lam);
            store_columns(moved, a, ca);
            store_columns(moved, b, cb);
        }
        k += LANES;
    }
    k..range.end
}

/// Eight particles' rows of [`Moved`] as columns: one register per quantity, one lane per
/// particle.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
struct Columns {
    predicted: V3,
    displacement: V3,
    inv_mass: std::arch::x86_64::__m256,
    pad: std::arch::x86_64::__m256,
}

// SAFETY: `Moved` is eight f32, `repr(C, align(32))`.
#[cfg(target_arch = "x86_64")]
unsafe impl Row for Moved {}

/// The rows of `moved` at `ends` as columns.
///
/// # Safety
/// As [`load_rows`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn load_columns(moved: &Disjoint<'_, Moved>, ends: &[u32]) -> Columns {
    // SAFETY: the caller's contract.
    let [x, y, z, dx, dy, dz, inv_mass, pad] = unsafe { load_rows(moved, ends) };
    Columns {
        predicted: [x, y, z],
        displacement: [dx, dy, dz],
        inv_mass,
        pad,
    }
}

/// Stores columns as [`load_columns`] makes them back into the rows at `ends`.
///
/// # Safety
/// As [`store_rows`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn store_columns(moved: &Disjoint<'_, Moved>, ends: &[u32], c: Columns) {
    let ([x, y, z], [dx, dy, dz]) = (c.predicted, c.displacement);
    // SAFETY: the caller's contract.
    unsafe { store_rows(moved, ends, [x, y, z, dx, dy, dz, c.inv_mass, c.pad]) };
}

/// Projects constraint `k` (XPBD with constraint damping), moving its particles' predicted
/// positions and displacements and its multiplier.
///
/// # Safety
/// Constraint `k`'s particles are in `moved`, and no other thread uses them or its
/// multiplier meanwhile; `lambda` is at least as long as `c`.
#[inline(always)]
unsafe fn project<R: Real>(
    c: &DistanceConstraints,
    s: &Scaled<R>,
    k: usize,
    moved: &Disjoint<'_, Moved<R>>,
    lambda: &Disjoint<'_, R>,
) {
    let (a, b) = (c.a[k] as usize, c.b[k] as usize);
    // SAFETY: in bounds (`c.a[k]` checked, the rest by the caller's contract); no other
    // thread uses them (the caller's contract). Each `at` is read at once, so even a
    // self-constraint (a = b) holds no two borrows.
    let (ma, mb, lambda) = unsafe { (*moved.at(a), *moved.at(b), lambda.at(k)) };
    let (wa, wb) = (ma.inv_mass, mb.inv_mass);
    if wa + wb == R::ZERO {
        return;
    }
    let (pa, pb, dxa, dxb) = (ma.predicted, mb.predicted, ma.displacement, mb.displacement);
    let d = pb - pa;
    let len = d.length();
    if len <= R::TINY_LENGTH {
        return;
    }
    let one = R::ONE;
    let n = d * (one / len);
    let (alpha, gamma) = (s.alpha[k], s.gamma[k]);
    // ∇C · (p − x): how fast the constraint is changing this step.
    let rate = n.dot(dxb - dxa);
    let constraint = len - R::of_f32(c.rest[k]);
    let dl = (-constraint - alpha * *lambda - gamma * rate) / ((one + gamma) * (wa + wb) + alpha);
    *lambda += dl;
    let (da, db) = (n * (wa * dl), n * (wb * dl));
    // SAFETY: as above.
    unsafe {
        *moved.at(a) = Moved {
            predicted: pa - da,
            displacement: dxa - da,
            ..ma
        };
        *moved.at(b) = Moved {
            predicted: pb + db,
            displacement: dxb + db,
            ..mb
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// 29 constraints on distinct particles (three groups of eight and five left over),
    /// among them the cases a projection leaves alone or passes through: a particle tied
    /// to itself, two fixed particles, one fixed particle, two particles at one point, and
    /// a non-finite position.
    fn one_colour() -> (DistanceConstraints, Vec<Moved>, Vec<f32>) {
        let mut seed = 0x2545_f491_u32;
        let mut random = move || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed as f32 / u32::MAX as f32
        };
        let count = 29;
        let mut c = DistanceConstraints::default();
        let mut moved = Vec::new();
        for k in 0..count {
            let (a, b) = (2 * k as u32, 2 * k as u32 + if k == 3 { 0 } else { 1 });
            c.a.push(a);
            c.b.push(b);
            c.rest.push(0.05 + 0.1 * random());
            c.compliance.push(1e-3 * (0.5 + random()));
            c.damping.push(0.02 * random());
            for _ in 0..2 {
                let [x, y, z, dx, dy, dz] = [(); 6].map(|_| random() - 0.5);
                let inv_mass = 0.5 + 2.0 * random();
                moved.push(Moved {
                    predicted: Vec3::new(x, y, z),
                    displacement: 0.01 * Vec3::new(dx, dy, dz),
                    inv_mass,
                    pad: 0.0,
                });
            }
        }
        moved[10].inv_mass = 0.0;
        moved[11].inv_mass = 0.0;
        moved[18].inv_mass = 0.0;
        moved[25].predicted = moved[24].predicted;
        moved[35].predicted.y = f32::NAN;
        let lambda = (0..count).map(|_| random() - 0.5).collect();
        (c, moved, lambda)
    }

    #[test]
    fn the_sweep_eight_at_a_time_gives_the_same_bits_as_one_at_a_time() {
        let (c, start, lambda_start) = one_colour();
        let mut s = Scaled::default();
        s.update(&c, 1.0 / 600.0);
        let run = |eights: bool| {
            let (mut moved, mut lambda) = (start.clone(), lambda_start.clone());
            let (m, l) = (Disjoint::new(&mut moved), Disjoint::new(&mut lambda));
            // SAFETY: one thread; the constraints share no particle; lengths match.
            unsafe { project_range(&c, &s, 0..c.len(), eights, &m, &l) };
            // IEEE leaves a NaN's sign and payload to the hardware's operand order: any NaN
            // counts as the same value here.
            let bits = |v: Vec3| {
                v.to_array()
                    .map(|x| if x.is_nan() { u32::MAX } else { x.to_bits() })
            };
            let moved: Vec<_> = (moved.iter())
                .map(|m| {
                    (
                        bits(m.predicted),
                        bits(m.displacement),
                        m.inv_mass.to_bits(),
                    )
                })
                .collect();
            let lambda: Vec<_> = lambda.iter().map(|&l| bits(Vec3::splat(l))[0]).collect();
            (moved, lambda)
        };
        let (one_by_one, eights) = (run(false), run(true));
        assert_eq!(one_by_one, eights);
        // The projection did move particles, and left alone those it should.
        let unchanged =
            |p: usize| one_by_one.0[p].0 == start[p].predicted.to_array().map(f32::to_bits);
        assert!(!unchanged(0) && !unchanged(1) && !unchanged(19));
        assert!([6, 10, 11, 18, 24, 25].into_iter().all(unchanged));
        assert_eq!(one_by_one.0[34].0, [u32::MAX; 3]);
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // The groups of eight went through the AVX2 kernel, the five left over not.
            let (mut moved, mut lambda) = (start.clone(), lambda_start.clone());
            let (m, l) = (Disjoint::new(&mut moved), Disjoint::new(&mut lambda));
            // SAFETY: as above, and the CPU has AVX2.
            let left = unsafe { project_eights_avx2(&c, &s, 0..c.len(), &m, &l) };
            assert_eq!(left, 24..29);
        }
    }
}
