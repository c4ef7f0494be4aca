//! Extended position-based dynamics (XPBD) with small steps.

use glam::Vec3;

use super::super::constraints::{Coloured, DistanceConstraints};
use super::super::forces::Force;
use super::super::team::{Disjoint, Team, share};
use super::context::StepContext;
use super::kind::IntegratorKind;
use super::step::{Integrator, StepError, StepReport};
use crate::cloth::ClothState;

/// A particle's predicted position and its displacement this step.
#[derive(Clone, Copy, Debug)]
struct Moved {
    predicted: Vec3,
    displacement: Vec3,
}

/// Each substep: the forces that are not springs (gravity, air damping, …) move the
/// particles explicitly to a prediction; then every spring, seen as a distance constraint
/// with compliance `α = 1/k`, is projected in `xpbd_iterations` Gauss–Seidel sweeps with its
/// Lagrange multiplier (XPBD), visited colour by colour
/// ([`DistanceConstraints::coloured`]), and its dashpot `c` as constraint damping `γ = α·c/h`;
/// finally `v = (x' − x)/h`. With many small substeps and one sweep this is the "small steps"
/// method: stable at any stiffness, and as `α → 0` it approaches inextensible springs.
///
/// The step's displacement `x' − x` is kept beside the predicted positions and updated with
/// them: recovering it as a difference of two nearly equal f32 positions would lose most of
/// its digits at small steps (a 1 m/s particle moves 0.2 mm in a 0.2 ms step, a thousand
/// rounding units of a coordinate near 1 m), and that noise grows as the step shrinks.
#[derive(Default)]
pub struct Xpbd {
    /// The springs as constraints, in colour order.
    coloured: Coloured,
    built: bool,
    force: Vec<Vec3>,
    /// Per particle, its predicted position and its displacement side by side (a
    /// projection touches both: one cache line rather than two).
    moved: Vec<Moved>,
    lambda: Vec<f32>,
}

impl Xpbd {
    /// One Gauss–Seidel sweep over every constraint, colour by colour; a colour with enough
    /// constraints is shared out between the threads of the [`Team`] (its constraints
    /// share no particle, so the order within it changes nothing: the same bits on any
    /// number of threads).
    fn sweep(&mut self, inv_mass: &[f32], h: f32) {
        let c = &self.coloured.constraints;
        // `project` indexes `inv_mass` first (checked), so these make its other accesses in
        // bounds.
        assert!(self.moved.len() >= inv_mass.len());
        assert!(self.lambda.len() >= c.len());
        let team = Team::current();
        let moved = Disjoint::new(&mut self.moved);
        let lambda = Disjoint::new(&mut self.lambda);
        let project = |k: usize| {
            // SAFETY: constraint k's particles and multiplier are touched by no other
            // constraint of its colour, and colours run one after another; the arrays'
            // lengths were checked above.
            unsafe { project(c, k, inv_mass, h, &moved, &lambda) };
        };
        for (range, independent) in &self.coloured.colours {
            if *independent && team.members() > 1 && range.len() >= PARALLEL_COLOUR {
                team.run(&|i| {
                    share(range.len(), team.members(), i).for_each(|k| project(range.start + k))
                });
            } else {
                range.clone().for_each(project);
            }
        }
    }
}

/// Colours from this many constraints are shared out between threads.
const PARALLEL_COLOUR: usize = 1024;

/// Projects constraint `k` (XPBD with constraint damping), moving its particles' predicted
/// positions and displacements and its multiplier.
///
/// # Safety
/// No other thread may use constraint `k`'s particles or multiplier meanwhile; `moved` is at
/// least as long as `inv_mass`, and `lambda` as `c`.
#[inline(always)]
unsafe fn project(
    c: &DistanceConstraints,
    k: usize,
    inv_mass: &[f32],
    h: f32,
    moved: &Disjoint<'_, Moved>,
    lambda: &Disjoint<'_, f32>,
) {
    let (a, b) = (c.a[k] as usize, c.b[k] as usize);
    let (wa, wb) = (inv_mass[a], inv_mass[b]);
    if wa + wb == 0.0 {
        return;
    }
    // SAFETY: in bounds (`inv_mass[a]`, `inv_mass[b]` and `c.a[k]` were checked, and the
    // caller's contract sizes the rest); no other thread uses them (the caller's contract).
    // Each `at` is read at once, so even a self-constraint (a = b) holds no two borrows.
    let (ma, mb, lambda) = unsafe { (*moved.at(a), *moved.at(b), lambda.at(k)) };
    let (pa, pb, dxa, dxb) = (ma.predicted, mb.predicted, ma.displacement, mb.displacement);
    let d = pb - pa;
    let len = d.length();
    if len <= 1e-9 {
        return;
    }
    let n = d / len;
    let alpha = c.compliance[k] / (h * h);
    let gamma = c.compliance[k] * c.damping[k] / h;
    // ∇C · (p − x): how fast the constraint is changing this step.
    let rate = n.dot(dxb - dxa);
    let constraint = len - c.rest[k];
    let dl = (-constraint - alpha * *lambda - gamma * rate) / ((1.0 + gamma) * (wa + wb) + alpha);
    *lambda += dl;
    let (da, db) = ((wa * dl) * n, (wb * dl) * n);
    // SAFETY: as above.
    unsafe {
        *moved.at(a) = Moved {
            predicted: pa - da,
            displacement: dxa - da,
        };
        *moved.at(b) = Moved {
            predicted: pb + db,
            displacement: dxb + db,
        };
    }
}

impl Integrator for Xpbd {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::Xpbd
    }

    fn step(
        &mut self,
        ctx: &mut StepContext<'_>,
        state: &mut ClothState,
        h: f32,
    ) -> Result<StepReport, StepError> {
        let model = ctx.model;
        if !self.built {
            // The compliances come from the current stiffness: rebuilt when forces change.
            self.coloured = ctx.forces.constraints(model).coloured();
            self.built = true;
        }
        let not_springs = |t: &Force| !matches!(t, Force::Springs(_) | Force::BendSprings(_));
        ctx.forces_where(&state.pos, &state.vel, not_springs, &mut self.force);
        let w = &model.inv_mass;
        self.moved.clear();
        let particles = state.pos.iter().zip(state.vel.iter_mut());
        for (((x, v), f), &w) in particles.zip(&self.force).zip(w) {
            if w != 0.0 {
                *v += (*f * w) * h;
            }
            self.moved.push(Moved {
                predicted: *x + *v * h,
                displacement: *v * h,
            });
        }
        self.lambda.clear();
        self.lambda.resize(self.coloured.constraints.len(), 0.0);
        let sweeps = ctx.config.xpbd_iterations;
        ctx.solve(|| {
            for _ in 0..sweeps {
                self.sweep(w, h);
            }
            ((), sweeps, None, true)
        });
        let inv_h = 1.0 / h;
        let particles = state.pos.iter_mut().zip(state.vel.iter_mut());
        let displacements = self.moved.iter().map(|m| &m.displacement);
        for (((x, v), d), &w) in particles.zip(displacements).zip(w) {
            if w != 0.0 {
                *v = *d * inv_h;
                *x += *d;
            }
        }
        state.time += h as f64;
        Ok(ctx.report())
    }

    /// The constraint view keeps nothing about the state; only new strengths make it stale.
    fn forces_changed(&mut self) {
        self.built = false;
    }
}
