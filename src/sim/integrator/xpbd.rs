//! Extended position-based dynamics (XPBD) with small steps.

use std::ops::Range;

use glam::Vec3;

use super::super::constraints::Halves;
use super::super::forces::Force;
use super::super::kernels::{Moved, Scaled, project_range};
use super::context::StepContext;
use super::kind::IntegratorKind;
use super::report::{StepError, StepReport};
use super::step::Integrator;
use crate::cloth::ClothState;
use crate::parallel::{Disjoint, Team, share};

/// Each substep: the forces that are not springs (gravity, air damping, …) move the
/// particles explicitly to a prediction; then every spring, seen as a distance constraint
/// with compliance `α = 1/k`, is projected in `xpbd_iterations` Gauss–Seidel sweeps with its
/// Lagrange multiplier (XPBD), visited half by half and then across the seam, colour by
/// colour ([`DistanceConstraints::halves`](crate::sim::DistanceConstraints::halves)), and its dashpot `c` as constraint damping
/// `γ = α·c/h`; finally `v = (x' − x)/h`. With many small substeps and one sweep this is the
/// "small steps" method: stable at any stiffness, and as `α → 0` it approaches inextensible
/// springs.
///
/// The step's displacement `x' − x` is kept beside the predicted positions and updated with
/// them: recovering it as a difference of two nearly equal f32 positions would lose most of
/// its digits at small steps (a 1 m/s particle moves 0.2 mm in a 0.2 ms step, a thousand
/// rounding units of a coordinate near 1 m), and that noise grows as the step shrinks.
#[derive(Default)]
pub struct Xpbd {
    /// The springs as constraints: two halves and their seam, each in colour order.
    halves: Halves,
    built: bool,
    force: Vec<Vec3>,
    /// Per particle, its predicted position, its displacement and its inverse mass side by
    /// side: a projection reads them all, from one 32-byte row.
    moved: Vec<Moved>,
    lambda: Vec<f32>,
    scaled: Scaled,
}

impl Xpbd {
    /// One Gauss–Seidel sweep over every constraint: the two halves, each colour by colour,
    /// at the same time on two threads of the [`Team`] when they are large enough; then the
    /// seam's colours, one after another, a large one shared out between the threads.
    /// Constraints that run at the same time share no particle, so the order among them
    /// changes nothing: the same bits on any number of threads.
    fn sweep(&mut self) {
        let Halves {
            constraints: c,
            halves,
            seam,
            particles,
        } = &self.halves;
        let s = &self.scaled;
        assert!(self.lambda.len() >= c.len() && s.alpha.len() >= c.len());
        assert!(s.gamma.len() >= c.len() && *particles <= self.moved.len());
        let team = Team::current();
        let moved = Disjoint::new(&mut self.moved);
        let lambda = Disjoint::new(&mut self.lambda);
        let project = |range: Range<usize>, independent: bool| {
            // SAFETY: an independent colour's constraints share no particle or multiplier
            // (a dependent one goes one constraint at a time); what runs at the same time is
            // either the two halves (which share no particle) or the disjoint ranges of one
            // seam colour; the arrays' lengths, and every constraint's particles, were
            // checked above.
            unsafe { project_range(c, s, range, independent, &moved, &lambda) };
        };
        let colours = |colours: &[(Range<usize>, bool)]| {
            for (range, independent) in colours {
                project(range.clone(), *independent);
            }
        };
        let half_len = |h: &[(Range<usize>, bool)]| h.iter().map(|c| c.0.len()).sum::<usize>();
        if team.members() > 1 && halves.iter().all(|h| half_len(h) >= PARALLEL_COLOUR) {
            team.run(&|i| share(2, team.members(), i).for_each(|h| colours(&halves[h])));
        } else {
            halves.iter().for_each(|h| colours(h));
        }
        for (range, independent) in seam {
            if *independent && team.members() > 1 && range.len() >= PARALLEL_COLOUR {
                team.run(&|i| {
                    let share = share(range.len(), team.members(), i);
                    project(range.start + share.start..range.start + share.end, true);
                });
            } else {
                project(range.clone(), *independent);
            }
        }
    }
}

/// Halves, and seam colours, from this many constraints are shared out between threads.
const PARALLEL_COLOUR: usize = 1024;

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
            self.halves = ctx.forces.constraints(model).halves(&state.pos);
            self.scaled.h = None;
            self.built = true;
        }
        let not_springs = |t: &Force| t.springs().is_none();
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
                inv_mass: w,
                pad: 0.0,
            });
        }
        self.lambda.clear();
        self.lambda.resize(self.halves.constraints.len(), 0.0);
        self.scaled.update(&self.halves.constraints, h);
        let sweeps = ctx.config.xpbd_iterations;
        ctx.solve(|| {
            for _ in 0..sweeps {
                self.sweep();
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
