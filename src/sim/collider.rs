//! Colliders: resolved after every substep by projection plus a velocity response with
//! Coulomb friction measured against the collider's surface velocity.

use glam::Vec3;

use crate::cloth::{ClothModel, ClothState};

/// A solid the cloth cannot enter.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Collider {
    /// A sphere spinning with angular velocity `spin` (rad/s, axis × rate; zero for static).
    Sphere {
        center: Vec3,
        /// Metres.
        radius: f32,
        spin: Vec3,
        /// Coulomb friction coefficient (dimensionless, ≥ 0).
        friction: f32,
    },
    /// An infinite static plane through `point` with unit `normal` pointing to the free side.
    Plane {
        point: Vec3,
        normal: Vec3,
        friction: f32,
    },
}

impl Collider {
    /// The name of its phase in timings.
    pub fn phase(&self) -> &'static str {
        match self {
            Collider::Sphere { .. } => "sphere",
            Collider::Plane { .. } => "plane",
        }
    }

    /// Signed distance from `p` to the surface (metres, negative inside), the outward unit
    /// normal there, and the surface velocity there (m/s).
    pub fn surface(&self, p: Vec3) -> (f32, Vec3, Vec3) {
        match *self {
            Collider::Sphere {
                center,
                radius,
                spin,
                ..
            } => {
                let r = p - center;
                let len = r.length();
                let n = if len > 1e-9 { r / len } else { Vec3::Y };
                (len - radius, n, spin.cross(n * radius))
            }
            Collider::Plane { point, normal, .. } => ((p - point).dot(normal), normal, Vec3::ZERO),
        }
    }

    fn friction(&self) -> f32 {
        match *self {
            Collider::Sphere { friction, .. } | Collider::Plane { friction, .. } => friction,
        }
    }

    /// Resolves every free particle's move in this substep, from `start` to where the
    /// integrator put it (`state.pos`). A particle whose path enters the collider grown by
    /// `offset` is caught on its way in: for a sphere, the part of its move that points
    /// into the surface after the first contact is removed (the part along it is kept, so
    /// cloth still slides) before it is pushed out to `offset`; so a fast particle cannot
    /// pass through, however thin the sphere. Then its approaching normal velocity is
    /// removed (inelastic contact) and Coulomb friction applied: the tangential velocity
    /// relative to the surface shrinks by at most `friction` × the removed normal speed.
    /// Returns how many particles it moved.
    pub fn resolve(
        &self,
        model: &ClothModel,
        start: &[Vec3],
        state: &mut ClothState,
        offset: f32,
    ) -> usize {
        let mu = self.friction();
        let mut contacts = 0;
        let particles = state.pos.iter_mut().zip(state.vel.iter_mut());
        for (((x, v), &from), &w) in particles.zip(start).zip(&model.inv_mass) {
            if w == 0.0 {
                continue;
            }
            let Some(caught) = self.catch(from, *x, offset) else {
                continue;
            };
            contacts += 1;
            *x = caught;
            let (_, n, v_surface) = self.surface(caught);
            let v_rel = *v - v_surface;
            let vn = v_rel.dot(n);
            if vn < 0.0 {
                let v_t = v_rel - vn * n;
                let t_speed = v_t.length();
                let keep = if t_speed > 0.0 {
                    (1.0 - mu * (-vn) / t_speed).max(0.0)
                } else {
                    0.0
                };
                *v = v_surface + keep * v_t;
            }
        }
        contacts
    }

    /// Where a particle moving from `from` to `to` ends up, if its path comes closer than
    /// `offset` to the surface; `None` if it stays clear.
    fn catch(&self, from: Vec3, to: Vec3, offset: f32) -> Option<Vec3> {
        match *self {
            Collider::Sphere { center, radius, .. } => {
                let reach = radius + offset;
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
            Collider::Plane { point, normal, .. } => {
                // A half-space cannot be jumped over: pushing the end point out along the
                // normal keeps the whole path outside.
                let depth = offset - (to - point).dot(normal);
                (depth > 0.0).then(|| to + depth * normal)
            }
        }
    }
}

/// The first point (relative to the sphere's centre) where the segment `a → b` enters the
/// sphere of radius `r`, if `a` is outside it and the segment reaches it.
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

/// Smallest signed distance from any particle to any collider surface, metres; `None`
/// without colliders.
pub fn min_collider_distance(colliders: &[Collider], pos: &[Vec3]) -> Option<f32> {
    colliders
        .iter()
        .flat_map(|c| pos.iter().map(move |&p| c.surface(p).0))
        .reduce(f32::min)
}

/// A warning for each sphere smaller than the cloth's particle spacing (its median spring
/// rest length): collisions are per particle, so such a sphere can pass between particles
/// and the cloth's triangles over it.
pub fn small_sphere_warnings(colliders: &[Collider], model: &ClothModel) -> Vec<String> {
    let mut rest = model.springs.rest.clone();
    if rest.is_empty() {
        return Vec::new();
    }
    rest.sort_by(f32::total_cmp);
    let spacing = rest[rest.len() / 2];
    colliders
        .iter()
        .filter_map(|c| match *c {
            Collider::Sphere { radius, .. } if radius < spacing => Some(format!(
                "a sphere of radius {radius:.3} m is smaller than the cloth's particle spacing \
                 ({spacing:.3} m): collisions are per particle, so the cloth's triangles can pass \
                 over it; use a finer cloth or a larger sphere"
            )),
            _ => None,
        })
        .collect()
}
