//! The tip pass of a mesh obstacle: every cloth triangle kept a thickness off the
//! obstacle's tips (a pyramid's apex, a table's corners), which can poke through a
//! triangle whose particles and edges all keep clear of the faces and the sharp edges;
//! and, under a triangle wide enough for the surface's curve to rise through it, off the
//! other vertices too. It runs where the solids keep the cloth's triangles out (as a
//! sphere's face pass does: in every stepper), in the edge pass's frame and after it.

use glam::{Vec3, Vec3A};

use super::super::effect_kind::ContactPass;
use super::super::solid::touching;
use super::edge_pass::{EdgeFrame, EdgeMemory, ForTips};
use crate::sim::obstacle::{Tips, closest_weights};

/// A cloth triangle is tested against the smooth parts' vertices too where a ball of their
/// largest curvature would rise under it by this share of the thickness or more
/// ([`sag`]), and against each vertex whose own curvature would: its particles keep the
/// thickness off the surface, so a bulge of less cannot reach through it.
const RISK: f32 = 1.0;

/// How far a ball of `curvature` rises under the triangle `x` above the circle its corners
/// lie on (for a curvature `κ` and a least enclosing circle of radius `ρ`, `κρ²/2`).
fn sag(x: [Vec3; 3], curvature: f32) -> f32 {
    let [a, b, c] = [x[1] - x[0], x[2] - x[1], x[0] - x[2]].map(|e| e.length_squared());
    let longest = a.max(b).max(c);
    // Right or obtuse: the longest edge is the circle's diameter; acute: the circumcircle.
    let radius_squared = if 2.0 * longest >= a + b + c {
        0.25 * longest
    } else {
        let twice_area = (x[1] - x[0]).cross(x[2] - x[0]).length_squared();
        a * b * c / (4.0 * twice_area).max(f32::MIN_POSITIVE)
    };
    0.5 * curvature * radius_squared
}

/// Keeps every cloth triangle of the patches near a tip `pass.offset` off each tip within
/// reach, and off each smooth vertex within reach where the surface could rise through it
/// ([`RISK`]), in the edge pass's frame, after it (`memory`, [`EdgeMemory::for_tips`]): a tip
/// whose nearest point of the triangle lies inside it must stay a thickness off on the
/// side of the triangle's plane it began the substep on; one nearest an edge or a corner
/// of the triangle must stay a thickness from that point. What is missing moves the
/// nearest point by exactly that, its corners in proportion to their weights in it; their
/// velocity towards the tip is removed, with Coulomb friction `mu` across it. Nothing
/// where the obstacle has no tips or the pass keeps only the cloth's particles and edges
/// out (no patches). Returns how many pushes it made.
pub(super) fn push_tips<S, L, W, V>(
    tips: &Tips,
    frame: &EdgeFrame<S, L, W, V>,
    mu: f32,
    pass: &mut ContactPass<'_>,
    memory: &mut EdgeMemory,
) -> usize
where
    L: Fn(Vec3) -> Vec3,
    W: Fn(Vec3) -> Vec3,
    V: Fn(Vec3) -> Vec3,
{
    let Some(faces) = pass.faces.as_deref_mut() else {
        return 0;
    };
    if tips.is_empty() {
        return 0;
    }
    let thickness = pass.offset;
    let (model, state) = (pass.model, &mut *pass.state);
    let ForTips {
        before,
        local,
        odometers,
        found,
        close,
        moved_by,
        rounding,
    } = memory.for_tips();
    // A point of a triangle that passed a tip in the substep ends at most this far from
    // it: its particles' moves in the frame, and the tips' own.
    let travel = (before.iter().zip(local.iter()))
        .fold(0.0f32, |m, (b, l)| m.max(b.distance_squared(*l)))
        .sqrt();
    let most = Vec3::splat(thickness + travel + moved_by + rounding);
    let (curvature, smooth) = (tips.curvature(), tips.curvature() > 0.0);
    let near = |lo: Vec3, hi: Vec3| tips.any_in_box(lo - most, hi + most, smooth);
    faces.flag(model, |i| local[i as usize], near);
    let counted = odometers.len() == local.len();
    let mut pushed = 0;
    for (triangles, lo, hi) in faces.flagged() {
        // The tips near the patch, then those near each of its triangles.
        found.clear();
        tips.in_box(lo - most, hi + most, |tip| found.push(tip.into()));
        for &t in triangles {
            let ids = model.triangles[t as usize].map(|i| i as usize);
            let corners = |local: &[Vec3A]| ids.map(|i| Vec3::from(local[i]));
            let x = corners(local);
            // Wide enough that the smooth parts could bulge through it.
            // How far a ball of unit curvature rises under it.
            let wide = if smooth { sag(x, 1.0) } else { 0.0 };
            let risky = smooth && wide * curvature >= RISK * thickness;
            if found.is_empty() && !risky {
                continue;
            }
            // Its own corners' moves bound its points' (and the tips' own move).
            let moves = ids.map(|i| before[i].distance_squared(local[i]));
            let moved = moves[0].max(moves[1]).max(moves[2]).sqrt();
            let reach = Vec3::splat(thickness + moved + moved_by + rounding);
            let (lo, hi) = (
                x[0].min(x[1]).min(x[2]) - reach,
                x[0].max(x[1]).max(x[2]) + reach,
            );
            // In lanes: the tips are many, and each is told in or out at once.
            let (lo_lanes, hi_lanes) = (Vec3A::from(lo), Vec3A::from(hi));
            close.clear();
            close.extend(
                found
                    .iter()
                    .filter(|tip| (tip.cmpge(lo_lanes) & tip.cmple(hi_lanes)).all()),
            );
            if risky {
                // Each vertex where its own curvature could bulge that far.
                tips.smooth_in_box(lo, hi, |p, curvature| {
                    if wide * curvature >= RISK * thickness {
                        close.push(p.into());
                    }
                });
            }
            if close.is_empty() {
                continue;
            }
            let start = corners(before);
            let mut face = Face::new(x, start);
            let free = ids.map(|i| f32::from(model.inv_mass[i] > 0.0));
            for tip in close.iter().map(|&tip| Vec3::from(tip)) {
                let Some(Push { gap, away, w }) = face.missing(tip, thickness) else {
                    continue;
                };
                let weight: f32 = (0..3).map(|k| w[k] * w[k] * free[k]).sum();
                if weight <= 0.0 {
                    continue;
                }
                let (n, by) = ((frame.to_world)(away), (frame.to_world)(gap * away));
                let v_surface = (frame.velocity)(tip);
                for k in 0..3 {
                    let (i, part) = (ids[k], w[k] * free[k]);
                    if part <= 0.0 {
                        continue;
                    }
                    state.pos[i] += by * (part / weight);
                    state.vel[i] = touching(state.vel[i], v_surface, n, mu, part);
                    let was =
                        std::mem::replace(&mut local[i], (frame.to_local)(state.pos[i]).into());
                    if counted {
                        odometers[i] += f64::from(local[i].distance(was) + rounding);
                    }
                }
                face = Face::new(corners(local), start);
                pushed += 1;
            }
        }
    }
    pushed
}

/// A cloth triangle as the tip pass measures it: its corners in the frame and its unit
/// normal (zero for a degenerate one), and the plane it began the substep in (a corner
/// and a normal, not of unit length).
struct Face {
    x: [Vec3; 3],
    normal: Vec3,
    start: Vec3,
    began: Vec3,
}

/// What a triangle's nearest point to a tip must move by (m), which way (a unit vector),
/// and its corners' weights in that point.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Push {
    gap: f32,
    away: Vec3,
    w: [f32; 3],
}

impl Face {
    /// The triangle with corners `x`, where it began the substep at `start`.
    fn new(x: [Vec3; 3], start: [Vec3; 3]) -> Self {
        Face {
            x,
            normal: (x[1] - x[0]).cross(x[2] - x[0]).normalize_or_zero(),
            start: start[0],
            began: (start[1] - start[0]).cross(start[2] - start[0]),
        }
    }

    /// How the triangle must move to keep `thickness` off `tip` on the side it must keep
    /// (see [`push_tips`]); `None` where it keeps it already.
    fn missing(&self, tip: Vec3, thickness: f32) -> Option<Push> {
        let (x, normal) = (self.x, self.normal);
        if normal == Vec3::ZERO {
            return None;
        }
        // The side of the triangle the tip must keep: the side of its plane the tip began
        // the substep on (where it began in the plane, the side it ends on).
        let over = (tip - self.start).dot(self.began);
        let plane = (tip - x[0]).dot(normal);
        if over * plane > 0.0 && plane.abs() >= thickness {
            // On its side of the plane, and the thickness off it: off every point of it.
            return None;
        }
        let side = if over != 0.0 {
            over.signum()
        } else {
            plane.signum()
        };
        let w = closest_weights(tip, x);
        let q = w[0] * x[0] + w[1] * x[1] + w[2] * x[2];
        let height = side * (tip - q).dot(normal);
        if w.iter().all(|&w| w > 0.0) {
            // Inside: the triangle goes to the far side of the tip.
            let away = -side * normal;
            return (height < thickness).then_some(Push {
                gap: thickness - height,
                away,
                w,
            });
        }
        // Nearest an edge or a corner: kept a thickness off, where on its side.
        let (off, distance) = (q - tip, q.distance(tip));
        let room = distance > thickness * 1e-3 && height >= 0.0;
        (room && distance < thickness).then(|| Push {
            gap: thickness - distance,
            away: off / distance,
            w,
        })
    }
}

#[cfg(test)]
mod tests;
