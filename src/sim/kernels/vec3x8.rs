//! Eight 3-vectors in `wide`'s `f32x8` lanes, one vector a lane, for the terms that go an
//! element at a time (the hinges, the wind's triangles): each operation is glam's `Vec3`
//! one's, lane by lane and in the same order, so a kernel written with it does the
//! one-at-a-time path's IEEE operations (tested where the terms are).

use std::ops::{Add, Div, Mul, Neg, Sub};

use glam::Vec3;
use wide::f32x8;

/// Vectors a [`Vec3x8`] holds: its lanes.
pub const LANES: usize = 8;

/// Up to eight numbers in lanes, the lanes past them zero.
pub fn padded(v: &[f32]) -> f32x8 {
    let mut lanes = [0.0f32; LANES];
    lanes[..v.len()].copy_from_slice(v);
    lanes.into()
}

/// Eight 3-vectors, one a lane.
#[derive(Clone, Copy, Debug)]
pub struct Vec3x8 {
    pub x: f32x8,
    pub y: f32x8,
    pub z: f32x8,
}

impl Vec3x8 {
    /// `v` in every lane.
    pub fn splat(v: Vec3) -> Self {
        Self {
            x: f32x8::splat(v.x),
            y: f32x8::splat(v.y),
            z: f32x8::splat(v.z),
        }
    }

    /// `of[elements[lane][corner]]` in each lane, for up to eight elements; the lanes past
    /// the last hold zeros.
    pub fn gather<const N: usize>(of: &[Vec3], elements: &[[u32; N]], corner: usize) -> Self {
        let [mut x, mut y, mut z] = [[0.0f32; LANES]; 3];
        for (lane, e) in elements.iter().enumerate().take(LANES) {
            let p = of[e[corner] as usize];
            (x[lane], y[lane], z[lane]) = (p.x, p.y, p.z);
        }
        Self {
            x: x.into(),
            y: y.into(),
            z: z.into(),
        }
    }

    /// Eight vectors, one a lane (what [`Vec3x8::unpack`] gives back).
    #[inline(always)]
    pub fn pack(v: [Vec3; LANES]) -> Self {
        let [x, y, z] = [0, 1, 2].map(|c| f32x8::from(v.map(|p| p[c])));
        Self { x, y, z }
    }

    /// The eight vectors, one a lane.
    pub fn unpack(self) -> [Vec3; LANES] {
        let (x, y, z) = (self.x.to_array(), self.y.to_array(), self.z.to_array());
        std::array::from_fn(|lane| Vec3::new(x[lane], y[lane], z[lane]))
    }

    /// As `Vec3::dot`.
    pub fn dot(self, o: Self) -> f32x8 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// As `Vec3::max` (for numbers).
    #[inline(always)]
    pub fn max(self, o: Self) -> Self {
        Self {
            x: self.x.max(o.x),
            y: self.y.max(o.y),
            z: self.z.max(o.z),
        }
    }

    /// As `Vec3::cross`.
    pub fn cross(self, o: Self) -> Self {
        Self {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }
}

impl Add for Vec3x8 {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for Vec3x8 {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl Neg for Vec3x8 {
    type Output = Self;
    fn neg(self) -> Self {
        Self {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

/// Each lane's vector times that lane's number.
impl Mul<f32x8> for Vec3x8 {
    type Output = Self;
    fn mul(self, s: f32x8) -> Self {
        Self {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

/// Each lane's vector over that lane's number.
impl Div<f32x8> for Vec3x8 {
    type Output = Self;
    fn div(self, s: f32x8) -> Self {
        Self {
            x: self.x / s,
            y: self.y / s,
            z: self.z / s,
        }
    }
}
