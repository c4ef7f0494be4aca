//! A sphere the cloth cannot enter, still or spinning about its centre.

use glam::Vec3;

use super::effect_kind::{ClothBox, ContactPass, EffectKind, GuardShare};
#[cfg(doc)]
use super::faces::FacePatches;
use super::solid::{Solid, default_friction, resolve};
use crate::sim::obstacle::closest_weights;
use crate::sim::param_error::ParamError;
use crate::sim::self_contacts::ContactError;

/// A sphere spinning with angular velocity `spin` (zero for a still one).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sphere {
    /// Metres.
    pub center: Vec3,
    /// Metres.
    pub radius: f32,
    /// rad/s about each axis (axis × rate; default still).
    #[serde(default)]
    pub spin: Vec3,
    /// Coulomb friction coefficient (dimensionless, default 0.5).
    #[serde(default = "default_friction")]
    pub friction: f32,
}

impl Solid for Sphere {
    #[inline]
    fn surface_at(&self, p: Vec3) -> (f32, Vec3, Vec3) {
        let r = p - self.center;
        let len = r.length();
        let n = if len > 1e-9 { r / len } else { Vec3::Y };
        (len - self.radius, n, self.spin.cross(n * self.radius))
    }

    /// A path entering the sphere is caught at its first contact: the part of the move
    /// that points into the surface after it is removed (the part along it is kept, so
    /// cloth still slides) before the particle is pushed out to `offset`; so a fast
    /// particle cannot pass through, however small the sphere.
    #[inline]
    fn catch(&self, from: Vec3, to: Vec3, offset: f32) -> Option<Vec3> {
        let center = self.center;
        let reach = self.radius + offset;
        let entry = first_entry(from - center, to - center, reach);
        if entry.is_none() && (to - center).length_squared() >= reach * reach {
            return None;
        }
        // Keep the move's tangential part at the first contact, drop what points in.
        let moved = match entry {
            Some(hit) => {
                let n = hit.normalize_or(Vec3::Y);
                let rest = (to - center) - hit;
                hit + rest - rest.dot(n).min(0.0) * n
            }
            None => to - center,
        };
        let len = moved.length();
        let n = if len > 1e-9 { moved / len } else { Vec3::Y };
        Some(center + n * reach.max(len))
    }

    #[inline]
    fn friction(&self) -> f32 {
        self.friction
    }
}

impl Sphere {
    /// Keeps each triangle's interior out of the sphere too (with self-contact, whose
    /// guarantee covers the surface): a flat triangle over a small sphere dips in between
    /// its corners however far out they are. A triangle whose point nearest the centre is
    /// within the radius and the offset is pushed out along the line from the centre, its
    /// corners by their weights and inverse masses, and their velocities lose what points
    /// in; only the triangles of the patches whose box comes that near are tested
    /// ([`FacePatches`]). Returns the triangles pushed.
    fn keep_faces_out(&self, pass: &mut ContactPass<'_>) -> usize {
        let reach = self.radius + pass.offset;
        let (model, state) = (pass.model, &mut *pass.state);
        let Some(patches) = pass.faces.as_deref_mut() else {
            return 0;
        };
        // Only the triangles of the patches whose box comes within the reach.
        let center = self.center;
        let near =
            |lo: Vec3, hi: Vec3| center.clamp(lo, hi).distance_squared(center) < reach * reach;
        let inv = &model.inv_mass;
        let mut pushed = 0;
        for &t in patches.near(model, &state.pos, near) {
            let ids = model.triangles[t as usize].map(|i| i as usize);
            let x = ids.map(|i| state.pos[i]);
            let w = closest_weights(self.center, x);
            let q = w[0] * x[0] + w[1] * x[1] + w[2] * x[2];
            let gap = q - self.center;
            let d = gap.length();
            let weight: f32 = (0..3).map(|k| w[k] * w[k] * inv[ids[k]]).sum();
            if d >= reach || d < 1e-9 || weight <= 0.0 {
                continue;
            }
            let n = gap / d;
            let lambda = (reach - d) / weight;
            for k in 0..3 {
                let i = ids[k];
                state.pos[i] += (w[k] * inv[i] * lambda) * n;
                let inward = state.vel[i].dot(n);
                if w[k] > 0.0 && inward < 0.0 {
                    state.vel[i] -= inward * n;
                }
            }
            pushed += 1;
        }
        pushed
    }
}

/// The first point (relative to the sphere's centre) where the segment `a → b` enters the
/// sphere of radius `r`, if `a` is outside it and the segment reaches it.
#[inline]
fn first_entry(a: Vec3, b: Vec3, r: f32) -> Option<Vec3> {
    let d = b - a;
    let (aa, dd) = (a.length_squared(), d.length_squared());
    if aa < r * r || dd == 0.0 {
        return None;
    }
    // |a + t·d|² = r²  ⇔  dd·t² + 2(a·d)·t + (aa − r²) = 0; the smaller root enters.
    let half_b = a.dot(d);
    let disc = half_b * half_b - dd * (aa - r * r);
    if half_b >= 0.0 || disc < 0.0 {
        return None;
    }
    let t = (-half_b - disc.sqrt()) / dd;
    (0.0..=1.0).contains(&t).then(|| a + t * d)
}

impl EffectKind for Sphere {
    const NAME: &'static str = "sphere";
    const TITLE: &'static str = "Sphere";
    const MANY: bool = true;
    const ADDABLE: bool = true;

    fn check(&self) -> Result<(), ParamError> {
        ParamError::require(
            self.radius.is_finite() && self.radius > 0.0,
            "radius",
            self.radius,
            "must be positive metres",
        )?;
        ParamError::require(
            self.center.is_finite() && self.spin.is_finite(),
            "center",
            self.center,
            "must be finite metres",
        )
    }

    fn is_contact(&self) -> bool {
        true
    }

    fn resolve(&self, pass: &mut ContactPass<'_>) -> Result<usize, ContactError> {
        let particles = resolve(self, pass);
        Ok(particles + self.keep_faces_out(pass))
    }

    fn surface(&self, p: Vec3) -> Option<(f32, Vec3, Vec3)> {
        Some(self.surface_at(p))
    }

    fn guard(&self, up: Vec3) -> GuardShare {
        GuardShare {
            floor: Some(up.dot(self.center) - self.radius),
            surface_speed: self.spin.length() * self.radius,
            flow_speed: 0.0,
        }
    }

    fn on_gpu(&self) -> Result<(), &'static str> {
        Ok(())
    }

    /// Just under the cloth's middle, a quarter of its size across, so it falls onto it.
    fn suggested(cloth: &ClothBox) -> Self {
        let size = (cloth.hi - cloth.lo).max_element().max(0.1);
        let radius = 0.25 * size;
        let mid = 0.5 * (cloth.lo + cloth.hi);
        Sphere {
            center: Vec3::new(mid.x, cloth.lo.y - 0.05 * size - radius, mid.z),
            radius,
            spin: Vec3::ZERO,
            friction: default_friction(),
        }
    }
}
