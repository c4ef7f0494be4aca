//! Eight 3-vectors in AVX2 registers, one per lane (`[x, y, z]`), the few operations the
//! XPBD and VBD sweeps do on them (each the same IEEE operations as glam's `Vec3`), and
//! eight particles' rows loaded as columns.

use std::arch::x86_64::*;

use crate::parallel::Disjoint;

pub const LANES: usize = 8;

pub type V3 = [__m256; 3];

#[target_feature(enable = "avx2")]
#[inline]
pub fn sub(x: V3, y: V3) -> V3 {
    [
        _mm256_sub_ps(x[0], y[0]),
        _mm256_sub_ps(x[1], y[1]),
        _mm256_sub_ps(x[2], y[2]),
    ]
}

#[target_feature(enable = "avx2")]
#[inline]
pub fn add(x: V3, y: V3) -> V3 {
    [
        _mm256_add_ps(x[0], y[0]),
        _mm256_add_ps(x[1], y[1]),
        _mm256_add_ps(x[2], y[2]),
    ]
}

/// `s · x`, lane by lane.
#[target_feature(enable = "avx2")]
#[inline]
pub fn scale(s: __m256, x: V3) -> V3 {
    [
        _mm256_mul_ps(s, x[0]),
        _mm256_mul_ps(s, x[1]),
        _mm256_mul_ps(s, x[2]),
    ]
}

/// `(x₀y₀ + x₁y₁) + x₂y₂`, glam's order.
#[target_feature(enable = "avx2")]
#[inline]
pub fn dot(x: V3, y: V3) -> __m256 {
    let xy = _mm256_add_ps(_mm256_mul_ps(x[0], y[0]), _mm256_mul_ps(x[1], y[1]));
    _mm256_add_ps(xy, _mm256_mul_ps(x[2], y[2]))
}

/// A particle's row: eight `f32`, 32-byte aligned.
///
/// # Safety
/// The type is `repr(C, align(32))` and holds exactly eight `f32`.
pub unsafe trait Row: Copy {}

/// The rows at `ends` as eight columns, one register per field, one lane per row. Each half
/// row is loaded whole, row `i` beside row `i + 4`, then transposed four by four within the
/// halves of the registers.
///
/// # Safety
/// `ends` holds at least eight indices, every one in bounds, and no other thread writes
/// those rows meanwhile.
#[target_feature(enable = "avx2")]
#[inline]
pub unsafe fn load_rows<T: Row>(rows: &Disjoint<'_, T>, ends: &[u32]) -> [__m256; 8] {
    let base = rows.as_ptr() as *const f32;
    let mut halves = [[_mm256_setzero_ps(); 4]; 2];
    for (i, &end) in ends[..4].iter().enumerate() {
        let (row, other) = (8 * end as usize, 8 * ends[i + 4] as usize);
        for (h, half) in halves.iter_mut().enumerate() {
            // SAFETY: a row is eight f32, 32-byte aligned (`Row`); the rest is the caller's
            // contract.
            half[i] = unsafe {
                let low = _mm256_castps128_ps256(_mm_load_ps(base.add(row + 4 * h)));
                _mm256_insertf128_ps::<1>(low, _mm_load_ps(base.add(other + 4 * h)))
            };
        }
    }
    let ([a, b, c, d], [e, f, g, h]) = (transpose4(halves[0]), transpose4(halves[1]));
    [a, b, c, d, e, f, g, h]
}

/// Stores columns as [`load_rows`] makes them back into the rows at `ends`, row by row in
/// order.
///
/// # Safety
/// As [`load_rows`], and no other thread reads those rows meanwhile.
#[target_feature(enable = "avx2")]
#[inline]
pub unsafe fn store_rows<T: Row>(rows: &Disjoint<'_, T>, ends: &[u32], columns: [__m256; 8]) {
    let base = rows.as_ptr() as *mut f32;
    let [a, b, c, d, e, f, g, h] = columns;
    let low = transpose4([a, b, c, d]);
    let high = transpose4([e, f, g, h]);
    for (i, &end) in ends[..LANES].iter().enumerate() {
        let (half, row) = (i % 4, 8 * end as usize);
        // SAFETY: as `load_rows`.
        unsafe {
            let (l, h) = if i < 4 {
                (
                    _mm256_castps256_ps128(low[half]),
                    _mm256_castps256_ps128(high[half]),
                )
            } else {
                (
                    _mm256_extractf128_ps::<1>(low[half]),
                    _mm256_extractf128_ps::<1>(high[half]),
                )
            };
            _mm_store_ps(base.add(row), l);
            _mm_store_ps(base.add(row + 4), h);
        }
    }
}

/// The 4 × 4 transpose within each 128-bit half: element `j` of register `i` becomes
/// element `i` of register `j`, for the low halves and for the high halves.
#[target_feature(enable = "avx2")]
#[inline]
fn transpose4(r: [__m256; 4]) -> [__m256; 4] {
    let t = [
        _mm256_unpacklo_ps(r[0], r[1]),
        _mm256_unpackhi_ps(r[0], r[1]),
        _mm256_unpacklo_ps(r[2], r[3]),
        _mm256_unpackhi_ps(r[2], r[3]),
    ];
    [
        _mm256_shuffle_ps::<0x44>(t[0], t[2]),
        _mm256_shuffle_ps::<0xEE>(t[0], t[2]),
        _mm256_shuffle_ps::<0x44>(t[1], t[3]),
        _mm256_shuffle_ps::<0xEE>(t[1], t[3]),
    ]
}
