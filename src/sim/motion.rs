//! Prescribed rigid motion through keyframes: where a moving obstacle or a handle is at any
//! time, and how fast each of its points moves.
//!
//! A keyframe gives a time and, optionally, a translation and a rotation (axis and angle,
//! about the motion's pivot); a key it leaves out keeps the keyframe before's value (the
//! first keyframe's default: none). Between two keyframes the translation and the angle go
//! linearly in time, so 720° is two turns at a constant rate; where the two keyframes turn
//! about different axes, the rotation goes the shortest way between them (a slerp). A
//! keyframe with `ease = "smooth"` is eased into: the segment that ends at it follows
//! `s = 3u² − 2u³` of its time fraction `u` (a cubic Hermite with zero velocity at both
//! ends). Before the first keyframe the motion is at the first; after the last it holds still.

use glam::{Quat, Vec3};

/// An angle about an axis: `axis` any non-zero vector (normalised where it is used),
/// `degrees` the angle (right-handed).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisAngle {
    pub axis: Vec3,
    pub degrees: f32,
}

/// How a keyframe is reached from the one before.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Ease {
    /// At a constant rate (default).
    #[default]
    Linear,
    /// Starting and arriving at rest (cubic Hermite).
    Smooth,
}

fn is_linear(ease: &Ease) -> bool {
    *ease == Ease::Linear
}

/// One keyframe as a scene file writes it.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Keyframe {
    /// Seconds from the start.
    pub time: f64,
    /// Metres, added to where the thing was placed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub translate: Option<Vec3>,
    /// About the motion's pivot.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotate: Option<AxisAngle>,
    #[serde(default, skip_serializing_if = "is_linear")]
    pub ease: Ease,
}

/// A keyframe list that is not a motion: which keyframe (0-based), which key, and why.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("keyframe {index}: `{key}` {problem}")]
pub struct MotionError {
    pub index: usize,
    pub key: &'static str,
    pub problem: String,
}

/// Where a rigid motion is at one time: `point ↦ pivot + translation + rotation·(point −
/// pivot)`, with the velocity of the translation and the angular velocity (world frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    pub translation: Vec3,
    pub rotation: Quat,
    /// m/s.
    pub velocity: Vec3,
    /// rad/s, axis × rate.
    pub spin: Vec3,
}

impl Pose {
    /// No motion.
    pub const REST: Pose = Pose {
        translation: Vec3::ZERO,
        rotation: Quat::IDENTITY,
        velocity: Vec3::ZERO,
        spin: Vec3::ZERO,
    };

    /// Where `point` (as placed) is, with the motion about `pivot`.
    pub fn apply(&self, pivot: Vec3, point: Vec3) -> Vec3 {
        pivot + self.translation + self.rotation * (point - pivot)
    }

    /// Where a point that is at `moved` now (already moved) came from, as placed.
    pub fn unapply(&self, pivot: Vec3, moved: Vec3) -> Vec3 {
        pivot + self.rotation.inverse() * (moved - pivot - self.translation)
    }

    /// The velocity of the point that is at `moved` now, m/s.
    pub fn velocity_at(&self, pivot: Vec3, moved: Vec3) -> Vec3 {
        self.velocity + self.spin.cross(moved - pivot - self.translation)
    }
}

/// One keyframe with every key filled in.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Key {
    time: f64,
    translate: Vec3,
    /// Unit axis (Y where the angle is zero and no axis was ever given).
    axis: Vec3,
    /// Radians.
    angle: f32,
    ease: Ease,
}

impl Key {
    fn rotation(&self) -> Quat {
        Quat::from_axis_angle(self.axis, self.angle)
    }
}

/// A checked keyframe list ([`RigidMotion::new`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RigidMotion {
    keys: Vec<Key>,
}

impl RigidMotion {
    /// The motion through `frames`.
    ///
    /// # Errors
    /// [`MotionError`] for a time that is not finite, negative, out of order or repeated, a
    /// translation or angle that is not finite, or a zero axis.
    pub fn new(frames: &[Keyframe]) -> Result<Self, MotionError> {
        let mut keys: Vec<Key> = Vec::with_capacity(frames.len());
        for (index, f) in frames.iter().enumerate() {
            let bad = |key, problem: &str| MotionError {
                index,
                key,
                problem: problem.to_string(),
            };
            if !(f.time.is_finite() && f.time >= 0.0) {
                return Err(bad("time", "must be a finite number of seconds ≥ 0"));
            }
            if let Some(before) = keys.last()
                && f.time <= before.time
            {
                return Err(bad(
                    "time",
                    &format!("must be later than the keyframe before ({} s)", before.time),
                ));
            }
            let before = keys.last().copied().unwrap_or(Key {
                time: 0.0,
                translate: Vec3::ZERO,
                axis: Vec3::Y,
                angle: 0.0,
                ease: Ease::Linear,
            });
            let translate = match f.translate {
                Some(t) if !t.is_finite() => return Err(bad("translate", "must be finite")),
                Some(t) => t,
                None => before.translate,
            };
            let (axis, angle) = match f.rotate {
                Some(r) => {
                    if !(r.axis.is_finite() && r.degrees.is_finite()) {
                        return Err(bad("rotate", "must be finite"));
                    }
                    let Some(axis) = r.axis.try_normalize() else {
                        return Err(bad("rotate", "needs a non-zero axis"));
                    };
                    (axis, r.degrees.to_radians())
                }
                None => (before.axis, before.angle),
            };
            keys.push(Key {
                time: f.time,
                translate,
                axis,
                angle,
                ease: f.ease,
            });
        }
        Ok(Self { keys })
    }

    /// Whether it moves at all (two keyframes or more).
    pub fn moves(&self) -> bool {
        self.keys.len() > 1
    }

    /// The time of the last keyframe, after which it holds still (0 without keyframes).
    pub fn end(&self) -> f64 {
        self.keys.last().map_or(0.0, |k| k.time)
    }

    /// The pose at time `t`, seconds.
    pub fn at(&self, t: f64) -> Pose {
        let Some(first) = self.keys.first() else {
            return Pose::REST;
        };
        let still = |k: &Key| Pose {
            translation: k.translate,
            rotation: k.rotation(),
            velocity: Vec3::ZERO,
            spin: Vec3::ZERO,
        };
        if t <= first.time {
            return still(first);
        }
        let next = self.keys.partition_point(|k| k.time <= t);
        let (Some(a), Some(b)) = (self.keys.get(next.wrapping_sub(1)), self.keys.get(next)) else {
            return still(self.keys.last().unwrap_or(first));
        };
        let span = b.time - a.time;
        let u = ((t - a.time) / span) as f32;
        // The fraction of the way and its rate, per second.
        let (s, ds_dt) = match b.ease {
            Ease::Linear => (u, 1.0 / span as f32),
            Ease::Smooth => (u * u * (3.0 - 2.0 * u), 6.0 * u * (1.0 - u) / span as f32),
        };
        let translation = a.translate.lerp(b.translate, s);
        let velocity = (b.translate - a.translate) * ds_dt;
        let (rotation, spin) = match same_axis(a, b) {
            // One axis: the angle goes linearly, so whole turns count.
            Some((axis, from, to)) => {
                let angle = from + (to - from) * s;
                (
                    Quat::from_axis_angle(axis, angle),
                    axis * (to - from) * ds_dt,
                )
            }
            // Different axes: the shortest way from one rotation to the other.
            None => {
                let (qa, qb) = (a.rotation(), b.rotation());
                let mut rel = qb * qa.inverse();
                if rel.w < 0.0 {
                    rel = -rel;
                }
                let (axis, angle) = rel.to_axis_angle();
                (
                    Quat::from_axis_angle(axis, angle * s) * qa,
                    axis * angle * ds_dt,
                )
            }
        };
        Pose {
            translation,
            rotation,
            velocity,
            spin,
        }
    }
}

/// The common axis of two keys and their angles about it, where they turn about one axis
/// (either way round, or one of them not at all).
fn same_axis(a: &Key, b: &Key) -> Option<(Vec3, f32, f32)> {
    const PARALLEL: f32 = 1.0 - 1e-6;
    if a.angle == 0.0 {
        return Some((b.axis, 0.0, b.angle));
    }
    if b.angle == 0.0 {
        return Some((a.axis, a.angle, 0.0));
    }
    let d = a.axis.dot(b.axis);
    if d >= PARALLEL {
        Some((a.axis, a.angle, b.angle))
    } else if d <= -PARALLEL {
        Some((a.axis, a.angle, -b.angle))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time: f64) -> Keyframe {
        Keyframe {
            time,
            translate: None,
            rotate: None,
            ease: Ease::Linear,
        }
    }

    fn turn(axis: Vec3, degrees: f32) -> Option<AxisAngle> {
        Some(AxisAngle { axis, degrees })
    }

    fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
        (a - b).length() <= tol
    }

    /// Two keyframes, 720° about z in 2 s from rest: at 0.25 s the point has turned 90°,
    /// at 0.75 s 270°, at a constant 2π rad/s, with the translation linear in time.
    #[test]
    fn a_turn_of_720_degrees_is_two_turns_at_a_constant_rate() {
        let motion = RigidMotion::new(&[
            key(0.0),
            Keyframe {
                translate: Some(Vec3::new(0.5, 0.0, 0.0)),
                rotate: turn(Vec3::Z, 720.0),
                ..key(2.0)
            },
        ])
        .unwrap();
        let point = Vec3::X;
        for (t, degrees) in [(0.25, 90.0f32), (0.75, 270.0), (1.5, 540.0)] {
            let pose = motion.at(t);
            let expected = Quat::from_rotation_z(degrees.to_radians()) * point
                + Vec3::new(0.25 * t as f32, 0.0, 0.0);
            assert!(
                close(pose.apply(Vec3::ZERO, point), expected, 1e-5),
                "{t} s"
            );
            assert!(close(pose.spin, Vec3::Z * std::f32::consts::TAU, 1e-4));
            assert!(close(pose.velocity, Vec3::new(0.25, 0.0, 0.0), 1e-6));
        }
        // After the last keyframe: still, where it ended.
        let end = motion.at(5.0);
        assert_eq!((end.velocity, end.spin), (Vec3::ZERO, Vec3::ZERO));
        assert!(close(
            end.apply(Vec3::ZERO, point),
            Vec3::new(1.5, 0.0, 0.0),
            1e-5
        ));
        // Before the first: at the first.
        assert_eq!(motion.at(-1.0).apply(Vec3::ZERO, point), point);
    }

    /// A smooth keyframe is reached with zero velocity at both ends and half-way at the
    /// middle time; the velocity is the derivative of the position (finite differences).
    #[test]
    fn easing_starts_and_arrives_at_rest_and_the_velocity_is_the_derivative() {
        let motion = RigidMotion::new(&[
            key(1.0),
            Keyframe {
                translate: Some(Vec3::new(0.0, 2.0, 0.0)),
                rotate: turn(Vec3::Z, 90.0),
                ease: Ease::Smooth,
                ..key(3.0)
            },
        ])
        .unwrap();
        let (pivot, point) = (Vec3::new(0.1, 0.0, 0.0), Vec3::new(0.6, 0.3, 0.2));
        for t in [1.0, 3.0] {
            let pose = motion.at(t);
            assert!(pose.velocity.length() < 1e-6 && pose.spin.length() < 1e-6);
        }
        let middle = motion.at(2.0);
        assert!(close(middle.translation, Vec3::new(0.0, 1.0, 0.0), 1e-6));
        for t in [1.3, 2.0, 2.6] {
            let pose = motion.at(t);
            let h = 1e-3;
            let (before, after) = (motion.at(t - h), motion.at(t + h));
            let numeric =
                (after.apply(pivot, point) - before.apply(pivot, point)) / (2.0 * h as f32);
            let moved = pose.apply(pivot, point);
            let analytic = pose.velocity_at(pivot, moved);
            assert!(
                close(numeric, analytic, 2e-3 * analytic.length().max(1.0)),
                "{t}: {numeric} vs {analytic}"
            );
            assert!(close(pose.unapply(pivot, moved), point, 1e-5));
        }
    }

    /// Neighbouring keyframes about different axes: the rotation goes the shortest way
    /// between them (its angle to each end adds up to the angle between the ends), and the
    /// spin is about the axis of the rotation from one to the other.
    #[test]
    fn different_axes_go_the_shortest_way() {
        let motion = RigidMotion::new(&[
            Keyframe {
                rotate: turn(Vec3::X, 90.0),
                ..key(0.0)
            },
            Keyframe {
                rotate: turn(Vec3::Y, 90.0),
                ..key(1.0)
            },
        ])
        .unwrap();
        let (qa, qb) = (
            Quat::from_rotation_x(90f32.to_radians()),
            Quat::from_rotation_y(90f32.to_radians()),
        );
        let whole = qa.angle_between(qb);
        for t in [0.25, 0.5, 0.8] {
            let q = motion.at(t).rotation;
            let (to_a, to_b) = (q.angle_between(qa), q.angle_between(qb));
            assert!((to_a + to_b - whole).abs() < 1e-4, "{t}");
            assert!((to_a - whole * t as f32).abs() < 1e-4, "{t}");
        }
        let spin = motion.at(0.5).spin;
        assert!((spin.length() - whole).abs() < 1e-4);
    }

    /// A key left out keeps the keyframe before's value.
    #[test]
    fn a_missing_key_means_no_change() {
        let motion = RigidMotion::new(&[
            Keyframe {
                translate: Some(Vec3::X),
                rotate: turn(Vec3::Z, 30.0),
                ..key(0.0)
            },
            key(1.0),
            Keyframe {
                translate: Some(Vec3::Y),
                ..key(2.0)
            },
        ])
        .unwrap();
        let pose = motion.at(0.5);
        assert!(close(pose.translation, Vec3::X, 1e-6));
        assert_eq!(pose.spin, Vec3::ZERO);
        let later = motion.at(1.5);
        assert!(close(later.translation, (Vec3::X + Vec3::Y) / 2.0, 1e-6));
        let turned = Quat::from_rotation_z(30f32.to_radians()) * Vec3::X;
        assert!(close(later.rotation * Vec3::X, turned, 1e-6));
    }

    #[test]
    fn bad_keyframes_are_named() {
        let cases: [(Vec<Keyframe>, usize, &str); 5] = [
            (vec![key(1.0), key(0.5)], 1, "time"),
            (vec![key(1.0), key(1.0)], 1, "time"),
            (vec![key(f64::NAN)], 0, "time"),
            (
                vec![
                    key(0.0),
                    Keyframe {
                        rotate: turn(Vec3::ZERO, 10.0),
                        ..key(1.0)
                    },
                ],
                1,
                "rotate",
            ),
            (
                vec![Keyframe {
                    translate: Some(Vec3::new(f32::INFINITY, 0.0, 0.0)),
                    ..key(0.0)
                }],
                0,
                "translate",
            ),
        ];
        for (frames, index, key_name) in cases {
            let err = RigidMotion::new(&frames).unwrap_err();
            assert_eq!((err.index, err.key), (index, key_name), "{err}");
        }
    }
}
