//! Where a scene's action happens: the points a default camera should keep in view.

use glam::{Quat, Vec3};

use crate::mesh::bounds;
use crate::sim::Effect;

use super::simulation::Simulation;

/// Particles sampled for the swing of a pinned cloth (every k-th, at most about this many).
const SAMPLED_PARTICLES: usize = 256;
/// Angles sampled along each particle's swing.
const SWING_SAMPLES: usize = 12;

impl Simulation {
    /// Points (metres) that the cloth reaches over its motion, with the spheres it meets.
    ///
    /// A pinned cloth swings about the line through its pins: each particle moves on a
    /// circle about that line from where it starts, down through the lowest point and up the
    /// other side to the same height (a rigid swing, which the hanging cloth follows closely).
    /// A free cloth falls to the ground or onto its spheres, or about its own size when there
    /// is nothing to land on.
    pub fn motion_points(&self) -> Vec<Vec3> {
        let start = &self.initial().pos;
        let pins: Vec<Vec3> = self
            .model()
            .pins
            .iter()
            .map(|&p| start[p as usize])
            .collect();
        if pins.is_empty() {
            self.fall_points()
        } else {
            swing_points(start, &pins)
        }
    }

    /// The box around [`Simulation::motion_points`], `(lo, hi)` in metres.
    pub fn motion_bounds(&self) -> (Vec3, Vec3) {
        bounds(&self.motion_points())
    }

    fn fall_points(&self) -> Vec<Vec3> {
        let (mut lo, mut hi) = bounds(&self.initial().pos);
        let size = (hi - lo).max_element();
        let ground = self.effects().iter().find_map(|e| match e {
            Effect::Plane(p) if p.unit_normal().y > 0.9 => Some(p.point.y),
            _ => None,
        });
        let mut landed = false;
        for e in self.effects() {
            if let Effect::Sphere(s) = e {
                lo = lo.min(s.center - Vec3::splat(s.radius));
                hi = hi.max(s.center + Vec3::splat(s.radius));
                landed = true;
            }
        }
        lo.y = match ground {
            Some(y) => lo.y.min(y),
            None if !landed => lo.y - size,
            None => lo.y,
        };
        (0..8)
            .map(|i| {
                Vec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                )
            })
            .collect()
    }
}

/// Samples each (sampled) particle's circle about the pin line, from its start to the same
/// height on the other side.
fn swing_points(start: &[Vec3], pins: &[Vec3]) -> Vec<Vec3> {
    let origin = pins[0];
    let along = pins[pins.len() - 1] - origin;
    // With one pin (or pins one above another) the cloth swings about the horizontal axis
    // through the pin that is square to the direction of the cloth's centre.
    let axis = if along.length() > 1e-6 {
        along.normalize()
    } else {
        let centre = start.iter().sum::<Vec3>() / start.len() as f32;
        let out = (centre - origin) * Vec3::new(1.0, 0.0, 1.0);
        out.cross(Vec3::Y).try_normalize().unwrap_or(Vec3::X)
    };
    let stride = (start.len() / SAMPLED_PARTICLES).max(1);
    let mut points = Vec::with_capacity(start.len() / stride * (SWING_SAMPLES + 1));
    for &p in start.iter().step_by(stride) {
        let r = p - origin;
        let radial = r - r.dot(axis) * axis;
        // Signed angle from straight down to the particle, about the axis.
        let down = (-Vec3::Y - (-Vec3::Y).dot(axis) * axis).normalize_or_zero();
        let phi = down.cross(radial).dot(axis).atan2(down.dot(radial));
        for k in 0..=SWING_SAMPLES {
            let theta = -2.0 * phi * k as f32 / SWING_SAMPLES as f32;
            points.push(origin + Quat::from_axis_angle(axis, theta) * r);
        }
    }
    points
}
