//! The scalar type the kernels compute in: `f32` for stepping (the SIMD lanes hold eight),
//! `f64` where rounding must stay out of a measurement. The kernels are written once over
//! [`Real`]; each use picks its type, and `f32` is the default everywhere.

use std::fmt::Debug;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

/// A floating-point type a kernel can be compiled for. The methods are the ones the kernels
/// use, each inlined to the type's own (`f32::mul_add` is one fused instruction where the
/// CPU has FMA, a correctly rounded call where not), so an `f32` kernel is the same
/// instructions whether written over `Real` or over `f32`.
pub trait Real:
    Copy
    + Default
    + Debug
    + PartialOrd
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
{
    const ZERO: Self;
    const ONE: Self;
    /// Below this a spring's length counts as zero (its direction is undefined), metres.
    const TINY_LENGTH: Self;

    /// `self · a + b`, rounded once.
    fn mul_add(self, a: Self, b: Self) -> Self;
    fn sqrt(self) -> Self;
    /// The nearest value to `v`.
    fn of_f32(v: f32) -> Self;
    /// The nearest `f64` (exact from either type).
    fn to_f64(self) -> f64;
}

macro_rules! real {
    ($t:ty) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const TINY_LENGTH: Self = 1e-9;

            #[inline(always)]
            fn mul_add(self, a: Self, b: Self) -> Self {
                <$t>::mul_add(self, a, b)
            }

            #[inline(always)]
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }

            #[inline(always)]
            fn of_f32(v: f32) -> Self {
                v as $t
            }

            #[inline(always)]
            fn to_f64(self) -> f64 {
                self as f64
            }
        }
    };
}

real!(f32);
real!(f64);
