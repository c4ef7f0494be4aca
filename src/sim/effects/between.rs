//! Particles between two solids. Where two solids' collision offsets overlap (a sphere
//! resting on the ground, near where it touches it), no place keeps a particle the offset
//! clear of both, and each solid acting in turn leaves a particle where the last put it:
//! the ground lifted a particle squeezed under the sphere back into the sphere. After the
//! solids have acted, each free particle that touches one solid while within the offset of
//! another is moved by the least that keeps it the offset clear of both, each surface taken
//! as its tangent plane where the particle is, a few rounds over (the sphere's curve is
//! taken up in two or three); in a wedge that is along it, out to where the two offsets
//! leave room. Between two solids that face each other closer than twice the offset, no
//! place keeps both: the particle is left halfway, as far from each. Each solid's offset is
//! the distance it keeps ([`Effect::clearance`]: a mesh obstacle may have its own).

use glam::Vec3;

use super::effect_kind::ContactPass;
use super::registry::Effect;

/// Rounds of the least move at most: each takes the surfaces' tangent planes where the
/// particle is.
const ROUNDS: usize = 6;

/// The longest a round's move may be, as a multiple of the depth it makes up: near where
/// a sphere touches the ground their tangent planes meet at a few degrees, and the move
/// that clears both planes would throw a particle past where the curved surfaces leave
/// room (from 2 cm off the axis under a 0.3 m sphere, to 0.3 m for the 0.11 m needed); at
/// three times, it lands within 0.3 mm of that place in one to three rounds, at twice in
/// ten.
const LONGEST: f32 = 3.0;

/// How near the offset (as a share of it) a solid keeps a particle it touches: the solids'
/// own passes leave it there, rounded.
const TOUCHING: f32 = 1e-3;

/// How far past the offset (as a share of it) the rounds may leave a particle whose
/// approach is still taken out: their last move may overshoot where the curved surfaces
/// leave room by a few hundredths of it.
const LANDED: f32 = 0.1;

/// What [`Between::keep`] reuses: the boxes where two solids' offsets may overlap.
#[derive(Clone, Debug, Default)]
pub struct Between {
    regions: Vec<(Vec3, Vec3)>,
}

impl Between {
    /// Moves each free particle of `pass` that touches one of the solids among `effects`
    /// and is within the offset of another to where it keeps the offset clear of every
    /// one it is near (see the module's notes), its approach to each removed from its
    /// velocity. Only the particles in a box where two solids' offsets may overlap
    /// ([`Effect::shell`]) are asked. Returns how many it moved.
    pub fn keep(&mut self, effects: &[Effect], pass: &mut ContactPass<'_>) -> usize {
        let (t, offset) = (pass.state.time, pass.offset);
        let shells = || (effects.iter()).filter_map(|e| e.shell(t, e.clearance(offset)));
        self.regions.clear();
        for (k, (alo, ahi)) in shells().enumerate() {
            for (blo, bhi) in shells().skip(k + 1) {
                let (lo, hi) = (alo.max(blo), ahi.min(bhi));
                if lo.cmple(hi).all() {
                    self.regions.push((lo, hi));
                }
            }
        }
        if self.regions.is_empty() {
            return 0;
        }
        let (state, inv_mass) = (&mut *pass.state, &pass.model.inv_mass);
        let mut moved = 0;
        for (i, x) in state.pos.iter_mut().enumerate() {
            let inside = |&(lo, hi): &(Vec3, Vec3)| (x.cmpge(lo) & x.cmple(hi)).all();
            if !self.regions.iter().any(inside) || inv_mass.get(i).is_none_or(|&w| w == 0.0) {
                continue;
            }
            let Some(v) = state.vel.get_mut(i) else {
                continue;
            };
            if let Some((to, vel)) = between(effects, (*x, *v), t, offset) {
                (*x, *v) = (to, vel);
                moved += 1;
            }
        }
        moved
    }
}

/// A solid's surface near a particle: how far the particle is inside the offset of it
/// (`depth`, m; negative: that far clear), and the outward normal.
#[derive(Clone, Copy)]
struct Near {
    depth: f32,
    normal: Vec3,
}

/// Takes `near` into `two`, the two deepest so far, deepest first.
fn deeper_two(two: &mut [Option<Near>; 2], near: Near) {
    if two[0].is_none_or(|f| near.depth > f.depth) {
        *two = [Some(near), two[0]];
    } else if two[1].is_none_or(|s| near.depth > s.depth) {
        two[1] = Some(near);
    }
}

/// The two solids among `effects` whose offsets a particle at `x` is deepest in, at time
/// `t`, where it touches at least one (`None` for fewer than two touched).
fn deepest_two(effects: &[Effect], x: Vec3, t: f64, offset: f32) -> Option<[Near; 2]> {
    let mut two: [Option<Near>; 2] = [None, None];
    for e in effects {
        let Some((d, normal, _)) = e.surface(x, t) else {
            continue;
        };
        let kept = e.clearance(offset);
        if kept - d >= -TOUCHING * kept {
            deeper_two(
                &mut two,
                Near {
                    depth: kept - d,
                    normal,
                },
            );
        }
    }
    Some([two[0]?, two[1]?])
}

/// The least move that takes a particle `depth` along each of two unit normals (at least;
/// `[a, b]`), or where none can (they face each other), halfway between.
fn least_move([a, b]: [Near; 2]) -> Vec3 {
    let (da, db) = (a.depth.max(0.0), b.depth.max(0.0));
    // One of them alone may do for both.
    let along_a = da * a.normal;
    if along_a.dot(b.normal) >= db {
        return along_a;
    }
    let along_b = db * b.normal;
    if along_b.dot(a.normal) >= da {
        return along_b;
    }
    // Both: `x·a.normal + y·b.normal` meeting each depth exactly.
    let c = a.normal.dot(b.normal);
    let det = 1.0 - c * c;
    if det < 1e-6 {
        // Facing each other (alike ones were settled above): halfway, as deep in each.
        return 0.5 * (da - db) * a.normal;
    }
    let (x, y) = ((da - c * db) / det, (db - c * da) / det);
    x * a.normal + y * b.normal
}

/// Where a particle at `x` moving at `v` ends, and its velocity, if it touches one solid
/// among `effects` while within the offset of another (`None` otherwise): moved by the
/// least that keeps it clear of the two it is deepest in, a few rounds over, each no
/// longer than [`LONGEST`] times the depth it makes up.
fn between(effects: &[Effect], (x, v): (Vec3, Vec3), t: f64, offset: f32) -> Option<(Vec3, Vec3)> {
    let two = deepest_two(effects, x, t, offset)?;
    if two[0].depth <= TOUCHING * offset {
        // Touching both, within neither by more than their rounding: as the solids left it.
        return None;
    }
    let (mut x, mut near) = (x, two);
    for _ in 0..ROUNDS {
        x += least_move(near).clamp_length_max(LONGEST * near[0].depth);
        match deepest_two(effects, x, t, offset) {
            Some(now) if now[0].depth > TOUCHING * offset => near = now,
            _ => break,
        }
    }
    // Its approach to the surfaces it now touches (or nearly: [`LANDED`]) is taken out of
    // its velocity, the least change that leaves it moving towards neither (each solid's
    // own pass applied its friction): the two it approaches fastest, each approach speed
    // taken as a depth, as the place was settled.
    let mut approach: [Option<Near>; 2] = [None, None];
    for e in effects {
        let Some((d, normal, velocity)) = e.surface(x, t) else {
            continue;
        };
        if d <= e.clearance(offset) * (1.0 + LANDED) {
            let depth = (velocity - v).dot(normal);
            deeper_two(&mut approach, Near { depth, normal });
        }
    }
    // (One it moves away from counts too: taking out the other's approach may turn it
    // towards this one.)
    let v = match approach {
        [Some(a), _] if a.depth <= 0.0 => v,
        [Some(a), Some(b)] => v + least_move([a, b]),
        [Some(a), None] => v + a.depth * a.normal,
        _ => v,
    };
    Some((x, v))
}

#[cfg(test)]
mod tests;
