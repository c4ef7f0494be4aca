//! A still plane the cloth stays on one side of: a ground.

use glam::Vec3;

use super::effect_kind::{ClothBox, ContactPass, EffectKind, GuardShare};
use super::solid::{Solid, default_friction, resolve};
use crate::cloth::ClothState;
use crate::sim::param_error::ParamError;
use crate::sim::self_contacts::ContactError;

fn up() -> Vec3 {
    Vec3::Y
}

/// An infinite still plane through `point`; the cloth stays on the side `normal` points to.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plane {
    /// Metres (default the origin).
    #[serde(default)]
    pub point: Vec3,
    /// Towards the free side; need not be unit length, must not be zero (default up).
    #[serde(default = "up")]
    pub normal: Vec3,
    /// Coulomb friction coefficient (dimensionless, default 0.5).
    #[serde(default = "default_friction")]
    pub friction: f32,
}

impl Plane {
    /// The unit normal.
    pub fn unit_normal(&self) -> Vec3 {
        self.normal.normalize()
    }
}

/// A plane with its normal made unit once, for a substep's contacts.
struct UnitPlane {
    point: Vec3,
    normal: Vec3,
    friction: f32,
}

impl Solid for UnitPlane {
    #[inline]
    fn surface_at(&self, p: Vec3) -> (f32, Vec3, Vec3) {
        ((p - self.point).dot(self.normal), self.normal, Vec3::ZERO)
    }

    /// A half-space cannot be jumped over: pushing the end point out along the normal keeps
    /// the whole path outside.
    #[inline]
    fn catch(&self, _from: Vec3, to: Vec3, offset: f32) -> Option<Vec3> {
        let depth = offset - (to - self.point).dot(self.normal);
        (depth > 0.0).then(|| to + depth * self.normal)
    }

    #[inline]
    fn friction(&self) -> f32 {
        self.friction
    }
}

impl Plane {
    fn unit(&self) -> UnitPlane {
        UnitPlane {
            point: self.point,
            normal: self.unit_normal(),
            friction: self.friction,
        }
    }
}

impl EffectKind for Plane {
    const NAME: &'static str = "plane";
    const TITLE: &'static str = "Ground plane";
    const MANY: bool = false;
    const ADDABLE: bool = true;

    fn check(&self) -> Result<(), ParamError> {
        ParamError::require(
            self.normal.is_finite() && self.normal.length() >= 1e-6,
            "normal",
            self.normal,
            "must not be zero",
        )?;
        ParamError::require(
            self.point.is_finite(),
            "point",
            self.point,
            "must be finite metres",
        )
    }

    fn is_contact(&self) -> bool {
        true
    }

    fn resolve(&self, pass: &mut ContactPass<'_>) -> Result<usize, ContactError> {
        Ok(resolve(&self.unit(), pass))
    }

    fn is_solid(&self) -> bool {
        true
    }

    fn surface(&self, p: Vec3, _t: f64) -> Option<(f32, Vec3, Vec3)> {
        Some(self.unit().surface_at(p))
    }

    /// Unbounded but across a plane that faces along an axis: there, the points below
    /// `offset` above it.
    fn shell(&self, _t: f64, offset: f32) -> Option<(Vec3, Vec3)> {
        let n = self.unit_normal();
        let (mut lo, mut hi) = (Vec3::NEG_INFINITY, Vec3::INFINITY);
        // Exactly along an axis (its other components exactly zero), or bounded nowhere.
        if let Some(axis) = (0..3).find(|&k| n[k].abs() == 1.0 && n.length_squared() == 1.0) {
            if n[axis] > 0.0 {
                hi[axis] = self.point[axis] + offset;
            } else {
                lo[axis] = self.point[axis] - offset;
            }
        }
        Some((lo, hi))
    }

    fn guard(&self, up: Vec3, _cloth: &ClothState) -> GuardShare {
        GuardShare {
            floor: Some(up.dot(self.point)),
            ..GuardShare::default()
        }
    }

    fn on_gpu(&self) -> Result<(), &'static str> {
        Ok(())
    }

    /// Level, half the cloth's size below it.
    fn suggested(cloth: &ClothBox) -> Self {
        let size = (cloth.hi - cloth.lo).max_element().max(0.1);
        Plane {
            point: Vec3::new(0.0, cloth.lo.y - 0.5 * size, 0.0),
            normal: Vec3::Y,
            friction: default_friction(),
        }
    }
}
