//! The CPU step backend: an integrator, the scene's forces and its contacts, advanced in
//! fixed substeps, with a guard that rolls back a diverging frame and retries it with more
//! substeps. It charges the time of every step to phases.

use std::time::{Duration, Instant};

use crate::cloth::{ClothModel, ClothState, Real};

use super::backend::StepBackend;
use super::diagnosis::Cause;
use super::effects::{
    Between, ContactPass, Effect, FacePatches, Reach, SelfCollision, air_damping_of, gravity_of,
    shortest_edge,
};
use super::forces::ForceSet;
use super::guard::{Diverged, FrameOutcome, GuardEvent, GuardLimits, Trouble, check};
use super::guard_state::{CpuSnapshot, GuardState};
use super::integrator::{
    Integrator, IntegratorKind, StepContext, StepError, StepMeter, StepReport,
};
use super::kernels::{take_changes, take_moves};
use super::params::{Changes, SimParams, SolverConfig};
use super::precise_state::{PreciseState, as_f32, f32_view};
use super::precision::Precision;
use super::self_contacts::{SelfContacts, SelfWork};
use super::stats::StepStats;
use super::timings::PhaseTimings;

mod rescue;

/// Rounds of solids then the self-contact check after self-contact, at most: another
/// round only follows one whose check had to cut.
const RECHECKS: usize = 3;

/// The phase that times the copy of each substep's start positions, from which every
/// contact's paths run (taken before the integrator's step, where there are contacts).
pub const CONTACT_START: &str = "contact-start";

/// The phase that times the settling of particles left between two solids ([`Between`]).
pub const BETWEEN_SOLIDS: &str = "between-solids";

/// Settles the particles left between two of the solids among `effects` ([`Between`]),
/// timed as [`BETWEEN_SOLIDS`]; nothing (and no phase) where fewer than two act. Returns
/// how many it moved.
fn settle_between(
    timings: &mut PhaseTimings,
    between: &mut Between,
    effects: &[Effect],
    pass: &mut ContactPass<'_>,
) -> usize {
    if effects.iter().filter(|e| e.is_solid()).nth(1).is_none() {
        return 0;
    }
    timings.time(BETWEEN_SOLIDS, || between.keep(effects, pass))
}

/// Runs `work`, adding its wall time to `spent`.
fn timed<T>(spent: &mut Duration, work: impl FnOnce() -> T) -> T {
    let start = Instant::now();
    let out = work();
    *spent += start.elapsed();
    out
}

/// Advances a cloth on the CPU, its forces and integrator computing in precision `R`
/// (`f32`, or `f64` on a state of its own whose rounding the caller sees). Built from a
/// scene's effect list: absent effects are not in it and cost nothing.
pub struct CpuStepper<R: Real = f32> {
    integrator: Box<dyn Integrator<R>>,
    /// The integrator the parameters ask for (the guard may have fallen back from it).
    asked: IntegratorKind,
    forces: ForceSet<R>,
    /// The effects that act after each substep: solids in the scene's order, then
    /// self-collision.
    contacts: Vec<Effect>,
    /// The scene's effects, for the guard's limits, each mesh obstacle as this cloth meets
    /// it.
    effects: Vec<Effect>,
    /// What the mesh obstacles were fitted to.
    reach: Reach,
    solver: SolverConfig,
    gravity: glam::Vec3,
    dt: f32,
    /// Substeps per frame the parameters ask for.
    requested: u32,
    /// Substeps per frame in effect (the guard may have raised them).
    substeps: u32,
    offset: f32,
    guard: GuardState<CpuSnapshot<R>>,
    timings: PhaseTimings,
    stats: StepStats,
    meter: StepMeter,
    /// The frame's start, restored when nothing saves a frame.
    frame_start: CpuSnapshot<R>,
    /// Positions at the start of the current substep: the paths colliders sweep.
    substep_start: Vec<glam::Vec3>,
    /// A pinned particle moved outside the substeps before the frame being stepped, and
    /// where from ([`StepBackend::moved_outside`]): each try's first substep starts it there.
    /// (A grab invalidates the stepper, which drops the guard's rollback points: a try
    /// after a move starts at the frame's start, never at an earlier frame.)
    outside: Option<(u32, glam::Vec3)>,
    self_collision: Option<SelfCollision>,
    self_contacts: SelfContacts,
    /// Positions before the solids act (first, and again after self-contact), and before
    /// self-contact: what they, or it, moved is what changed since.
    before_solids: Vec<glam::Vec3>,
    /// The cloth's triangles in patches, for the solids' face passes.
    faces: FacePatches,
    /// Where two solids' offsets overlap (their boxes, reused).
    between: Between,
    /// Air damping in effect, 1/s (0 without the effect; for the guard's diagnosis).
    air_damping: f32,
    /// The state stepped, in a precision other than `f32`.
    precise: PreciseState<R>,
    /// The state rounded to `f32`, for the guard and the contacts, in a precision other
    /// than `f32`.
    view: ClothState,
}

/// The CPU stepper for `effects` with `params`, in the precision they ask for.
pub fn cpu_backend(
    model: &ClothModel,
    params: &SimParams,
    effects: &[Effect],
) -> Box<dyn StepBackend> {
    match params.solver.precision {
        Precision::F32 => Box::new(CpuStepper::<f32>::build(model, params, effects)),
        Precision::F64 => Box::new(CpuStepper::<f64>::build(model, params, effects)),
    }
}

impl CpuStepper {
    /// A stepper in `f32` for `effects` with the strengths in `params` (whatever precision
    /// they ask for: [`cpu_backend`] heeds it).
    pub fn new(model: &ClothModel, params: &SimParams, effects: &[Effect]) -> Self {
        Self::build(model, params, effects)
    }
}

impl<R: Real> CpuStepper<R> {
    /// A stepper in precision `R` for `effects` with the strengths in `params`.
    pub fn build(model: &ClothModel, params: &SimParams, effects: &[Effect]) -> Self {
        let mut stepper = Self {
            integrator: params.step.integrator.build(),
            asked: params.step.integrator,
            forces: ForceSet::default(),
            contacts: Vec::new(),
            effects: Vec::new(),
            reach: Reach::default(),
            solver: params.solver,
            gravity: glam::Vec3::ZERO,
            dt: params.step.dt,
            requested: 0,
            substeps: 1,
            offset: params.contact.offset,
            guard: GuardState::new(params.guard.clone()),
            timings: PhaseTimings::default(),
            stats: StepStats::default(),
            meter: StepMeter::default(),
            frame_start: CpuSnapshot::default(),
            substep_start: Vec::new(),
            outside: None,
            self_collision: None,
            self_contacts: SelfContacts::default(),
            before_solids: Vec::new(),
            faces: FacePatches::default(),
            between: Between::default(),
            air_damping: 0.0,
            precise: PreciseState::default(),
            view: ClothState::default(),
        };
        stepper.configure(model, params, effects, Changes::all());
        stepper
    }

    /// Whether anything acts on the state after each substep (solids, self-collision).
    fn contacts_exist(&self) -> bool {
        !self.contacts.is_empty()
    }

    /// Integrates one substep and charges its phases; the contacts are not resolved (see
    /// [`CpuStepper::resolve_contacts`]).
    fn advance(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState<R>,
    ) -> Result<StepReport, StepError> {
        let h = self.step_length();
        if self.contacts_exist() {
            let start = &mut self.substep_start;
            self.timings.time(CONTACT_START, || {
                start.clear();
                match R::f32_slice(&state.pos) {
                    Some(pos) => start.extend_from_slice(pos),
                    None => start.extend(state.pos.iter().map(|p| R::v3_f32(*p))),
                }
            });
        }
        self.forces.set_time(state.time);
        let report = self.integrate_with(model, state, |integrator, ctx, state| {
            integrator.step(ctx, state, h)
        })?;
        self.stats.record(&report);
        Ok(report)
    }

    /// Resolves the contacts (solids, then self-collision) after a substep, from the paths since its
    /// start, and charges their phases. `strain_limit`: the guard's, where it judges the
    /// substep (self-contact then refuses a state past it: [`SelfContacts::strain_limit`]).
    ///
    /// # Errors
    /// [`StepError::Contact`] when self-collision refuses a state that has blown up.
    fn resolve_contacts(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState<R>,
        strain_limit: Option<f32>,
    ) -> Result<(), StepError> {
        if !self.contacts_exist() {
            return Ok(());
        }
        self.self_contacts.strain_limit = strain_limit;
        let mut view = std::mem::take(&mut self.view);
        let resolved = as_f32(state, &mut view, |state| {
            self.resolve_contacts_f32(model, state)
        });
        self.view = view;
        resolved
    }

    /// [`CpuStepper::resolve_contacts`] on the state in `f32`.
    fn resolve_contacts_f32(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
    ) -> Result<(), StepError> {
        // A cloth stretched past what the mesh obstacles were fitted to has them fitted
        // again, before any contact meets it.
        if let Some(fitted) = self.reach.outgrown(&self.effects, &state.pos) {
            self.take_effects(fitted);
        }
        let mut contacts = 0;
        let mut pass = ContactPass {
            model,
            start: &self.substep_start,
            substep: self.substep_length(),
            state,
            offset: self.offset,
            self_contacts: &mut self.self_contacts,
            faces: Some(&mut self.faces),
        };
        // Self-contact's upkeep between the effects, timed as a phase of its own.
        let mut upkeep = Duration::ZERO;
        if self.self_collision.is_some() {
            timed(&mut upkeep, || {
                self.before_solids.clone_from(&pass.state.pos)
            });
        }
        // Where two solids' offsets overlap, what the last left inside another is settled
        // once every solid has acted: before self-contact (it comes last), or after them.
        let mut settled = false;
        for c in &self.contacts {
            if matches!(c, Effect::SelfCollision(_)) {
                let (timings, between) = (&mut self.timings, &mut self.between);
                contacts += settle_between(timings, between, &self.contacts, &mut pass);
                settled = true;
                // What the solids moved rests on them; self-contact starts from where they
                // left the cloth (it comes last).
                let held = &mut pass.self_contacts.held;
                timed(&mut upkeep, || {
                    take_moves(&mut self.before_solids, &pass.state.pos, held)
                });
            }
            contacts += self.timings.time(c.phase(), || c.resolve(&mut pass))?;
        }
        if !settled {
            let (timings, between) = (&mut self.timings, &mut self.between);
            contacts += settle_between(timings, between, &self.contacts, &mut pass);
        }
        // Self-contact may have pushed cloth into a solid (a stack pressing its lowest
        // layer): where it moved anything, the solids act once more, and the cloth's
        // motion since self-contact is checked again, cut where a pair of the cloth could
        // meet.
        if let Some(own) = self.self_collision
            && self.contacts.len() > 1
            && timed(&mut upkeep, || {
                take_changes(&mut self.before_solids, &pass.state.pos)
            })
        {
            for _ in 0..RECHECKS {
                for c in self.contacts.iter().filter(|c| c.is_solid()) {
                    contacts += self.timings.time(c.phase(), || c.resolve(&mut pass))?;
                }
                let (timings, between) = (&mut self.timings, &mut self.between);
                contacts += settle_between(timings, between, &self.contacts, &mut pass);
                // Nothing moved since self-contact: nothing to check.
                if !timed(&mut upkeep, || self.before_solids != pass.state.pos) {
                    break;
                }
                let placed = &self.before_solids;
                let settle = || {
                    let motion = [pass.start, &placed[..]];
                    (pass.self_contacts).settle(own.thickness, model, motion, pass.state)
                };
                if self.timings.time(super::SELF_RECHECK, settle)? == 0 {
                    break;
                }
                // The next round starts from where the check left the cloth.
                timed(&mut upkeep, || {
                    take_changes(&mut self.before_solids, &pass.state.pos)
                });
            }
        }
        if self.self_collision.is_some() {
            self.timings.add(super::SELF_UPKEEP, upkeep);
        }
        if contacts > 0 {
            // Contacts changed positions and velocities after the integrator's step.
            self.integrator.contacts_moved();
        }
        Ok(())
    }

    /// Takes `effects` (each mesh obstacle fitted to the cloth) as the scene's, their
    /// contacts as the ones that act after each substep.
    fn take_effects(&mut self, effects: Vec<Effect>) {
        self.contacts = effects.iter().filter(|e| e.is_contact()).cloned().collect();
        // Self-collision last, after the solids have moved what they touch.
        self.contacts
            .sort_by_key(|e| matches!(e, Effect::SelfCollision(_)));
        self.effects = effects;
    }

    /// The likely cause of a frame that failed from positions `pos` at up to `tried`
    /// substeps per frame, and with `fallback` where the guard tried it: a self-collision
    /// thickness the cloth cannot take, an explicit integrator past its stable step, or
    /// else the stiffness.
    fn diagnose(
        &self,
        model: &ClothModel,
        pos: &[glam::Vec3],
        (tried, fallback): (u32, Option<IntegratorKind>),
    ) -> Cause {
        if let Some(s) = &self.self_collision
            && let Err(too_thick) = s.fits(shortest_edge(model))
        {
            return Cause::Thickness(too_thick);
        }
        let kind = self.integrator.kind();
        let forces = &self.forces;
        let substeps = Cause::substeps(kind, model, forces, pos, self.air_damping, self.dt, tried);
        Cause::of_springs(substeps, kind, fallback)
    }

    /// Runs `steps` (the integrator's work) on `state` and charges its phases.
    fn integrate_with<T>(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState<R>,
        steps: impl FnOnce(&mut dyn Integrator<R>, &mut StepContext<'_, R>, &mut ClothState<R>) -> T,
    ) -> T {
        let start = Instant::now();
        let result = {
            let mut ctx = StepContext::new(model, &self.forces, &self.solver, &mut self.meter);
            steps(self.integrator.as_mut(), &mut ctx, state)
        };
        let total = start.elapsed();
        let m = &self.meter;
        for &(name, took, calls) in &m.terms.entries {
            if calls > 0 {
                self.timings.add_calls(name, took, calls as u64);
            }
        }
        if m.derivatives > Duration::ZERO {
            self.timings.add("jacobian", m.derivatives);
        }
        if m.solve > Duration::ZERO {
            self.timings.add("solve", m.solve);
        }
        self.timings
            .add("integrate", total.saturating_sub(m.forces + m.solve));
        result
    }

    /// A frame's substeps: taken together where the integrator has a way to
    /// ([`Integrator::steps`]) and nothing acts between them (no contacts), else one by one.
    /// One by one, each substep is `checked` against the guard's limits before contacts read
    /// its positions: a state that blew up within the frame reaches the guard at once,
    /// never contact detection.
    fn frame_substeps(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState<R>,
        checked: bool,
    ) -> Result<(), Trouble> {
        let count = self.substeps;
        if count > 1 && !self.contacts_exist() {
            let h = self.step_length();
            self.forces.set_time(state.time);
            let together = self.integrate_with(model, state, |integrator, ctx, state| {
                integrator.steps(ctx, state, h, count)
            });
            if let Some(report) = together {
                self.stats.record_steps(&report?, count);
                return Ok(());
            }
        }
        let limits = self.guard.limits.filter(|_| checked);
        let depth = limits.map_or(0.0, |l| l.depth_of(f32_view(state, &mut self.view)));
        for k in 0..count {
            self.advance(model, state)?;
            if let Some(l) = limits
                && let Some(trouble) =
                    l.check_substep(model, f32_view(state, &mut self.view), depth)
            {
                return Err(trouble);
            }
            if k == 0 {
                self.start_outside();
            }
            self.resolve_contacts(model, state, limits.map(|l| l.strain))?;
        }
        Ok(())
    }

    /// Starts the particle moved outside the substeps where it was moved from, in the
    /// substep's start positions the contacts' paths run from (it is pinned: the step left
    /// it where the move put it).
    fn start_outside(&mut self) {
        if let Some((p, from)) = self.outside
            && let Some(start) = self.substep_start.get_mut(p as usize)
        {
            *start = from;
        }
    }

    /// One frame at the substeps in effect, ending exactly at `end` (seconds); checked
    /// against the guard's limits.
    fn try_frame(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState<R>,
        end: f64,
    ) -> Result<(), Trouble> {
        self.frame_substeps(model, state, true)?;
        // Whole frames end on the frame clock, however the substeps' lengths rounded.
        state.time = end;
        let limits = self.guard.limits.as_ref().ok_or(Trouble::NonFinite)?;
        match check(model, f32_view(state, &mut self.view), limits) {
            Some(trouble) => Err(trouble),
            None => Ok(()),
        }
    }
}

impl<R: Real> CpuStepper<R> {
    /// The substep's length in the stepper's precision, seconds.
    fn step_length(&self) -> R {
        R::of_f32(self.dt) / R::of_f32(self.substeps as f32)
    }

    /// Runs `f` on the state this stepper steps: `state` itself in `f32`; else its own,
    /// taken from `state` when that changed and rounded into it afterwards.
    fn on_state<T>(
        &mut self,
        state: &mut ClothState,
        f: impl FnOnce(&mut Self, &mut ClothState<R>) -> T,
    ) -> T {
        if let Some(same) = (state as &mut dyn std::any::Any).downcast_mut::<ClothState<R>>() {
            return f(self, same);
        }
        let mut precise = std::mem::take(&mut self.precise);
        precise.load(state);
        let out = f(self, &mut precise.state);
        precise.store(state);
        self.precise = precise;
        out
    }

    /// One frame under the guard, on the state stepped (see [`StepBackend::frame`]).
    fn guarded_frame(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState<R>,
    ) -> Result<FrameOutcome, Diverged> {
        let end = state.time + self.dt as f64;
        if !self.guard.policy.enabled {
            // With the guard off a failed step is all there is to report.
            self.frame_start.state.clone_from(state);
            if let Err(trouble) = self.frame_substeps(model, state, false) {
                let pos = f32_view(&self.frame_start.state, &mut self.view)
                    .pos
                    .clone();
                return Err(Diverged {
                    time: state.time,
                    reason: trouble.to_string(),
                    substeps: self.substeps,
                    fallback: String::new(),
                    cause: self.diagnose(model, &pos, (self.substeps, None)),
                });
            }
            state.time = end;
            return Ok(FrameOutcome::Stepped);
        }
        if self.guard.limits.is_none() {
            self.guard.limits = Some(GuardLimits::derive(
                &self.guard.policy,
                model,
                (f32_view(state, &mut self.view), &state.pos),
                self.gravity,
                &self.forces,
                &self.effects,
            ));
        }
        self.frame_start.state.clone_from(state);
        self.frame_start.forced = self.self_contacts.work.forced_total;
        match self.try_frame(model, state, end) {
            Ok(()) => {
                self.frame_stood();
                Ok(self.maybe_recover(end).unwrap_or(FrameOutcome::Stepped))
            }
            Err(trouble) => self.rescue(model, state, end, trouble),
        }
    }
}

impl<R: Real> StepBackend for CpuStepper<R> {
    fn name(&self) -> &'static str {
        "cpu"
    }

    fn configure(
        &mut self,
        model: &ClothModel,
        params: &SimParams,
        effects: &[Effect],
        changes: Changes,
    ) {
        if changes.is_empty() {
            return;
        }
        let forces_changed = (self.forces).apply(model, &params.material, effects, changes);
        if changes.intersects(Changes::EFFECTS | Changes::CONTACT) {
            // Each mesh obstacle as this cloth meets it: what its edges and triangles can
            // reach between their particles.
            let fitted = self.reach.fit(effects, model, params.contact.offset);
            self.take_effects(fitted);
        }
        if changes.contains(Changes::EFFECTS) {
            self.self_collision = effects.iter().find_map(|e| match e {
                Effect::SelfCollision(s) => Some(*s),
                _ => None,
            });
            // The patches the solids' face passes take (a sphere's, and a mesh obstacle's
            // of its tips), cut now for a cloth among solids, with self-contact's setup
            // where it runs: built now, not in the first substep, and timed as its own
            // phase where either was built (not where they were this cloth's already). A
            // cloth too large for self-contact is refused by the first substep, with its
            // error.
            let start = std::time::Instant::now();
            let solids =
                (effects.iter()).any(|e| matches!(e, Effect::Sphere(_) | Effect::Obstacle(_)));
            let cut = solids && self.faces.prepare(model);
            if self.self_collision.is_some() {
                let built = matches!(self.self_contacts.prepare(model), Ok(true));
                if built || cut {
                    self.timings.add(super::SELF_SETUP, start.elapsed());
                }
            }
            self.air_damping = air_damping_of(effects);
            self.gravity = gravity_of(effects);
        }
        self.asked = params.step.integrator;
        if changes.contains(Changes::INTEGRATOR) && self.integrator.kind() != params.step.integrator
        {
            self.integrator = params.step.integrator.build::<R>();
        }
        // New forces or strengths make whatever the integrator derived stale (new masses
        // come with `invalidate`).
        if forces_changed {
            self.integrator.forces_changed();
        }
        self.solver = params.solver;
        self.dt = params.step.dt;
        self.offset = params.contact.offset;
        self.guard.reconfigure(&params.guard);
        let requested = params.step.substeps.max(1);
        if requested != self.requested {
            self.requested = requested;
            self.substeps = requested;
        }
    }

    fn invalidate(&mut self) {
        self.integrator.invalidate();
        self.guard.forget_history();
        self.precise.forget();
    }

    fn restart(&mut self) {
        self.invalidate();
        self.substeps = self.requested;
        if self.integrator.kind() != self.asked {
            self.integrator = self.asked.build();
        }
        self.guard.restart();
        self.outside = None;
        self.self_contacts.forget();
    }

    fn substep(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
    ) -> Result<StepReport, StepError> {
        let stepped = self.on_state(state, |stepper, state| {
            let report = stepper.advance(model, state)?;
            stepper.start_outside();
            stepper.resolve_contacts(model, state, None)?;
            Ok(report)
        });
        self.outside = None;
        stepped
    }

    /// One frame under the guard: a frame that breaks a limit (non-finite, too fast, a
    /// spring overstretched, too much kinetic energy, a failed solve) is rolled back to the
    /// last checkpoint and redone with twice the substeps, up to `max_refinements` times,
    /// then with the fallback integrator; raised substeps come back down after
    /// `recover_after` healthy frames.
    fn frame(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
    ) -> Result<FrameOutcome, Diverged> {
        let stepped = self.on_state(state, |stepper, state| stepper.guarded_frame(model, state));
        self.outside = None;
        stepped
    }

    fn moved_outside(&mut self, particle: u32, from: glam::Vec3) {
        self.outside = Some((particle, from));
    }

    fn substeps(&self) -> u32 {
        self.substeps
    }

    fn substep_length(&self) -> f32 {
        self.dt / self.substeps as f32
    }

    fn take_timings(&mut self) -> PhaseTimings {
        self.timings.take()
    }

    fn take_stats(&mut self) -> StepStats {
        std::mem::take(&mut self.stats)
    }

    fn take_guard_events(&mut self) -> Vec<GuardEvent> {
        std::mem::take(&mut self.guard.events)
    }

    fn integrator(&self) -> IntegratorKind {
        self.integrator.kind()
    }

    fn positions_f64(&self, out: &mut Vec<glam::DVec3>) -> bool {
        if R::VECTORISED || !self.precise.holds() {
            return false;
        }
        out.clear();
        out.extend(self.precise.state.pos.iter().map(|p| R::v3_f64(*p)));
        true
    }

    fn self_collision_work(&self) -> Option<SelfWork> {
        self.self_collision.map(|_| self.self_contacts.work)
    }
}

#[cfg(test)]
mod tests;
