//! What the guard can see behind a frame nothing saved: the likely cause, and what to do
//! about it. The message a user reads names that cause instead of always the stiffness.

use glam::Vec3;

use crate::cloth::{ClothModel, Real};

use super::effects::TooThick;
use super::forces::ForceSet;
use super::integrator::IntegratorKind;

/// Power-iteration sweeps for the stiffest vibration: the estimate (a Rayleigh quotient,
/// never above the true value) is within a few percent of it on a grid cloth by then.
const SWEEPS: usize = 64;

/// Substeps per frame beyond which a method is said to have no practical stable step.
const PRACTICAL_SUBSTEPS: f64 = 100_000.0;

/// The likely cause of a frame nothing saved.
#[derive(Clone, Debug, PartialEq)]
pub enum Cause {
    /// An explicit integrator's substep is longer than its stable step for the cloth's
    /// stiffest spring vibration.
    Substeps {
        integrator: IntegratorKind,
        /// Angular frequency of the stiffest vibration, rad/s.
        omega: f32,
        /// Substeps per frame that make the integrator stable on it (`None`: no practical
        /// number does, with so little damping).
        needed: Option<u32>,
        /// The most substeps per frame the guard tried.
        tried: u32,
        /// Implicit Euler was among the integrators tried (the advice then names only
        /// XPBD).
        implicit_tried: bool,
    },
    /// The self-collision thickness is at or above the cloth's shortest rest edge.
    Thickness(TooThick),
    /// A held particle pulls the cloth harder than it can follow (`implicit_tried` as for
    /// [`Cause::Substeps`]).
    Pull { implicit_tried: bool },
    /// A handle has moved the cloth: it may carry it faster than it can follow, or, with
    /// `self_contact`, hold it nearer other cloth than the thickness leaves room for
    /// (`implicit_tried` as for [`Cause::Substeps`]).
    Handle {
        implicit_tried: bool,
        self_contact: bool,
    },
    /// The step backend failed or cannot run the scene.
    Backend,
    /// Nothing more specific: the springs are too stiff for the step (`implicit_tried` as
    /// for [`Cause::Substeps`]).
    Stiffness { implicit_tried: bool },
}

impl std::fmt::Display for Cause {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // The integrators stable at any step, less one that already failed.
        let stable = |tried: bool| match tried {
            true => "XPBD",
            false => "implicit Euler or XPBD",
        };
        match self {
            Cause::Substeps {
                integrator,
                omega,
                needed: Some(needed),
                tried,
                implicit_tried,
            } => write!(
                f,
                "Too few substeps for the stiffness: {} is stable on this cloth's stiffest \
                 spring vibration ({omega:.0} rad/s) only from about {needed} substeps per \
                 frame (tried up to {tried}). Raise the substeps, lower the stiffness, or \
                 choose {} (stable at any step).",
                integrator.label(),
                stable(*implicit_tried)
            ),
            Cause::Substeps {
                integrator,
                omega,
                needed: None,
                implicit_tried,
                ..
            } => write!(
                f,
                "{} has no practical stable step on this cloth's stiffest spring vibration \
                 ({omega:.0} rad/s) with so little damping. Choose {} (stable at any step), \
                 or add damping.",
                integrator.label(),
                stable(*implicit_tried)
            ),
            Cause::Thickness(too_thick) => write!(f, "The likely cause: {too_thick}."),
            Cause::Pull { implicit_tried } => write!(
                f,
                "The held particle pulls the cloth harder than it can follow: move the pointer \
                 more slowly{}.",
                match implicit_tried {
                    true => " or raise the substeps (implicit Euler failed too)",
                    false => ", raise the substeps, or choose implicit Euler",
                }
            ),
            Cause::Handle {
                implicit_tried,
                self_contact,
            } => {
                let (hold, thinner) = match self_contact {
                    true => (
                        ", or hold it nearer other cloth than the self-collision thickness",
                        ", lower the thickness",
                    ),
                    false => ("", ""),
                };
                write!(
                    f,
                    "A handle carries the cloth: it may move it faster than the cloth can \
                     follow{hold}. Slow the handle's keyframes{thinner}, lower the stiffness{}.",
                    match implicit_tried {
                        true => " or raise the substeps (implicit Euler failed too)",
                        false => ", raise the substeps, or choose implicit Euler",
                    }
                )
            }
            Cause::Backend => f.write_str("The step backend failed; try the CPU backend."),
            Cause::Stiffness {
                implicit_tried: true,
            } => f.write_str(
                "Lower the stiffness or raise the substeps (implicit Euler failed too).",
            ),
            Cause::Stiffness {
                implicit_tried: false,
            } => f.write_str("Lower the stiffness, raise the substeps, or choose implicit Euler."),
        }
    }
}

impl Cause {
    /// [`Cause::Substeps`] when `integrator` at `tried` substeps of a `dt`-second frame is
    /// past its stable step for the stiffest vibration of the spring terms in `forces` about
    /// `pos` (with air damping at `air_damping` 1/s); `None` otherwise.
    pub fn substeps<R: Real>(
        integrator: IntegratorKind,
        model: &ClothModel,
        forces: &ForceSet<R>,
        pos: &[Vec3],
        air_damping: f32,
        dt: f32,
        tried: u32,
    ) -> Option<Cause> {
        let vibration = stiffest_vibration(model, forces, pos, air_damping)?;
        let stable = integrator.stable_substep(vibration.omega as f64, vibration.gamma as f64)?;
        let h = dt as f64 / tried.max(1) as f64;
        if h <= stable {
            return None;
        }
        let needed = (dt as f64 / stable).ceil();
        Some(Cause::Substeps {
            integrator,
            omega: vibration.omega,
            needed: (needed <= PRACTICAL_SUBSTEPS).then_some(needed as u32),
            tried,
            implicit_tried: false,
        })
    }

    /// The cause of a frame that failed under `integrator` and, where the guard tried it,
    /// `fallback`: [`Cause::Substeps`] as [`Cause::substeps`] finds it, else
    /// [`Cause::Stiffness`]; their advice names no integrator among those.
    pub fn of_springs(
        substeps: Option<Cause>,
        integrator: IntegratorKind,
        fallback: Option<IntegratorKind>,
    ) -> Cause {
        let implicit_tried =
            [Some(integrator), fallback].contains(&Some(IntegratorKind::ImplicitEuler));
        let mut cause = substeps.unwrap_or(Cause::Stiffness { implicit_tried });
        if let Cause::Substeps {
            implicit_tried: t, ..
        } = &mut cause
        {
            *t = implicit_tried;
        }
        cause
    }
}

/// The stiffest vibration of a cloth's springs about a shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vibration {
    /// Angular frequency, rad/s.
    pub omega: f32,
    /// Damping rate of that vibration (its dashpots and the air), 1/s.
    pub gamma: f32,
}

/// The stiffest vibration of the spring terms of `forces` about the shape `pos`: power
/// iteration on `M^-½·K·M^-½`, `K` the springs' stiffness along their current directions
/// (pinned particles held), with the dashpots' and the air's damping of the mode found.
/// `None` without springs.
pub fn stiffest_vibration<R: Real>(
    model: &ClothModel,
    forces: &ForceSet<R>,
    pos: &[Vec3],
    air_damping: f32,
) -> Option<Vibration> {
    let scale: Vec<f32> = model.inv_mass.iter().map(|w| w.sqrt()).collect();
    // Springs as (a, b, direction, k, c), read once.
    let s = &model.springs;
    let springs: Vec<(usize, usize, Vec3, f32, f32)> = forces
        .springs()
        .flat_map(|t| t.each())
        .filter_map(|(e, k, c)| {
            let (a, b) = (s.a[e] as usize, s.b[e] as usize);
            let n = (pos[b] - pos[a]).try_normalize()?;
            Some((a, b, n, k, c))
        })
        .collect();
    if springs.is_empty() {
        return None;
    }
    // `M^-½·S·M^-½·y` for the springs' stiffness (k) or their dashpots (c).
    let apply = |y: &[Vec3], pick: fn(f32, f32) -> f32| {
        let mut out = vec![Vec3::ZERO; y.len()];
        for &(a, b, n, k, c) in &springs {
            let t = pick(k, c) * n.dot(scale[a] * y[a] - scale[b] * y[b]);
            out[a] += t * n;
            out[b] -= t * n;
        }
        for (o, &w) in out.iter_mut().zip(&scale) {
            *o *= w;
        }
        out
    };
    // A fixed start with a part along every mode: signs from a hash of the index.
    let mut y: Vec<Vec3> = (0..pos.len())
        .map(|i| {
            let h = (i as u32).wrapping_mul(0x9E37_79B9);
            let sign = |bit: u32| if h >> bit & 1 == 0 { 1.0 } else { -1.0 };
            Vec3::new(sign(7), sign(13), sign(21)) * scale[i].signum()
        })
        .collect();
    let norm = |y: &[Vec3]| {
        y.iter()
            .map(|v| v.length_squared() as f64)
            .sum::<f64>()
            .sqrt()
    };
    let mut lambda = 0.0f64;
    for _ in 0..SWEEPS {
        let length = norm(&y);
        if length == 0.0 {
            return None;
        }
        y.iter_mut().for_each(|v| *v /= length as f32);
        let z = apply(&y, |k, _| k);
        lambda = y.iter().zip(&z).map(|(a, b)| a.dot(*b) as f64).sum();
        y = z;
    }
    let length = norm(&y);
    if !(lambda > 0.0 && length > 0.0) {
        return None;
    }
    y.iter_mut().for_each(|v| *v /= length as f32);
    let dashpots: f64 = (y.iter().zip(apply(&y, |_, c| c)))
        .map(|(a, b)| a.dot(b) as f64)
        .sum();
    Some(Vibration {
        omega: lambda.sqrt() as f32,
        gamma: dashpots as f32 + air_damping,
    })
}
