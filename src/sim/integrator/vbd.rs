//! Vertex block descent (VBD; Chen, Macklin, Kim et al., SIGGRAPH 2024).

use super::context::StepContext;
use super::kind::IntegratorKind;
use super::report::{StepError, StepReport};
use super::step::Integrator;
use crate::cloth::{ClothState, Real, Vector};
use crate::parallel::{Disjoint, Team};
use crate::sim::forces::Force;
use crate::sim::kernels::{Particle, Stencil, StepLength, descend_range, descend_range_plain};

/// Backward Euler's step written as a minimisation, solved one particle at a time.
///
/// Each substep moves every particle by the displacement `d` that minimises
/// `G(d) = Σᵢ ½ mᵢ |dᵢ − ŷᵢ|² + h²·E(x + d)`, with `ŷᵢ = h·vᵢ + h²·fᵢ/mᵢ` the inertial
/// prediction (`f`: every force but the springs, at the start of the step: gravity, air
/// damping, wind, bending, as XPBD takes them) and `E` the springs' energy; the springs'
/// dashpots act on the new velocity `d/h` (Rayleigh-free, as implicit Euler's do). Its
/// minimum is implicit Euler's step for the springs. The descent starts from each
/// particle's last acceleration, capped at the external one's size, and makes
/// `vbd_iterations` sweeps; in each, a particle takes one Newton step on `G` with the others
/// held: `Hᵢ·Δdᵢ = −∇ᵢG`, where `Hᵢ = mᵢ·I + Σ (h²·(k·n nᵀ + k·max(0, 1 − L/l)·(I − n nᵀ))
/// + h·c·n nᵀ)` over its springs is the 3 × 3 block of the Hessian kept positive definite (a
/// compressed spring's negative transverse term left out). Particles are visited colour by
/// colour ([`Stencil`]): no two of a colour share a spring, so a colour's particles move at
/// the same time on the team's threads, and the result does not depend on how many there
/// are. Finally `v = d/h`, `x += d`.
///
/// At one sweep it is one Gauss–Seidel Newton iteration; as the sweeps grow it converges to
/// the implicit step (each sweep of two particles on a spring shrinks the distance to it by
/// about `(h²k/(m + h²k))²`). First order in the step. Stable far past the explicit methods'
/// limits (at a hundred times the default stiffness, where they all blow up), though not at
/// every step: an unconverged sweep can add energy, and with one sweep on a stiff cloth the
/// largest steps gain it (`clothsim accuracy --map`).
///
/// The displacement is kept as such, not recovered as a difference of two positions (see
/// [`super::Xpbd`] for why that matters in f32 at small steps).
#[derive(Default)]
pub struct Vbd<R: Real = f32> {
    /// Built from the springs' strengths at the first step after they change.
    stencil: Option<Stencil>,
    force: Vec<R::V3>,
    /// The inertial displacement `ŷ` per particle, metres.
    inertial: Vec<R::V3>,
    /// Per particle its start position, its displacement `d` this step (metres) and its
    /// masses, side by side: the descent reads them from one 32-byte row.
    particles: Vec<Particle<R>>,
    /// The velocities before the last step and its length, from which the next step's
    /// first guess takes each particle's last acceleration; `None` when the state changed
    /// outside since (or there was no step yet).
    previous: Option<(Vec<R::V3>, R)>,
}

/// Colours from this many particles are shared out between the team's threads.
const PARALLEL_COLOUR: usize = 1024;
/// Particles per piece of a colour (a multiple of the groups of eight).
const PIECE: usize = 256;
/// Particles per piece of the step's start and end.
const SETUP_PIECE: usize = 2048;

impl<R: Real> Vbd<R> {
    /// The descent's starting point: `d = h·v + h²·ã`, where `ã` is the particle's
    /// acceleration over its last step, `a_last`, scaled down to the size of the external
    /// acceleration `a = f/m` where it is larger: a cloth hanging at rest starts where it is
    /// (its weight held by the springs), a falling one where it falls to, and a swinging
    /// one where its swing takes it. With no last step, `ã = a` (the inertial prediction).
    /// Pinned particles stay.
    ///
    /// Chen et al.'s adaptive start keeps only `a_last`'s part along `a`, clamped to
    /// `[0, |a|]`. One sweep a substep from there lets the bench cloth fall too far at first
    /// (2.3× the reference's sag at 0.17 s, N = 128) and leaves a slow swing that has not
    /// died down at 2 s (the sag then 7–10 % off for most substep counts). The whole
    /// `a_last`, uncapped, follows the reference's swing but feeds the solve's own error
    /// back until the cloth blows up (at 1.1 s). Capped, it follows the swing, and at N/2
    /// substeps of one sweep the sag at 2 s is within 2.5 % of the reference's from N = 32
    /// to 256 (docs/performance.md).
    fn first_guess(&self, v: R::V3, f: R::V3, w: f32, p: usize, h: R) -> R::V3 {
        if w == 0.0 {
            return R::V3::ZERO;
        }
        let a = f * R::of_f32(w);
        let taken = match &self.previous {
            Some((last, last_h)) if p < last.len() => {
                let a_last = (v - last[p]) / *last_h;
                let (size, most) = (a_last.length(), a.length());
                if size > most {
                    a_last * (most / size)
                } else {
                    a_last
                }
            }
            _ => a,
        };
        (v + taken * h) * h
    }

    /// One sweep: every free particle, colour by colour, takes its Newton step; a large
    /// colour in pieces shared between the team's threads.
    fn sweep(&mut self, stencil: &Stencil, h: R) {
        let inertial = &self.inertial;
        let n = self.particles.len();
        assert!(stencil.spans.len() == n && inertial.len() == n);
        // In `f32` the descent takes its AVX2 lanes; in any other precision, one particle
        // at a time.
        let rows = (&mut self.particles as &mut dyn std::any::Any).downcast_mut::<Vec<Particle>>();
        if let (Some(rows), Some(inertial)) = (rows, R::f32_slice(inertial)) {
            // `h` is an `f32` here: the conversion is exact.
            let step = StepLength::new(h.to_f32());
            // SAFETY: as below.
            by_colour(stencil, rows, |particles, range| unsafe {
                descend_range(stencil, particles, inertial, range, step, true)
            });
            return;
        }
        let step = StepLength::new(h);
        // SAFETY: a colour's particles share no spring, so while a piece moves its
        // particles no other thread writes them or any particle they read; the stencil was
        // built for these particles (lengths checked above).
        by_colour(stencil, &mut self.particles, |particles, range| unsafe {
            descend_range_plain(stencil, particles, inertial, range, step)
        });
    }
}

/// `work(range)` over `0..n` in pieces, shared between the team's members from
/// [`PARALLEL_COLOUR`] particles on: per-particle work whose result does not depend on who
/// does a piece (the step's start and its end).
fn by_piece(n: usize, work: &(dyn Fn(std::ops::Range<usize>) + Sync)) {
    let pieces = n.div_ceil(SETUP_PIECE);
    Team::current().run_pieces_if(n >= PARALLEL_COLOUR, pieces, &|_, piece| {
        let start = piece * SETUP_PIECE;
        work(start..(start + SETUP_PIECE).min(n));
    });
}

/// `descend(particles, range)` over every colour of `stencil` in order, each colour in
/// pieces that the team's members take as they come where the colour is large.
fn by_colour<P: Send>(
    stencil: &Stencil,
    particles: &mut [P],
    descend: impl Fn(&Disjoint<'_, P>, std::ops::Range<usize>) + Sync,
) {
    let particles = Disjoint::new(particles);
    let team = Team::current();
    for colour in &stencil.colours {
        let pieces = colour.len().div_ceil(PIECE);
        let parallel = colour.len() >= PARALLEL_COLOUR;
        team.run_pieces_if(parallel, pieces, &|_, piece| {
            let start = colour.start + piece * PIECE;
            let range = start..(start + PIECE).min(colour.end);
            descend(&particles, range);
        });
    }
}

impl<R: Real> Integrator<R> for Vbd<R> {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::Vbd
    }

    fn step(
        &mut self,
        ctx: &mut StepContext<'_, R>,
        state: &mut ClothState<R>,
        h: R,
    ) -> Result<StepReport, StepError> {
        let model = ctx.model;
        let n = model.particle_count();
        let stencil = match self.stencil.take() {
            Some(s) if s.spans.len() == n => s,
            _ => Stencil::new(&ctx.forces.constraints(model), n),
        };
        let not_springs = |t: &Force<R>| t.springs().is_none();
        ctx.forces_where(&state.pos, &state.vel, not_springs, &mut self.force);
        let (mut inertial, mut rows) = (
            std::mem::take(&mut self.inertial),
            std::mem::take(&mut self.particles),
        );
        inertial.resize(n, R::V3::ZERO);
        rows.resize(n, Particle::default());
        {
            let (pos, vel, force) = (&state.pos, &state.vel, &self.force);
            let (w, mass) = (&model.inv_mass, &model.mass);
            let (inertial, rows) = (Disjoint::new(&mut inertial), Disjoint::new(&mut rows));
            by_piece(n, &|range| {
                // SAFETY: the pieces' ranges do not overlap.
                let (inertial, rows) =
                    unsafe { (inertial.part(range.clone()), rows.part(range.clone())) };
                for ((p, y), row) in range.zip(inertial).zip(rows) {
                    let (v, f) = (vel[p], force[p]);
                    *y = (v + f * R::of_f32(w[p]) * h) * h;
                    *row = Particle {
                        pos: pos[p],
                        disp: self.first_guess(v, f, w[p], p, h),
                        inv_mass: R::of_f32(w[p]),
                        mass: R::of_f32(mass[p]),
                    };
                }
            });
        }
        (self.inertial, self.particles) = (inertial, rows);
        let sweeps = ctx.config.vbd_iterations;
        ctx.solve(|| {
            for _ in 0..sweeps {
                self.sweep(&stencil, h);
            }
            ((), sweeps, None, true)
        });
        self.stencil = Some(stencil);
        if !self.particles.iter().all(|p| p.disp.is_finite()) {
            return Err(StepError::NonFinite { iterations: sweeps });
        }
        let mut previous = self.previous.take().map(|p| p.0).unwrap_or_default();
        previous.clone_from(&state.vel);
        self.previous = Some((previous, h));
        let inv_h = R::ONE / h;
        let (pos, vel) = (Disjoint::new(&mut state.pos), Disjoint::new(&mut state.vel));
        let particles = &self.particles;
        by_piece(n, &|range| {
            // SAFETY: the pieces' ranges do not overlap.
            let (pos, vel) = unsafe { (pos.part(range.clone()), vel.part(range.clone())) };
            for ((x, v), row) in pos.iter_mut().zip(vel).zip(&particles[range]) {
                if row.inv_mass != R::ZERO {
                    *v = row.disp * inv_h;
                    *x += row.disp;
                }
            }
        });
        state.time += h.to_f64();
        Ok(ctx.report())
    }

    fn invalidate(&mut self) {
        self.previous = None;
    }

    /// Keeps the last velocities: what contacts did to a particle is part of the change of
    /// velocity its next first guess reads, and a collider's push (against the external
    /// acceleration) clamps to nothing there, so a particle resting on a collider starts
    /// where it rests. Forgetting them would start every particle of a cloth that touches
    /// anything from the inertial guess, below the surface it rests on.
    fn contacts_moved(&mut self) {}

    /// The stencil keeps the springs' strengths: new strengths make it stale.
    fn forces_changed(&mut self) {
        self.stencil = None;
        self.invalidate();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU32, Ordering};

    /// The step's start and end reach every particle once, on one thread and on two, for
    /// cloths below, at and past a piece's size and the size from which pieces are shared.
    #[test]
    fn by_piece_visits_every_particle_once() {
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a pool");
            for n in [
                0,
                1,
                1023,
                1024,
                SETUP_PIECE,
                SETUP_PIECE + 1,
                5 * SETUP_PIECE - 7,
            ] {
                let visits: Vec<AtomicU32> = (0..n).map(|_| AtomicU32::new(0)).collect();
                pool.install(|| {
                    by_piece(n, &|range| {
                        for p in range {
                            visits[p].fetch_add(1, Ordering::Relaxed);
                        }
                    })
                });
                let counts: Vec<u32> = visits.iter().map(|v| v.load(Ordering::Relaxed)).collect();
                assert!(
                    counts.iter().all(|&c| c == 1),
                    "{threads} threads, {n} particles"
                );
            }
        }
    }
}
