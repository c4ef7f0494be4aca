//! A running simulation: the one owner of the cloth's model and state, its parameters, its
//! effects and the step backend. The GUI, the CLI and the tests change things only through
//! it, and it tells the backend exactly what a change made stale.

use crate::cloth::{ClothModel, ClothState};
use crate::sim::{
    Cause, Changes, Diverged, Effect, ForceSet, FrameOutcome, GuardEvent, IntegratorKind,
    Intersections, ParamError, PhaseTimings, SimParams, StepBackend, StepError, StepReport,
    StepStats, cpu_backend, intersections, obstacle_overlap_warnings, thickness_fits,
};

use super::error::SceneError;
use super::file::SceneFile;
use super::scene::Scene;

/// How far back, in simulated seconds, the pointer's velocity is measured for a held
/// particle (see [`Simulation::grab`]).
pub const GRAB_WINDOW: f64 = 0.1;

/// The particle the pointer holds, and where the pointer held it lately.
#[derive(Clone, Debug)]
struct Held {
    particle: u32,
    /// `(simulated time, target)`, oldest first: the samples of the last [`GRAB_WINDOW`]
    /// and the newest one before that.
    trail: Vec<(f64, glam::Vec3)>,
    /// Where the particle was when the backend last stepped, while the pointer has moved
    /// it since (outside any substep): the next frame takes that move into its first
    /// substep ([`StepBackend::moved_outside`]).
    from: Option<glam::Vec3>,
}

impl Held {
    /// Records that the pointer holds the particle at `target` at simulated time `now`, and
    /// returns the pointer's velocity since the trail's first sample (`None` if the clock
    /// has not moved since it).
    fn follow(&mut self, now: f64, target: glam::Vec3) -> Option<glam::Vec3> {
        // A reset turns the clock back: samples from "the future" no longer count.
        self.trail.retain(|&(t, _)| t <= now);
        let old = (self.trail.iter()).rposition(|&(t, _)| now - t >= GRAB_WINDOW);
        self.trail.drain(..old.unwrap_or(0));
        let velocity = match self.trail.first() {
            Some(&(t, from)) if t < now => Some((target - from) / (now - t) as f32),
            _ => None,
        };
        match self.trail.last_mut() {
            Some(last) if last.0 == now => last.1 = target,
            _ => self.trail.push((now, target)),
        }
        velocity
    }
}

/// Scene data, live state, parameters, effects and the backend that steps them.
pub struct Simulation {
    /// The file the scene was built from, for saving the current setup.
    file: SceneFile,
    scenario: String,
    cloth_name: String,
    warnings: Vec<String>,
    /// The scenario's pins, applied while `pins_enabled`.
    scenario_pins: Vec<u32>,
    pins_enabled: bool,
    /// Particles the user pinned or unpinned by hand (toggled on top of the scene's).
    toggled_pins: Vec<u32>,
    /// The particle being dragged, held where the pointer puts it.
    held: Option<Held>,
    model: ClothModel,
    initial: ClothState,
    state: ClothState,
    params: SimParams,
    effects: Vec<Effect>,
    backend: Box<dyn StepBackend>,
    /// Frames advanced since the last reset.
    frames: u64,
}

impl Simulation {
    /// Starts the scene from its initial state on the CPU backend.
    pub fn new(scene: Scene) -> Self {
        // A new CPU stepper is configured for the scene already.
        let backend = cpu_backend(&scene.model, &scene.params, &scene.effects);
        Self::assemble(scene, backend)
    }

    /// Starts the scene on the given backend (configured here with the scene's parameters).
    pub fn with_backend(scene: Scene, mut backend: Box<dyn StepBackend>) -> Self {
        backend.configure(&scene.model, &scene.params, &scene.effects, Changes::all());
        Self::assemble(scene, backend)
    }

    /// The simulation of `scene` on `backend`, configured for it.
    fn assemble(scene: Scene, backend: Box<dyn StepBackend>) -> Self {
        let mut warnings = scene.warnings;
        let offset = scene.params.contact.offset;
        warnings.extend(obstacle_overlap_warnings(
            &scene.effects,
            &scene.model,
            &scene.initial.pos,
            offset,
        ));
        warnings.extend(intersection_warnings(
            &scene.effects,
            &scene.model,
            &scene.initial,
        ));
        Self {
            file: scene.file,
            scenario: scene.scenario,
            cloth_name: scene.cloth_name,
            warnings,
            scenario_pins: scene.pins,
            pins_enabled: true,
            toggled_pins: Vec::new(),
            held: None,
            state: scene.initial.clone(),
            initial: scene.initial,
            model: scene.model,
            params: scene.params,
            effects: scene.effects,
            backend,
            frames: 0,
        }
    }

    /// Moves the running simulation to another backend: the state, parameters and effects
    /// stay; the new backend starts from the current state.
    ///
    /// # Errors
    /// The old backend's state could not be read back; it stays in use.
    pub fn set_backend(&mut self, mut backend: Box<dyn StepBackend>) -> Result<(), StepError> {
        self.backend.sync(&self.model, &mut self.state)?;
        backend.configure(&self.model, &self.params, &self.effects, Changes::all());
        backend.invalidate();
        self.backend = backend;
        Ok(())
    }

    /// An independent copy on a fresh CPU stepper: the same scene, model, state, frame
    /// count, parameters, effects and pins. What only a backend knows (substeps the guard
    /// raised, a multi-step integrator's history, timings) starts anew.
    pub fn fork(&self) -> Simulation {
        let backend = cpu_backend(&self.model, &self.params, &self.effects);
        Simulation {
            file: self.file.clone(),
            scenario: self.scenario.clone(),
            cloth_name: self.cloth_name.clone(),
            warnings: self.warnings.clone(),
            scenario_pins: self.scenario_pins.clone(),
            pins_enabled: self.pins_enabled,
            toggled_pins: self.toggled_pins.clone(),
            held: self.held.clone(),
            model: self.model.clone(),
            initial: self.initial.clone(),
            state: self.state.clone(),
            params: self.params.clone(),
            effects: self.effects.clone(),
            backend,
            frames: self.frames,
        }
    }

    /// Takes over a state stepped elsewhere (a copy of this simulation on another thread)
    /// with the frames it had advanced.
    pub fn adopt_state(&mut self, state: &ClothState, frames: u64) {
        self.state.clone_from(state);
        self.frames = frames;
        self.move_taken();
        self.backend.invalidate();
    }

    /// Back on the CPU stepper (from the GPU, say), keeping the state.
    ///
    /// # Errors
    /// As [`Simulation::set_backend`].
    pub fn use_cpu(&mut self) -> Result<(), StepError> {
        let cpu = cpu_backend(&self.model, &self.params, &self.effects);
        self.set_backend(cpu)
    }

    pub fn scenario(&self) -> &str {
        &self.scenario
    }

    pub fn cloth_name(&self) -> &str {
        &self.cloth_name
    }

    /// Notes from importing the cloth, then about the scene's start: a solid the cloth
    /// already meets, a cloth that intersects itself.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    pub fn model(&self) -> &ClothModel {
        &self.model
    }

    pub fn state(&self) -> &ClothState {
        &self.state
    }

    /// The positions to every digit the backend computes them in (an `f64` stepper's own,
    /// not their `f32` rounding in [`Simulation::state`]), as `f64`.
    pub fn positions_f64(&self) -> Vec<glam::DVec3> {
        let mut out = Vec::new();
        if !self.backend.positions_f64(&mut out) {
            out.extend(self.state.pos.iter().map(|p| p.as_dvec3()));
        }
        out
    }

    /// The state the simulation started from (and returns to on reset).
    pub fn initial(&self) -> &ClothState {
        &self.initial
    }

    pub fn params(&self) -> &SimParams {
        &self.params
    }

    pub fn effects(&self) -> &[Effect] {
        &self.effects
    }

    /// The triangle pairs that intersect now: the cloth's own, and the cloth's against each
    /// solid (see [`crate::sim::intersections()`]).
    pub fn intersections(&self) -> Intersections {
        intersections(
            &self.effects,
            self.state.time,
            &self.model.triangles,
            &self.state.pos,
        )
    }

    /// The likely cause of the frame from `start` (seconds) failing, where the backend saw
    /// only `cause`: it cannot see a grab, so with nothing more specific than the stiffness
    /// the held particle's pull is named, and else a handle that has moved the cloth.
    fn cause_beyond(&self, cause: Cause, start: f64) -> Cause {
        let Cause::Stiffness { implicit_tried } = cause else {
            return cause;
        };
        if self.held.is_some() {
            Cause::Pull { implicit_tried }
        } else if self.handle_moved(start) {
            let self_contact = (self.effects.iter()).any(|e| matches!(e, Effect::SelfCollision(_)));
            Cause::Handle {
                implicit_tried,
                self_contact,
            }
        } else {
            cause
        }
    }

    /// Whether a handle has moved the cloth by the end of the frame from `start` (seconds):
    /// its pose then is not its first, and it holds a particle (one still pinned).
    fn handle_moved(&self, start: f64) -> bool {
        let end = start + f64::from(self.params.step.dt);
        let pinned = |p: &u32| self.model.inv_mass.get(*p as usize) == Some(&0.0);
        (self.effects.iter()).any(|e| match e {
            Effect::Handle(h) => {
                h.motion.at(end) != h.motion.at(f64::NEG_INFINITY) && h.particles.iter().any(pinned)
            }
            _ => false,
        })
    }

    /// The solids among the effects (spheres, planes): what a particle may not enter.
    pub fn solids(&self) -> impl Iterator<Item = &Effect> {
        self.effects.iter().filter(|e| e.is_solid())
    }

    /// Frames advanced since the last reset.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Name of the step backend ("cpu", …).
    pub fn backend_name(&self) -> &'static str {
        self.backend.name()
    }

    /// The simulation as a scene to start others from: its model (with the pins in force),
    /// its initial state, and its current parameters and effects.
    pub fn to_scene(&self) -> Scene {
        Scene {
            file: self.scene_file(),
            scenario: self.scenario.clone(),
            cloth_name: self.cloth_name.clone(),
            model: self.model.clone(),
            initial: self.initial.clone(),
            params: self.params.clone(),
            effects: self.effects.clone(),
            pins: self.scenario_pins.clone(),
            warnings: self.warnings.clone(),
        }
    }

    /// The current setup as a scene file: the scene's cloth and placement with the
    /// parameters, effects and pins in force now.
    pub fn scene_file(&self) -> SceneFile {
        // Handled particles are pinned while their handle moves them; the file keeps them
        // in its `[[handles]]`, not in `[pins]`.
        let handled: Vec<u32> = (self.effects.iter())
            .filter_map(|e| match e {
                Effect::Handle(h) => Some(h.particles.iter().copied()),
                _ => None,
            })
            .flatten()
            .collect();
        let pins: Vec<u32> = (self.model.pins.iter().copied())
            .filter(|p| !handled.contains(p))
            .collect();
        let changed = self.model.pins != self.scenario_pins;
        self.file.with_setup(
            &self.params,
            &self.effects,
            changed.then_some(pins.as_slice()),
        )
    }

    /// Writes [`Simulation::scene_file`] to `path`, its paths relative to it and the
    /// built-in meshes it names beside it.
    ///
    /// # Errors
    /// [`SaveError`](super::SaveError): a file in a built-in mesh's place, or a write that failed (nothing
    /// is left half-written).
    pub fn save_scene(&self, path: &std::path::Path) -> Result<super::Saved, super::SaveError> {
        super::save::save(&self.scene_file(), path)
    }

    /// The cloth as it is now, as OBJ text: current positions, the triangles, the UVs.
    /// Importing it gives back the same particles and triangles.
    pub fn export_obj(&self) -> String {
        let soup = crate::mesh::PolygonSoup {
            positions: self.state.pos.clone(),
            uvs: Some(self.model.uvs.clone()),
            face_indices: self.model.triangles.iter().flatten().copied().collect(),
            face_arities: vec![3; self.model.triangles.len()],
        };
        crate::mesh::write_obj(&soup)
    }

    /// The last self-collision pass's work, when the scene has self-collision.
    pub fn self_collision_work(&self) -> Option<crate::sim::SelfWork> {
        self.backend.self_collision_work()
    }

    /// The pairs of the cloth that prescribed motion (a grab, pins, a handle) forced
    /// together since the simulation was made, over the substeps that stand, on either
    /// backend; `None` without self-collision.
    pub fn forced_pairs(&self) -> Option<u64> {
        self.backend.forced_pairs()
    }

    /// Total mechanical energy (kinetic plus the potential of the conservative forces),
    /// joules.
    pub fn energy(&self) -> f64 {
        self.state.kinetic_energy(&self.model)
            + ForceSet::<f32>::new(&self.model, &self.params.material, &self.effects)
                .potential_energy(&self.model, &self.state.pos)
    }

    /// Replaces the parameters of the running simulation; the backend redoes only what the
    /// [changes](SimParams::changes_to) touch (a stiffness slider retunes the springs in
    /// place and rebuilds nothing). The state, the time, the timings and the substeps the
    /// guard raised are kept (unless `substeps` itself changed); an integrator the guard
    /// fell back from is asked for again; a new density rescales the masses. Only that
    /// reads back a backend's copy of the state: a slider moving a stiffness on the GPU
    /// backend sends the new strengths and nothing else.
    ///
    /// # Errors
    /// [`SceneError::Params`] naming the bad value; nothing changes then.
    pub fn set_params(&mut self, params: SimParams) -> Result<(), SceneError> {
        params.validate()?;
        let mut changes = self.params.changes_to(&params);
        // Asking for the integrator the guard replaced asks for it once more.
        if self.backend.integrator() != params.step.integrator {
            changes |= Changes::INTEGRATOR;
        }
        if changes.contains(Changes::DENSITY) {
            self.before_edit();
            self.model.set_density(params.material.density);
            self.backend.invalidate();
        }
        self.params = params;
        if changes.contains(Changes::PRECISION) && self.backend.name() == "cpu" {
            // Another precision is another stepper; it starts from the current state.
            self.backend = cpu_backend(&self.model, &self.params, &self.effects);
            self.backend.invalidate();
            return Ok(());
        }
        (self.backend).configure(&self.model, &self.params, &self.effects, changes);
        Ok(())
    }

    /// Replaces the effect list (switches forces on or off, moves or retunes colliders).
    /// Returns warnings about it (a mesh obstacle added where the cloth already meets it).
    /// The state, and a backend's copy of it, are left as they are.
    ///
    /// # Errors
    /// [`SceneError::Effect`] for a value out of range, [`SceneError::Thickness`] for a
    /// self-collision thickness at or above the cloth's shortest rest edge; nothing changes
    /// then.
    pub fn set_effects(&mut self, effects: Vec<Effect>) -> Result<Vec<String>, SceneError> {
        for effect in &effects {
            effect.check().map_err(|error| SceneError::Effect {
                effect: effect.phase(),
                error,
            })?;
            if let Effect::Obstacle(o) = effect
                && !o.is_loaded()
            {
                return Err(SceneError::Effect {
                    effect: effect.phase(),
                    error: ParamError::new("obj", o.source(), "was not read: load it first"),
                });
            }
        }
        if let Some(twice) = crate::sim::listed_twice(&effects) {
            return Err(SceneError::Effect {
                effect: twice.kind,
                error: ParamError::new("type", twice.kind, twice.rule()),
            });
        }
        thickness_fits(&effects, &self.model).map_err(|error| SceneError::Thickness {
            cloth: self.cloth_name.clone(),
            error,
        })?;
        // An obstacle added now that the cloth already meets is warned about (one it had
        // before may rest on it).
        let added: Vec<Effect> = (effects.iter())
            .filter(|e| match e {
                Effect::Obstacle(new) => !self.effects.iter().any(|old| match old {
                    Effect::Obstacle(old) => old.shape == new.shape,
                    _ => false,
                }),
                _ => false,
            })
            .cloned()
            .collect();
        self.effects = effects;
        let offset = self.params.contact.offset;
        let warnings = obstacle_overlap_warnings(&added, &self.model, &self.state.pos, offset);
        (self.backend).configure(&self.model, &self.params, &self.effects, Changes::EFFECTS);
        Ok(warnings)
    }

    /// The scenario's pins (whether or not they are enabled).
    pub fn scenario_pins(&self) -> &[u32] {
        &self.scenario_pins
    }

    pub fn pins_enabled(&self) -> bool {
        self.pins_enabled
    }

    /// Switches the scenario's pins on or off. Newly pinned particles stop where they are.
    pub fn set_pins_enabled(&mut self, enabled: bool) {
        self.pins_enabled = enabled;
        self.refresh_pins();
    }

    /// Pins particle `p` if it is free, frees it if it is pinned (on top of the scene's pins).
    pub fn toggle_pin(&mut self, p: u32) {
        if p as usize >= self.model.particle_count() {
            return;
        }
        match self.toggled_pins.iter().position(|&q| q == p) {
            Some(i) => {
                self.toggled_pins.remove(i);
            }
            None => self.toggled_pins.push(p),
        }
        self.refresh_pins();
    }

    /// Holds particle `p` at `target` (metres) until [`Simulation::release`]. Works under
    /// every integrator: a held particle is pinned, and its velocity is the pointer's.
    ///
    /// That velocity is measured in simulated time: the way from where the pointer held it
    /// [`GRAB_WINDOW`] ago (or at its last call before that) to `target`. So it does not
    /// depend on how many frames the window draws per simulated frame, and one jittery
    /// sample barely moves it. A first call, or calls while the clock stands still, count
    /// the move from where the particle is as one frame's.
    pub fn grab(&mut self, p: u32, target: glam::Vec3) {
        if p as usize >= self.model.particle_count() || !target.is_finite() {
            return;
        }
        self.before_edit();
        if self.grabbed() != Some(p) {
            self.held = Some(Held {
                particle: p,
                trail: Vec::new(),
                from: None,
            });
            self.refresh_pins();
        }
        let now = self.state.time;
        let i = p as usize;
        let was = self.state.pos[i];
        let Some(held) = self.held.as_mut() else {
            return;
        };
        held.from.get_or_insert(was);
        let pointer = held.follow(now, target);
        self.state.vel[i] = pointer.unwrap_or((target - was) / self.params.step.dt);
        self.state.pos[i] = target;
        self.backend.invalidate();
    }

    /// Hands the backend the move the pointer made since the last step, for the frame
    /// about to be stepped.
    fn hand_over_move(&mut self) {
        if let Some(Held {
            particle,
            from: Some(from),
            ..
        }) = self.held
        {
            self.backend.moved_outside(particle, from);
        }
    }

    /// The step took the pointer's move (or the state it started from was replaced).
    fn move_taken(&mut self) {
        if let Some(held) = &mut self.held {
            held.from = None;
        }
    }

    /// Lets go of the held particle; it flies on at the pointer's velocity (see
    /// [`Simulation::grab`]).
    pub fn release(&mut self) {
        if self.held.take().is_some() {
            self.refresh_pins();
        }
    }

    /// The particle being held, if any.
    pub fn grabbed(&self) -> Option<u32> {
        self.held.as_ref().map(|h| h.particle)
    }

    /// Pins in force: the scene's (when enabled), toggled by hand, and the held particle.
    fn refresh_pins(&mut self) {
        self.before_edit();
        let mut pins = if self.pins_enabled {
            self.scenario_pins.clone()
        } else {
            Vec::new()
        };
        for &p in &self.toggled_pins {
            match pins.iter().position(|&q| q == p) {
                Some(i) => {
                    pins.remove(i);
                }
                None => pins.push(p),
            }
        }
        let held: Vec<u32> = self.grabbed().into_iter().collect();
        pins.extend(held.iter().copied());
        let newly_pinned: Vec<u32> = pins
            .iter()
            .copied()
            .filter(|p| !self.model.pins.contains(p) && !held.contains(p))
            .collect();
        self.model.set_pins(&pins);
        for p in newly_pinned {
            self.state.vel[p as usize] = glam::Vec3::ZERO;
        }
        // A handle takes back what is pinned again at once, so that the next frame starts
        // from where its motion has them (the guard then counts the stretch as given).
        for effect in &self.effects {
            if let Effect::Handle(handle) = effect {
                handle.place(&self.model.inv_mass, &mut self.state);
            }
        }
        self.backend.invalidate();
    }

    /// Changes the live state (a drag, a throw); the backend is told.
    pub fn modify_state(&mut self, change: impl FnOnce(&mut ClothState)) {
        self.before_edit();
        change(&mut self.state);
        self.backend.invalidate();
    }

    /// Substeps per frame in effect: the requested count, or more if the guard raised it.
    pub fn substeps(&self) -> u32 {
        self.backend.substeps()
    }

    /// The substep in effect, seconds.
    pub fn substep_length(&self) -> f32 {
        self.backend.substep_length()
    }

    /// Back to the initial state; parameters, effects and pins are kept. The run starts
    /// over as a new one would ([`StepBackend::restart`]): the frames after it are the
    /// first run's again.
    pub fn reset(&mut self) {
        self.state.clone_from(&self.initial);
        for &p in &self.model.pins {
            self.state.vel[p as usize] = glam::Vec3::ZERO;
        }
        self.frames = 0;
        self.move_taken();
        self.backend.restart();
    }

    /// Advances one frame (`params.step.dt`).
    ///
    /// # Errors
    /// [`Diverged`]: the state is left at the frame's start. Its cause is the held
    /// particle's pull, or a handle that has moved, where the backend saw nothing more
    /// specific.
    pub fn step_frame(&mut self) -> Result<FrameOutcome, Diverged> {
        self.hand_over_move();
        let start = self.state.time;
        let out = self
            .backend
            .frame(&self.model, &mut self.state)
            .map_err(|mut e| {
                e.cause = self.cause_beyond(e.cause, start);
                e
            })?;
        self.move_taken();
        self.frames += 1;
        Ok(out)
    }

    /// Advances one substep with no divergence guard; for tests and tools that inspect
    /// every substep.
    ///
    /// # Errors
    /// The integrator's [`StepError`].
    pub fn substep(&mut self) -> Result<StepReport, StepError> {
        self.hand_over_move();
        let report = self.backend.substep(&self.model, &mut self.state)?;
        self.move_taken();
        Ok(report)
    }

    /// Makes [`Simulation::state`] current when the backend steps a copy of its own (the
    /// GPU backend between read-backs); a no-op on the CPU.
    ///
    /// # Errors
    /// [`StepError::Device`] when the copy could not be read; the state is then unchanged.
    pub fn sync_state(&mut self) -> Result<(), StepError> {
        self.backend.sync(&self.model, &mut self.state)
    }

    /// Whether the backend stepped past [`Simulation::state`] (the GPU backend between
    /// read-backs): [`Simulation::sync_state`] would bring it up to date.
    pub fn state_behind(&self) -> bool {
        self.backend.state_behind()
    }

    /// CPU threads that may step the cloth (see [`StepBackend::cpu_threads`]; one for the GPU
    /// backend: the thread that submits).
    pub fn cpu_threads(&self) -> usize {
        self.backend.cpu_threads()
    }

    /// Before an edit that reads or replaces part of the state or the model: brings the state
    /// up to date with the backend's copy, so the edit starts from the latest frame and
    /// what the backend takes afterwards is the edited latest frame. A copy that cannot be
    /// read leaves the state as it was; the backend remembers why and fails its next frame
    /// with it, which is where the user hears of it.
    fn before_edit(&mut self) {
        let _ = self.backend.sync(&self.model, &mut self.state);
    }

    /// Wall time per phase since the last call.
    pub fn take_timings(&mut self) -> PhaseTimings {
        self.backend.take_timings()
    }

    /// Work counters since the last call.
    pub fn take_stats(&mut self) -> StepStats {
        self.backend.take_stats()
    }

    /// What the stability guard did since the last call.
    pub fn take_guard_events(&mut self) -> Vec<GuardEvent> {
        self.backend.take_guard_events()
    }

    /// The integrator in effect: the requested one, or the guard's fallback.
    pub fn integrator_in_effect(&self) -> IntegratorKind {
        self.backend.integrator()
    }
}

/// A warning for a cloth that already intersects itself or a solid in `initial`: the
/// guarantee that contact keeps a cloth free of intersections starts from a free state.
fn intersection_warnings(
    effects: &[Effect],
    model: &ClothModel,
    initial: &ClothState,
) -> Vec<String> {
    let found = intersections(effects, initial.time, &model.triangles, &initial.pos);
    let mut warnings = Vec::new();
    if found.self_pairs > 0 {
        warnings.push(format!(
            "the cloth intersects itself at the start ({} triangle pairs meet): contact \
             keeps a cloth free of intersections only from a free start",
            found.self_pairs
        ));
    }
    let solids = effects.iter().filter(|e| e.is_solid());
    for (k, (count, solid)) in found.obstacles.iter().zip(solids).enumerate() {
        if *count > 0 {
            warnings.push(format!(
                "the cloth intersects solid {} ({}) at the start: {count} of its triangles \
                 meet it",
                k + 1,
                solid.phase()
            ));
        }
    }
    warnings
}
