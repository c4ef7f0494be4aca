//! The precision a simulation computes in: `f32` (the default: fast, the SIMD lanes hold
//! eight) or `f64` (where rounding must stay out of a measurement). The state, the forces,
//! the integrators and the kernels are written once over [`Real`], with its 3-vector
//! ([`Vector`]) and 3×3 matrix ([`Matrix`]): glam's `Vec3`/`Mat3` for `f32`, `DVec3`/`DMat3`
//! for `f64`. Every method here is the type's own, inlined, so an `f32` path written over
//! `Real` is the same instructions, and the same bits, as one written over `f32`.

use std::fmt::Debug;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

use glam::{DMat3, DVec3, Mat3, Vec3, Vec3A};

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
    + MulAssign
    + std::iter::Sum
{
    /// A point, a velocity or a force in this precision.
    type V3: Vector<Self>;
    /// A 3×3 block (a force derivative) in this precision.
    type M3: Matrix<Self>;
    /// Whether the vectorised kernels (component arrays, SIMD lanes) compute in this
    /// precision: `f32` only; `f64` takes the plain paths.
    const VECTORISED: bool;
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
    /// The nearest value to `v`.
    fn of_f64(v: f64) -> Self;
    /// The nearest `f32`.
    fn to_f32(self) -> f32;
    fn max(self, other: Self) -> Self;
    fn min(self, other: Self) -> Self;
    fn sin(self) -> Self;
    fn sin_cos(self) -> (Self, Self);
    fn atan2(self, other: Self) -> Self;

    /// `v` in this precision (exact).
    fn v3(v: Vec3) -> Self::V3;
    /// The nearest vector to `v` in this precision.
    fn v3_of(v: DVec3) -> Self::V3;
    /// The nearest `f32` vector.
    fn v3_f32(v: Self::V3) -> Vec3;
    /// `v` in `f64` (exact).
    fn v3_f64(v: Self::V3) -> DVec3;
    /// The same vectors as `f32` ones, when this is `f32`: the way into the vectorised
    /// kernels, which have an `f32` path only.
    fn f32_slice(v: &[Self::V3]) -> Option<&[Vec3]>;
    /// As [`Real::f32_slice`], to write.
    fn f32_slice_mut(v: &mut [Self::V3]) -> Option<&mut [Vec3]>;
    /// As [`Real::f32_slice`], a growable vector.
    fn f32_vec_mut(v: &mut Vec<Self::V3>) -> Option<&mut Vec<Vec3>>;
}

/// A 3-vector in precision `R`: glam's operators and the methods the simulation uses.
pub trait Vector<R>:
    Copy
    + Default
    + Debug
    + PartialEq
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Neg<Output = Self>
    + Mul<Output = Self>
    + Mul<R, Output = Self>
    + Div<R, Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign<R>
{
    const ZERO: Self;
    fn new(x: R, y: R, z: R) -> Self;
    fn splat(v: R) -> Self;
    fn x(self) -> R;
    fn y(self) -> R;
    fn z(self) -> R;
    fn to_array(self) -> [R; 3];
    fn dot(self, other: Self) -> R;
    fn cross(self, other: Self) -> Self;
    fn length(self) -> R;
    fn length_squared(self) -> R;
    fn distance(self, other: Self) -> R;
    fn is_finite(self) -> bool;
}

/// A 3×3 matrix in precision `R`.
pub trait Matrix<R: Real>:
    Copy
    + Debug
    + PartialEq
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + AddAssign
    + SubAssign
    + Mul<R, Output = Self>
    + Mul<R::V3, Output = R::V3>
{
    const ZERO: Self;
    const IDENTITY: Self;
    fn from_cols(x: R::V3, y: R::V3, z: R::V3) -> Self;
    fn from_diagonal(d: R::V3) -> Self;
    fn col(&self, i: usize) -> R::V3;
    fn inverse(&self) -> Self;
}

macro_rules! vector {
    ($v:ty, $t:ty) => {
        impl Vector<$t> for $v {
            const ZERO: Self = <$v>::ZERO;
            #[inline(always)]
            fn new(x: $t, y: $t, z: $t) -> Self {
                <$v>::new(x, y, z)
            }
            #[inline(always)]
            fn splat(v: $t) -> Self {
                <$v>::splat(v)
            }
            #[inline(always)]
            fn x(self) -> $t {
                self.x
            }
            #[inline(always)]
            fn y(self) -> $t {
                self.y
            }
            #[inline(always)]
            fn z(self) -> $t {
                self.z
            }
            #[inline(always)]
            fn to_array(self) -> [$t; 3] {
                <$v>::to_array(&self)
            }
            #[inline(always)]
            fn dot(self, other: Self) -> $t {
                <$v>::dot(self, other)
            }
            #[inline(always)]
            fn cross(self, other: Self) -> Self {
                <$v>::cross(self, other)
            }
            #[inline(always)]
            fn length(self) -> $t {
                <$v>::length(self)
            }
            #[inline(always)]
            fn length_squared(self) -> $t {
                <$v>::length_squared(self)
            }
            #[inline(always)]
            fn distance(self, other: Self) -> $t {
                <$v>::distance(self, other)
            }
            #[inline(always)]
            fn is_finite(self) -> bool {
                <$v>::is_finite(self)
            }
        }
    };
}

macro_rules! matrix {
    ($m:ty, $v:ty, $t:ty) => {
        impl Matrix<$t> for $m {
            const ZERO: Self = <$m>::ZERO;
            const IDENTITY: Self = <$m>::IDENTITY;
            #[inline(always)]
            fn from_cols(x: $v, y: $v, z: $v) -> Self {
                <$m>::from_cols(x, y, z)
            }
            #[inline(always)]
            fn from_diagonal(d: $v) -> Self {
                <$m>::from_diagonal(d)
            }
            #[inline(always)]
            fn col(&self, i: usize) -> $v {
                <$m>::col(self, i)
            }
            #[inline(always)]
            fn inverse(&self) -> Self {
                <$m>::inverse(self)
            }
        }
    };
}

vector!(Vec3, f32);
vector!(DVec3, f64);
vector!(Vec3A, f32);
matrix!(Mat3, Vec3, f32);
matrix!(DMat3, DVec3, f64);

macro_rules! real {
    ($t:ident, $v:ty, $m:ty) => {
        impl Real for $t {
            type V3 = $v;
            type M3 = $m;
            const VECTORISED: bool = matches!(stringify!($t).as_bytes(), b"f32");
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

            #[inline(always)]
            fn of_f64(v: f64) -> Self {
                v as $t
            }

            #[inline(always)]
            fn to_f32(self) -> f32 {
                self as f32
            }

            #[inline(always)]
            fn max(self, other: Self) -> Self {
                <$t>::max(self, other)
            }

            #[inline(always)]
            fn min(self, other: Self) -> Self {
                <$t>::min(self, other)
            }

            #[inline(always)]
            fn sin(self) -> Self {
                <$t>::sin(self)
            }

            #[inline(always)]
            fn sin_cos(self) -> (Self, Self) {
                <$t>::sin_cos(self)
            }

            #[inline(always)]
            fn atan2(self, other: Self) -> Self {
                <$t>::atan2(self, other)
            }

            #[inline(always)]
            fn v3(v: Vec3) -> $v {
                <$v>::new(v.x as $t, v.y as $t, v.z as $t)
            }

            #[inline(always)]
            fn v3_of(v: DVec3) -> $v {
                <$v>::new(v.x as $t, v.y as $t, v.z as $t)
            }

            #[inline(always)]
            fn v3_f32(v: $v) -> Vec3 {
                Vec3::new(v.x as f32, v.y as f32, v.z as f32)
            }

            #[inline(always)]
            fn v3_f64(v: $v) -> DVec3 {
                DVec3::new(v.x as f64, v.y as f64, v.z as f64)
            }

            f32_views!($t);
        }
    };
}

macro_rules! f32_views {
    (f32) => {
        fn f32_slice(v: &[Vec3]) -> Option<&[Vec3]> {
            Some(v)
        }
        fn f32_slice_mut(v: &mut [Vec3]) -> Option<&mut [Vec3]> {
            Some(v)
        }
        fn f32_vec_mut(v: &mut Vec<Vec3>) -> Option<&mut Vec<Vec3>> {
            Some(v)
        }
    };
    (f64) => {
        fn f32_slice(_: &[DVec3]) -> Option<&[Vec3]> {
            None
        }
        fn f32_slice_mut(_: &mut [DVec3]) -> Option<&mut [Vec3]> {
            None
        }
        fn f32_vec_mut(_: &mut Vec<DVec3>) -> Option<&mut Vec<Vec3>> {
            None
        }
    };
}

real!(f32, Vec3, Mat3);
real!(f64, DVec3, DMat3);
