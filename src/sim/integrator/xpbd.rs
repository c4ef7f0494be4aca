//! Extended position-based dynamics (XPBD) with small steps.

use std::ops::Range;

use super::super::constraints::Halves;
use super::super::forces::Force;
use super::super::kernels::{Moved, Scaled, project_range, project_range_plain};
use super::context::StepContext;
use super::kind::IntegratorKind;
use super::report::{StepError, StepReport};
use super::step::Integrator;
use crate::cloth::{ClothState, Real};
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
pub struct Xpbd<R: Real = f32> {
    /// The springs as constraints: two halves and their seam, each in colour order.
    halves: Halves,
    built: bool,
    force: Vec<R::V3>,
    /// Per particle, its predicted position, its displacement and its inverse mass side by
    /// side: a projection reads them all, from one 32-byte row.
    moved: Vec<Moved<R>>,
    lambda: Vec<R>,
    scaled: Scaled<R>,
}

impl<R: Real> Xpbd<R> {
    /// One Gauss–Seidel sweep over every constraint: the two halves, each colour by colour,
    /// at the same time on two threads of the [`Team`] when they are large enough; then the
    /// seam's colours, one after another, a large one shared out between the threads.
    /// Constraints that run at the same time share no particle, so the order among them
    /// changes nothing: the same bits on any number of threads.
    fn sweep(&mut self) {
        let (halves, c) = (&self.halves, &self.halves.constraints);
        let s = &self.scaled;
        assert!(self.lambda.len() >= c.len() && s.alpha.len() >= c.len());
        assert!(s.gamma.len() >= c.len() && halves.particles <= self.moved.len());
        // SAFETY (both projections): an independent colour's constraints share no particle
        // or multiplier (a dependent one goes one constraint at a time); what runs at the
        // same time is either the two halves (which share no particle) or the disjoint
        // ranges of one seam colour; the arrays' lengths, and every constraint's particles,
        // were checked above.
        // In `f32` the projection takes its AVX2 lanes; in any other precision, one
        // constraint at a time.
        use std::any::Any;
        let moved = (&mut self.moved as &mut dyn Any).downcast_mut::<Vec<Moved>>();
        let lambda = (&mut self.lambda as &mut dyn Any).downcast_mut::<Vec<f32>>();
        let scaled = (s as &dyn Any).downcast_ref::<Scaled>();
        if let (Some(moved), Some(lambda), Some(s)) = (moved, lambda, scaled) {
            sweep_with(halves, moved, lambda, |range, independent, m, l| unsafe {
                project_range(c, s, range, independent, m, l)
            });
            return;
        }
        sweep_with(
            halves,
            &mut self.moved,
            &mut self.lambda,
            |range, _, m, l| unsafe { project_range_plain(c, s, range, m, l) },
        );
    }
}

/// One sweep over the colours of `halves`: `project(range, independent, moved, lambda)`
/// on each colour's range, the two halves at the same time on two threads where they are
/// large, then the seam's colours, each shared out where it is independent and large.
fn sweep_with<M: Send, L: Send>(
    halves: &Halves,
    moved: &mut [M],
    lambda: &mut [L],
    project: impl Fn(Range<usize>, bool, &Disjoint<'_, M>, &Disjoint<'_, L>) + Sync,
) {
    let Halves {
        constraints: _,
        halves,
        seam,
        particles: _,
    } = halves;
    let team = Team::current();
    let moved = Disjoint::new(moved);
    let lambda = Disjoint::new(lambda);
    let project = |range: Range<usize>, independent: bool| {
        project(range, independent, &moved, &lambda);
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

/// Halves, and seam colours, from this many constraints are shared out between threads.
const PARALLEL_COLOUR: usize = 1024;

impl<R: Real> Integrator<R> for Xpbd<R> {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::Xpbd
    }

    fn step(
        &mut self,
        ctx: &mut StepContext<'_, R>,
        state: &mut ClothState<R>,
        h: R,
    ) -> Result<StepReport, StepError> {
        let model = ctx.model;
        if !self.built {
            // The compliances come from the current stiffness: rebuilt when forces change.
            let pos: Vec<glam::Vec3> = state.pos.iter().map(|p| R::v3_f32(*p)).collect();
            self.halves = ctx.forces.constraints(model).halves(&pos);
            self.scaled.h = None;
            self.built = true;
        }
        let not_springs = |t: &Force<R>| t.springs().is_none();
        ctx.forces_where(&state.pos, &state.vel, not_springs, &mut self.force);
        let w = &model.inv_mass;
        self.moved.clear();
        let particles = state.pos.iter().zip(state.vel.iter_mut());
        for (((x, v), f), &w) in particles.zip(&self.force).zip(w) {
            if w != 0.0 {
                *v += (*f * R::of_f32(w)) * h;
            }
            self.moved.push(Moved {
                predicted: *x + *v * h,
                displacement: *v * h,
                inv_mass: R::of_f32(w),
                pad: R::ZERO,
            });
        }
        self.lambda.clear();
        self.lambda.resize(self.halves.constraints.len(), R::ZERO);
        self.scaled.update(&self.halves.constraints, h);
        let sweeps = ctx.config.xpbd_iterations;
        ctx.solve(|| {
            for _ in 0..sweeps {
                self.sweep();
            }
            ((), sweeps, None, true)
        });
        let inv_h = R::ONE / h;
        let particles = state.pos.iter_mut().zip(state.vel.iter_mut());
        let displacements = self.moved.iter().map(|m| &m.displacement);
        for (((x, v), d), &w) in particles.zip(displacements).zip(w) {
            if w != 0.0 {
                *v = *d * inv_h;
                *x += *d;
            }
        }
        state.time += h.to_f64();
        Ok(ctx.report())
    }

    /// The constraint view keeps nothing about the state; only new strengths make it stale.
    fn forces_changed(&mut self) {
        self.built = false;
    }
}
