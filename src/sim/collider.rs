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

    /// Pushes every free particle closer than `offset` to the surface out to `offset`, removes
    /// its approaching normal velocity (inelastic contact) and applies Coulomb friction: the
    /// tangential velocity relative to the surface shrinks by at most `friction` × the removed
    /// normal speed. Returns how many particles it moved.
    pub fn resolve(&self, model: &ClothModel, state: &mut ClothState, offset: f32) -> usize {
        let mu = self.friction();
        let mut contacts = 0;
        for i in 0..state.pos.len() {
            if model.inv_mass[i] == 0.0 {
                continue;
            }
            let (dist, n, v_surface) = self.surface(state.pos[i]);
            let depth = offset - dist;
            if depth <= 0.0 {
                continue;
            }
            contacts += 1;
            state.pos[i] += depth * n;
            let v_rel = state.vel[i] - v_surface;
            let vn = v_rel.dot(n);
            if vn < 0.0 {
                let v_t = v_rel - vn * n;
                let t_speed = v_t.length();
                let keep = if t_speed > 0.0 {
                    (1.0 - mu * (-vn) / t_speed).max(0.0)
                } else {
                    0.0
                };
                state.vel[i] = v_surface + keep * v_t;
            }
        }
        contacts
    }
}

/// Smallest signed distance from any particle to any collider surface, metres; `None`
/// without colliders.
pub fn min_collider_distance(colliders: &[Collider], pos: &[Vec3]) -> Option<f32> {
    colliders
        .iter()
        .flat_map(|c| pos.iter().map(move |&p| c.surface(p).0))
        .reduce(f32::min)
}

/// The colliders among `effects`, in order.
pub fn colliders_of(effects: &[super::Effect]) -> Vec<Collider> {
    effects
        .iter()
        .filter_map(|e| match e {
            super::Effect::Collider(c) => Some(*c),
            _ => None,
        })
        .collect()
}
