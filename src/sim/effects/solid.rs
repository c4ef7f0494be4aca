//! What a solid the cloth cannot enter shares with every other: each substep every free
//! particle's path is caught where it comes within the collision thickness of the surface,
//! then an inelastic velocity response with Coulomb friction against the surface's own
//! velocity (a spinning sphere drags the cloth).

use glam::Vec3;

use super::effect_kind::ContactPass;

/// Coulomb friction of a solid when a scene file gives none (dimensionless).
pub(super) const DEFAULT_FRICTION: f32 = 0.5;

/// [`DEFAULT_FRICTION`], for serde's defaults.
pub(super) fn default_friction() -> f32 {
    DEFAULT_FRICTION
}

/// A solid's surface, for [`resolve`].
pub(super) trait Solid {
    /// Signed distance from `p` to the surface (metres, negative inside), the outward unit
    /// normal there, and the surface velocity there (m/s).
    fn surface_at(&self, p: Vec3) -> (f32, Vec3, Vec3);

    /// Where a particle moving from `from` to `to` ends up, if its path comes closer than
    /// `offset` to the surface; `None` if it stays clear.
    fn catch(&self, from: Vec3, to: Vec3, offset: f32) -> Option<Vec3>;

    /// Where a caught move ends, with the surface's normal and velocity there: by default
    /// [`Solid::catch`], then [`Solid::surface_at`] where it ends.
    fn contact(&self, from: Vec3, to: Vec3, offset: f32) -> Option<(Vec3, Vec3, Vec3)> {
        let caught = self.catch(from, to, offset)?;
        let (_, n, v_surface) = self.surface_at(caught);
        Some((caught, n, v_surface))
    }

    /// Coulomb friction coefficient (dimensionless, ≥ 0).
    fn friction(&self) -> f32;
}

/// Resolves every free particle's move in this substep, from `pass.start` to where the
/// integrator put it: a path entering the solid grown by the offset is caught
/// ([`Solid::catch`]), its approaching normal velocity removed (inelastic contact) and
/// Coulomb friction applied: the tangential velocity relative to the surface shrinks by at
/// most `friction` × the removed normal speed. Returns how many particles it moved.
pub(super) fn resolve(solid: &impl Solid, pass: &mut ContactPass<'_>) -> usize {
    let (mu, offset) = (solid.friction(), pass.offset);
    let (start, inv_mass) = (pass.start, &pass.model.inv_mass);
    let mut contacts = 0;
    let state = &mut *pass.state;
    let particles = state.pos.iter_mut().zip(state.vel.iter_mut());
    for (((x, v), &from), &w) in particles.zip(start).zip(inv_mass) {
        if w == 0.0 {
            continue;
        }
        let Some((caught, n, v_surface)) = solid.contact(from, *x, offset) else {
            continue;
        };
        contacts += 1;
        *x = caught;
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
