//! What a solid the cloth cannot enter shares with every other: each substep every free
//! particle's path is caught where it comes within the collision thickness of the surface,
//! then an inelastic velocity response with Coulomb friction against the surface's own
//! velocity (a spinning sphere drags the cloth).

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::Vec3;

use super::effect_kind::ContactPass;
use crate::mesh::bounds;
use crate::parallel::{Disjoint, PARALLEL_ELEMENTS, each_part_from, within};
use crate::sim::obstacle::Gathered;

/// Coulomb friction of a solid when a scene file gives none (dimensionless).
pub(super) const DEFAULT_FRICTION: f32 = 0.5;

/// [`DEFAULT_FRICTION`], for serde's defaults.
pub(super) fn default_friction() -> f32 {
    DEFAULT_FRICTION
}

/// A solid's surface, for [`resolve`].
pub(super) trait Solid {
    /// Particles from which [`resolve`] shares them out between the team's members: a
    /// solid whose [`Solid::contact`] walks a tree costs enough a particle to share from
    /// fewer than [`PARALLEL_ELEMENTS`].
    const SHARED_FROM: usize = PARALLEL_ELEMENTS;

    /// Signed distance from `p` to the surface (metres, negative inside), the outward unit
    /// normal there, and the surface velocity there (m/s).
    fn surface_at(&self, p: Vec3) -> (f32, Vec3, Vec3);

    /// Where a particle moving from `from` to `to` ends up, if its path comes closer than
    /// `offset` to the surface; `None` if it stays clear.
    fn catch(&self, from: Vec3, to: Vec3, offset: f32) -> Option<Vec3>;

    /// Whether a particle moving from `from` to `to` is told clear of the surface at a
    /// glance, far enough that [`Solid::catch`] could not catch it (by default none is:
    /// every move is caught or not by the catch itself).
    #[inline]
    fn clear(&self, _from: Vec3, _to: Vec3, _offset: f32) -> bool {
        false
    }

    /// Whether a particle moving from `from` to `to` is told clear of the surface by what
    /// its last contact left in `memory` (by default none is): then [`Solid::contact`]
    /// would find nothing either.
    #[inline]
    fn clear_remembered(&self, _from: Vec3, _to: Vec3, _offset: f32, _memory: &Gathered) -> bool {
        false
    }

    /// Where a caught move ends, with the surface's normal and velocity there: by default
    /// [`Solid::catch`], then [`Solid::surface_at`] where it ends. `memory`: what the
    /// particle's last contact left (what a mesh gathered near it; other solids need none).
    fn contact(
        &self,
        from: Vec3,
        to: Vec3,
        offset: f32,
        _memory: Option<&mut Gathered>,
    ) -> Option<(Vec3, Vec3, Vec3)> {
        let caught = self.catch(from, to, offset)?;
        let (_, n, v_surface) = self.surface_at(caught);
        Some((caught, n, v_surface))
    }

    /// Coulomb friction coefficient (dimensionless, ≥ 0).
    fn friction(&self) -> f32;

    /// Whether every move within the box `lo..hi` keeps farther than `offset` from the
    /// surface, with a margin no rounding of [`Solid::catch`] bridges (by default no box
    /// is: every move is tested on its own). See [`resolve_in_boxes`].
    #[inline]
    fn box_clear(&self, _lo: Vec3, _hi: Vec3, _offset: f32) -> bool {
        false
    }
}

/// Resolves every free particle's move in this substep, from `pass.start` to where the
/// integrator put it: a path entering the solid grown by the offset is caught
/// ([`Solid::catch`]), its approaching normal velocity removed (inelastic contact) and
/// Coulomb friction applied: the tangential velocity relative to the surface shrinks by at
/// most `friction` × the removed normal speed. Returns how many particles it moved.
///
/// Each particle's contact is its own, so a large cloth's particles are shared out between
/// the team's members ([`each_part`](crate::parallel::each_part)); the result is the same however they are cut.
pub(super) fn resolve(solid: &(impl Solid + Sync), pass: &mut ContactPass<'_>) -> usize {
    resolve_remembering(solid, pass, None)
}

/// [`resolve`] with each particle's memory of its last contact (`memory[i]` particle i's,
/// as long as the cloth has particles).
pub(super) fn resolve_remembering(
    solid: &(impl Solid + Sync),
    pass: &mut ContactPass<'_>,
    memory: Option<&mut [Gathered]>,
) -> usize {
    resolve_parts(solid, pass, memory, false).0
}

/// [`resolve`] for a solid that tells boxes of moves clear ([`Solid::box_clear`]): each
/// member takes the box of its particles' moves first and tests none of them where that box
/// is clear (a cloth falling onto a sphere, still above it, moves none). Returns how many
/// particles it moved and the box of every particle's move as the integrator left it
/// (`(0, 0)` for no particle). The result is the same however the particles are cut: a
/// move in a clear box is not caught either way.
pub(super) fn resolve_in_boxes(
    solid: &(impl Solid + Sync),
    pass: &mut ContactPass<'_>,
) -> (usize, (Vec3, Vec3)) {
    let (contacts, joined) = resolve_parts(solid, pass, None, true);
    (contacts, joined.unwrap_or((Vec3::ZERO, Vec3::ZERO)))
}

/// The one loop of [`resolve_remembering`] and [`resolve_in_boxes`]: each member resolves
/// its part of the particles (with its part of `memory`); where `boxed`, it first takes
/// its part's box of moves, joins it to the others' (returned: `None` for no particle),
/// and passes the part by where that box is clear.
fn resolve_parts<S: Solid + Sync>(
    solid: &S,
    pass: &mut ContactPass<'_>,
    memory: Option<&mut [Gathered]>,
    boxed: bool,
) -> (usize, Option<(Vec3, Vec3)>) {
    let (start, inv_mass) = (pass.start, &pass.model.inv_mass[..]);
    let contacts = AtomicUsize::new(0);
    let state = &mut *pass.state;
    let offset = pass.offset;
    let memory = memory.map(Disjoint::new);
    // The parts' boxes, joined as they come: a least and a greatest, in any order.
    let joined: Mutex<Option<(Vec3, Vec3)>> = Mutex::new(None);
    let arrays = [&mut state.pos[..], &mut state.vel[..]];
    each_part_from(S::SHARED_FROM, arrays, |range, [pos, vel]| {
        // SAFETY: `each_part`'s ranges are disjoint, so are these parts of the memory.
        let memory = memory.as_ref().map(|m| unsafe { m.part(range.clone()) });
        let (start, inv_mass) = (within(start, range.clone()), within(inv_mass, range));
        if boxed && !start.is_empty() {
            let part = join(bounds(start), bounds(pos));
            {
                let mut joined = joined.lock().unwrap_or_else(|e| e.into_inner());
                *joined = Some(joined.map_or(part, |all| join(all, part)));
            }
            if solid.box_clear(part.0, part.1, offset) {
                return;
            }
        }
        let found = resolve_part(solid, offset, pos, vel, start, inv_mass, memory);
        contacts.fetch_add(found, Ordering::Relaxed);
    });
    let joined = joined.into_inner().unwrap_or_else(|e| e.into_inner());
    (contacts.into_inner(), joined)
}

/// The box of two boxes.
fn join(a: (Vec3, Vec3), b: (Vec3, Vec3)) -> (Vec3, Vec3) {
    (a.0.min(b.0), a.1.max(b.1))
}

/// [`resolve`] over one run of particles.
fn resolve_part(
    solid: &impl Solid,
    offset: f32,
    pos: &mut [Vec3],
    vel: &mut [Vec3],
    start: &[Vec3],
    inv_mass: &[f32],
    mut memory: Option<&mut [Gathered]>,
) -> usize {
    let mu = solid.friction();
    let mut contacts = 0;
    let particles = pos.iter_mut().zip(vel.iter_mut());
    for (i, (((x, v), &from), &w)) in particles.zip(start).zip(inv_mass).enumerate() {
        if w == 0.0 || solid.clear(from, *x, offset) {
            continue;
        }
        let memory = memory.as_deref_mut().and_then(|m| m.get_mut(i));
        if (memory.as_deref()).is_some_and(|m| solid.clear_remembered(from, *x, offset, m)) {
            continue;
        }
        let Some((caught, n, v_surface)) = solid.contact(from, *x, offset, memory) else {
            continue;
        };
        contacts += 1;
        *x = caught;
        *v = touching(*v, v_surface, n, mu, 1.0);
    }
    contacts
}

/// The velocity `v` of a particle that touches a surface moving at `v_surface` (unit
/// normal `n`), where `part` of it (1: all) bears on the contact: that part of its
/// approach along `n` is removed, and its sliding slowed by Coulomb friction `mu` in
/// proportion. Unchanged where it moves away.
pub(super) fn touching(v: Vec3, v_surface: Vec3, n: Vec3, mu: f32, part: f32) -> Vec3 {
    let v_rel = v - v_surface;
    let vn = v_rel.dot(n);
    if vn >= 0.0 {
        return v;
    }
    let v_t = v_rel - vn * n;
    let speed = v_t.length();
    let keep = if speed > 0.0 {
        (1.0 - mu * part * (-vn) / speed).max(0.0)
    } else {
        0.0
    };
    v_surface + (1.0 - part) * vn * n + keep * v_t
}
