//! Running a loop compiled for AVX2 where the CPU has it.
//!
//! The crate is built for the baseline x86-64 (SSE2), so its loops over component arrays
//! go four floats at a time. [`wide()`] runs a piece of work through a function compiled
//! for AVX2, picked at run time, where the compiler can go eight at a time. A loop that
//! should benefit must be inlined all the way into the closure: write it in an
//! `#[inline(always)]` function and pass an `#[inline(always)]` closure. Without FMA the
//! compiler does the same IEEE operations in the same order either way, so the results
//! are the same bits on every CPU. [`wide_fma`] also enables FMA, for loops that write
//! their fused multiply-adds out (`mul_add`): one instruction with FMA, a correctly
//! rounded library call (the same result, more slowly) without, so the same bits too.

/// Runs `work`, compiled for AVX2 when the CPU has it (see the notes at the top of `parallel/wide.rs`).
#[inline(always)]
pub fn wide<R>(work: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        return unsafe { wide_avx2(work) };
    }
    work()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn wide_avx2<R>(work: impl FnOnce() -> R) -> R {
    work()
}

/// Runs `work`, compiled for AVX2 and FMA when the CPU has both (see the notes at the top of `parallel/wide.rs`).
#[inline(always)]
pub fn wide_fma<R>(work: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU supports AVX2 and FMA (checked just above).
        return unsafe { wide_fma_avx2(work) };
    }
    work()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn wide_fma_avx2<R>(work: impl FnOnce() -> R) -> R {
    work()
}
