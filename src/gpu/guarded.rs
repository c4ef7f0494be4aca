//! The stability guard on the GPU: the CPU guard's limits, policy and record
//! ([`crate::sim::GuardLimits`], [`crate::sim::GuardState`]), with the state measured by a
//! reduction on the device and rolled back from copies kept there. A frame that breaks a
//! limit is redone from the last checkpoint with twice the substeps, up to the policy's
//! refinements; raised substeps come back down after a run of healthy frames. When every
//! refinement fails, the policy's fallback integrator is tried at the requested substeps if
//! the GPU runs it (implicit Euler, the default, XPBD, VBD); when that fails too, or is
//! not tried, the state is the frame's start and the run stops with the likely cause.
//! A frame in which self-contact's room for pairs or grid entries ran out (the substeps
//! concerned left the cloth where they started it) is redone with the room grown, from its
//! start or, in a replay, from the rollback point.

use std::time::Instant;

use crate::cloth::{ClothModel, ClothState};
use crate::sim::{Cause, Diverged, FrameOutcome, GuardAction, GuardLimits, Trouble, resolved};

use super::error::GpuError;
use super::health::Watch;
use super::snapshot::DeviceSnapshot;
use super::stepper::GpuStepper;
use super::support::GPU_INTEGRATORS;

/// Why a try at a frame failed.
enum Failed {
    /// It broke one of the guard's limits.
    Limit(Trouble),
    /// The device failed (said in the text); nothing more can be stepped.
    Device(String),
}

/// A try at a frame that broke no limit.
enum Tried {
    /// It stands.
    Stood,
    /// Self-contact's room ran out (and has grown since): the frame is to be redone.
    RanOut,
}

/// Tries a frame has at being redone where self-contact's room ran out; past them a frame
/// that ran out stands as stepped (safe: the substeps concerned did not move the cloth).
const ROOM_TRIES: u32 = 4;

/// The frame as stepped, and its end measured.
const FRAME: Watch = Watch {
    keep_start: true,
    measure: true,
};

/// A frame replayed from a rollback point, its end measured.
const REPLAY: Watch = Watch {
    keep_start: false,
    measure: true,
};

impl GpuStepper {
    /// One frame under the guard (see the module documentation).
    pub(super) fn guarded_frame(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
    ) -> Result<FrameOutcome, Diverged> {
        let end = state.time + self.dt as f64;
        let outcome = if self.guard.policy.enabled {
            let start = Instant::now();
            let outcome = self.checked_frame(model, state, end);
            self.timings.add("gpu", start.elapsed());
            outcome?
        } else {
            self.timed_run(model, state, self.substeps)
                .map_err(|e| self.device_failure(state.time, e.to_string()))?;
            state.time = end;
            FrameOutcome::Stepped
        };
        // A cloth grown past what the mesh obstacles were fitted to has them fitted again.
        (self.refit_obstacles(model, state))
            .map_err(|e| self.device_failure(state.time, e.to_string()))?;
        Ok(outcome)
    }

    fn checked_frame(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
        end: f64,
    ) -> Result<FrameOutcome, Diverged> {
        if self.guard.limits.is_none() {
            self.derive_limits(model, state)
                .map_err(|why| self.device_failure(state.time, why))?;
        }
        self.room_tries = ROOM_TRIES;
        let outcome = loop {
            match self.try_frame(model, state, state.time, FRAME, true) {
                Ok(Tried::RanOut) => {
                    let start = self.frame_start.clone();
                    self.restore(&start);
                }
                Ok(Tried::Stood) => {
                    self.guard.healthy_frame(&self.frame_start);
                    break Ok(self.maybe_recover(end).unwrap_or(FrameOutcome::Stepped));
                }
                Err(Failed::Limit(trouble)) => break self.rescue(model, state, end, trouble),
                Err(Failed::Device(why)) => break Err(self.device_failure(state.time, why)),
            }
        }?;
        state.time = end;
        if self.read_every_frame {
            // The frame's last submission copied its end out with the measure.
            self.read_copied(state)
                .map_err(|e| self.device_failure(state.time, e.to_string()))?;
        }
        Ok(outcome)
    }

    /// The guard's limits from the caller's state, brought up to date first.
    fn derive_limits(&mut self, model: &ClothModel, state: &mut ClothState) -> Result<(), String> {
        if !self.upload && self.behind {
            self.read_back(state).map_err(|e| e.to_string())?;
        }
        let limits = GuardLimits::derive(
            &self.guard.policy,
            model,
            (state, &state.pos),
            self.gravity,
            &self.forces,
            &self.effects,
        );
        self.health.set_up(&self.queue, limits.up);
        self.guard.limits = Some(limits);
        Ok(())
    }

    /// One frame from `time` (seconds) at the substeps in effect, submitted with what
    /// `watch` asks, and its end judged against the guard's limits; or, while the frame has
    /// tries left, to be redone where self-contact's room ran out, the room grown when
    /// `grow` (else it ran out, whatever the tries).
    fn try_frame(
        &mut self,
        model: &ClothModel,
        state: &ClothState,
        time: f64,
        watch: Watch,
        grow: bool,
    ) -> Result<Tried, Failed> {
        (self.run(model, state, (self.substeps, time), watch))
            .map_err(|e| Failed::Device(e.to_string()))?;
        let health = self.health.read(&self.device).map_err(|e| {
            let why = e.to_string();
            self.lost = Some(why.clone());
            Failed::Device(why)
        })?;
        let device = |e: GpuError| Failed::Device(e.to_string());
        let counters = self.contacts.read_counters(&self.device).map_err(device)?;
        // Self-contact's searches measure each substep's fastest particle before its cuts, as the
        // CPU's guard checks each substep: a blow-up inside the frame is caught there even
        // where the contacts or the room running out held the cloth back by its end.
        let mut motion = health.motion;
        if let Some(read) = &counters {
            motion.speed = motion.speed.max(read.fastest);
            motion.finite &= read.fastest.is_finite();
        }
        let limits = (self.guard.limits.as_ref()).ok_or(Failed::Limit(Trouble::NonFinite))?;
        if let Some(trouble) = limits.judge(&motion, || health.strain) {
            // The room a blown-up try asked for (its boxes cover everything) is not given.
            return Err(Failed::Limit(trouble));
        }
        let ran_out = match counters {
            Some(read) if grow => {
                (self.contacts.make_room(&self.device, read.asked)).map_err(device)?
            }
            Some(read) => self.contacts.runs_out(read.asked),
            None => false,
        };
        if ran_out && !grow {
            return Ok(Tried::RanOut);
        }
        if ran_out && self.room_tries > 0 {
            self.room_tries -= 1;
            return Ok(Tried::RanOut);
        }
        Ok(Tried::Stood)
    }

    /// Encodes and submits the copy of `snapshot` into the live particle buffer (and the
    /// display's); returns the time it holds. The device's copy is then ahead of the
    /// caller's state.
    pub(super) fn restore(&mut self, snapshot: &DeviceSnapshot) -> f64 {
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("particles rollback"),
            });
        let live = &self.particles[self.current];
        let time = snapshot.restore(&mut encoder, live);
        self.contacts.roll_back_forced(snapshot.forced);
        if let Some(display) = &self.display {
            encoder.copy_buffer_to_buffer(live, 0, display, 0, None);
        }
        self.queue.submit([encoder.finish()]);
        self.upload = false;
        self.forget_guesses();
        self.behind = true;
        time
    }

    /// Replays from the rollback point to `end` at the substeps in effect, from the start
    /// again where self-contact's room ran out.
    fn replay(&mut self, model: &ClothModel, state: &ClothState, end: f64) -> Result<(), Failed> {
        'again: loop {
            let from = (self.guard.checkpoint.clone()).unwrap_or_else(|| self.frame_start.clone());
            let time = self.restore(&from);
            let frames = ((end - time) / self.dt as f64).round().max(1.0) as u32;
            for k in 0..frames {
                let start = time + k as f64 * self.dt as f64;
                if let Tried::RanOut = self.try_frame(model, state, start, REPLAY, true)? {
                    continue 'again;
                }
            }
            return Ok(());
        }
    }

    /// A frame failed with `trouble`: roll back and redo it with more substeps; else
    /// restore the frame's start (read back into `state`) and say why.
    fn rescue(
        &mut self,
        model: &ClothModel,
        state: &mut ClothState,
        end: f64,
        trouble: Trouble,
    ) -> Result<FrameOutcome, Diverged> {
        match self.admit(model, state, end, &trouble) {
            Ok(Some(outcome)) => return Ok(outcome),
            Ok(None) => {}
            Err(why) => return Err(self.device_failure(state.time, why)),
        }
        self.guard.failed_frame();
        let before = self.substeps;
        let mut last = trouble;
        let refinements = self.guard.policy.max_refinements;
        let tries = (before.saturating_mul(2), refinements);
        match self.replay_doubling(model, state, end, tries, &mut last) {
            Ok(true) => {
                let to = self.substeps;
                (self.guard).record(end, Some(&last), GuardAction::Refined, (before, to));
                return Ok(FrameOutcome::Refined { from: before, to });
            }
            Ok(false) => {}
            Err(why) => return Err(self.device_failure(state.time, why)),
        }
        let tried = self.substeps;
        let (mut fallback, mut fell_back) = (String::new(), None);
        if let Some(kind) = self.guard.policy.fallback
            && kind != self.integrator
            && GPU_INTEGRATORS.contains(&kind)
        {
            let original = self.integrator;
            self.switch_integrator(kind);
            // At the requested substeps, then refined as the integrator asked for was.
            let tries = (self.requested, refinements + 1);
            match self.replay_doubling(model, state, end, tries, &mut last) {
                Ok(true) => {
                    let action = GuardAction::FellBack { integrator: kind };
                    (self.guard).record(end, Some(&last), action, (before, self.substeps));
                    return Ok(FrameOutcome::FellBack { integrator: kind });
                }
                Ok(false) => {}
                Err(why) => return Err(self.device_failure(state.time, why)),
            }
            self.switch_integrator(original);
            fallback = format!(
                ", and with {} at up to {} substeps",
                kind.label(),
                self.substeps
            );
            fell_back = Some(kind);
        }
        let start = self.frame_start.clone();
        self.restore(&start);
        self.set_substeps(before);
        let gave_up = GuardAction::GaveUp;
        (self.guard).record(state.time, Some(&last), gave_up, (before, before));
        if let Err(e) = self.read_back(state) {
            return Err(self.device_failure(state.time, e.to_string()));
        }
        let cause = Cause::substeps(
            self.integrator,
            model,
            &self.forces,
            &state.pos,
            self.air_damping,
            self.dt,
            tried,
        );
        Err(Diverged {
            time: state.time,
            reason: last.to_string(),
            substeps: tried,
            fallback,
            cause: Cause::of_springs(cause, self.integrator, fell_back),
        })
    }

    /// Replays to `end` at `from` substeps a frame, then at twice as many, `tries` times in
    /// all, until one stands (`Ok(true)`; its substeps stay in effect); `last` is the last
    /// try's trouble, an error the device's failure. The substeps are the last tried where
    /// none stood.
    fn replay_doubling(
        &mut self,
        model: &ClothModel,
        state: &ClothState,
        end: f64,
        (from, tries): (u32, u32),
        last: &mut Trouble,
    ) -> Result<bool, String> {
        for k in 0..tries {
            self.set_substeps(if k == 0 {
                from
            } else {
                self.substeps.saturating_mul(2)
            });
            match self.replay(model, state, end) {
                Ok(()) => return Ok(true),
                Err(Failed::Limit(t)) => *last = t,
                Err(Failed::Device(why)) => return Err(why),
            }
        }
        Ok(false)
    }

    /// A speed or kinetic-energy limit crossed, as on the CPU: the frame redone from its
    /// start against the limits raised to admit what it reached, with twice the substeps
    /// and then with the substeps in effect, which it ends with on the device. Where both
    /// stand and their velocities agree ([`resolved`]), the motion is the scene's: the frame
    /// and the raised limits stand. Else nothing stands, for the rescue to roll back; an
    /// error is the device's failure.
    fn admit(
        &mut self,
        model: &ClothModel,
        state: &ClothState,
        end: f64,
        trouble: &Trouble,
    ) -> Result<Option<FrameOutcome>, String> {
        let Some(limits) = self.guard.limits else {
            return Ok(None);
        };
        let Some(raised) = limits.admitting(trouble, self.integrator) else {
            return Ok(None);
        };
        self.guard.limits = Some(raised);
        let before = self.substeps;
        self.set_substeps(before.saturating_mul(2));
        let fine = self.redone(model, state)?;
        self.set_substeps(before);
        let coarse = match fine {
            Some(_) => self.redone(model, state)?,
            None => None,
        };
        if let (Some(fine), Some(coarse)) = (fine, coarse)
            && resolved(&coarse, &fine)
        {
            self.guard.healthy_frame(&self.frame_start);
            let action = GuardAction::Raised {
                speed: raised.speed,
                joules: raised.kinetic_energy,
            };
            (self.guard).record(end, Some(trouble), action, (before, before));
            return Ok(Some(FrameOutcome::Stepped));
        }
        self.guard.limits = Some(limits);
        Ok(None)
    }

    /// The frame redone from its start at the substeps in effect, against the guard's
    /// limits: its end velocities (read back) where it stood, `None` where it broke a limit
    /// or self-contact's room ran out.
    fn redone(
        &mut self,
        model: &ClothModel,
        state: &ClothState,
    ) -> Result<Option<Vec<glam::Vec3>>, String> {
        let start = self.frame_start.clone();
        let time = self.restore(&start);
        // Limits raised to admit a speed could let a blow-up's try ask for room it must not
        // get: a try that ran out is not admitted, and the room stays.
        match self.try_frame(model, state, time, REPLAY, false) {
            Ok(Tried::Stood) => {
                let mut end = state.clone();
                self.read_back(&mut end).map_err(|e| e.to_string())?;
                // Read into a copy: the caller's state is still behind the device's.
                self.behind = true;
                Ok(Some(end.vel))
            }
            Ok(Tried::RanOut) | Err(Failed::Limit(_)) => Ok(None),
            Err(Failed::Device(why)) => Err(why),
        }
    }

    /// After a healthy frame: maybe bring raised substeps back down.
    fn maybe_recover(&mut self, end: f64) -> Option<FrameOutcome> {
        let before = self.substeps;
        let to = self.guard.step_down(before, self.requested)?;
        self.set_substeps(to);
        (self.guard).record(end, None, GuardAction::Recovered, (before, to));
        Some(FrameOutcome::Recovered { from: before, to })
    }

    /// The run stops: the device failed at `time` (seconds) for `why`.
    fn device_failure(&self, time: f64, why: String) -> Diverged {
        Diverged {
            time,
            reason: why,
            substeps: self.substeps,
            fallback: String::new(),
            cause: Cause::Backend,
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::super::health::Watch;
    use super::super::stepper::GpuStepper;
    use crate::cloth::ClothState;
    use crate::device::{AdapterPreference, HeadlessDevice};
    use crate::gpu::packing::tests::unbent;
    use crate::scene::Scene;
    use crate::sim::{Changes, IntegratorKind, Motion, SimParams, StepBackend};

    /// The rollback point kept on the device is a state the run passed through, to the
    /// bit, `checkpoint_frames` healthy frames or more before the latest: restored and read
    /// back after sixteen frames (by then the second candidate has aged into it), it is
    /// the state read back after the frame it names.
    #[test]
    fn the_devices_checkpoint_is_an_earlier_frames_state_to_the_bit() {
        let gpu = HeadlessDevice::open(AdapterPreference::Software).expect("an adapter");
        let scene = guarded_bench();
        let model = &scene.model;
        let mut stepper = stepper_on(&gpu, &scene);
        let mut state = scene.initial.clone();
        let mut seen = vec![state.clone()];
        for _ in 0..16 {
            stepper.frame(model, &mut state).expect("a healthy frame");
            seen.push(state.clone());
        }
        let checkpoint = stepper.guard.checkpoint.clone().expect("a checkpoint");
        let params = &scene.params;
        let frame = (checkpoint.time / params.step.dt as f64).round() as usize;
        let age = params.guard.checkpoint_frames as usize;
        assert!(
            (1..=16 - age).contains(&frame),
            "checkpoint at frame {frame}"
        );
        stepper.restore(&checkpoint);
        let mut back = state.clone();
        stepper.read_back(&mut back).expect("read back");
        assert_eq!(back.pos, seen[frame].pos);
        assert_eq!(back.vel, seen[frame].vel);
        assert_ne!(back.pos, state.pos, "the cloth moved since");
    }

    /// A replay (the guard's redo from its rollback point after a broken limit) in which a
    /// frame runs out of self-contact's room starts again from the rollback point with the
    /// room grown, and ends where the same replay with room enough ends, to the bit.
    /// `layers` at 4 quads under XPBD at 8 substeps, on the GPU for frame 14, as its
    /// five cloths reach the sphere; then replayed from the checkpoint to there at 16
    /// substeps, once as it was and once with the room shrunk to 8 pairs and 64 grid entries
    /// just before (the cloths alone need more than that). The replays run the wide path:
    /// without `size_pairs` recording what each search asked for, the positions differ.
    #[test]
    fn a_replay_that_runs_out_of_room_starts_again_with_more() {
        let gpu = HeadlessDevice::open(AdapterPreference::Software).expect("an adapter");
        let options = Default::default();
        let mut scene = Scene::open_resized("layers", None, &options, Some(4)).expect("scene");
        scene.params.step.integrator = IntegratorKind::Xpbd;
        scene.params.step.substeps = 8;
        scene.params.guard.enabled = true;
        let mut cpu = crate::scene::Simulation::new(scene.clone());
        for _ in 0..14 {
            cpu.step_frame().expect("a frame");
        }
        scene.initial = cpu.state().clone();
        let model = &scene.model;
        let replayed = |room: Option<[u32; 2]>| {
            let mut stepper = stepper_on(&gpu, &scene);
            let mut state = scene.initial.clone();
            for frame in 14..15 {
                let outcome = stepper.frame(model, &mut state).expect("a frame");
                assert_eq!(outcome, crate::sim::FrameOutcome::Stepped, "frame {frame}");
            }
            assert!(stepper.guard.checkpoint.is_some(), "a rollback point");
            let own = stepper.contacts.own.as_mut().expect("self-contact");
            // The wide path (the room test in `gpu::self_contact` runs one workgroup).
            (own.room, own.forced) = (room, Some(false));
            stepper.set_substeps(16);
            let before = stepper.stats.steps;
            let end = state.time;
            assert!(
                stepper.replay(model, &state, end).is_ok(),
                "the replay stands"
            );
            stepper.read_back(&mut state).expect("read back");
            (state, stepper.stats.steps - before)
        };
        let ((roomy, plain), (tight, again)) = (replayed(None), replayed(Some([8, 64])));
        assert!(roomy.pos == tight.pos, "positions differ");
        assert!(roomy.vel == tight.vel, "velocities differ");
        assert!(
            again > plain,
            "started again: {again} substeps against {plain}"
        );
    }

    /// The largest relative extension of a spring of `state` (0 when none is stretched).
    fn strain(scene: &Scene, state: &ClothState) -> f32 {
        let s = &scene.model.springs;
        (0..s.len())
            .map(|e| {
                let (a, b) = (s.a[e] as usize, s.b[e] as usize);
                state.pos[a].distance(state.pos[b]) / s.rest[e] - 1.0
            })
            .fold(0.0, f32::max)
    }

    /// On a jittered, moving cloth the device measures what the CPU guard does: the fastest
    /// speed, the kinetic energy, the lowest height along a tilted `up` and the largest
    /// stretch, to f32 rounding; a NaN velocity or an infinite position anywhere is seen.
    #[test]
    fn the_devices_measure_of_a_state_is_the_cpus() {
        let gpu = HeadlessDevice::open(AdapterPreference::Software).expect("an adapter");
        let scene = Scene::builtin("sphere-drop").expect("scene");
        let (model, params) = (&scene.model, &scene.params);
        let mut state = scene.initial.clone();
        let mut rng = crate::test_rng::uniform(7);
        let mut jitter = |scale: f32| scale * Vec3::new(rng() - 0.5, rng() - 0.5, rng() - 0.5);
        for (x, v) in state.pos.iter_mut().zip(&mut state.vel) {
            *x += jitter(0.01);
            *v = jitter(3.0);
        }
        let mut stepper =
            GpuStepper::new(&gpu.device, &gpu.queue, model, params, &scene.effects, true)
                .expect("stepper");
        let up = Vec3::new(0.3, 0.9, -0.2).normalize();
        stepper.health.set_up(&gpu.queue, up);
        let measure = Watch {
            keep_start: false,
            measure: true,
        };
        let mut measured = |state: &ClothState| {
            stepper.upload = true;
            stepper
                .run(model, state, (0, state.time), measure)
                .expect("run");
            stepper.health.read(&gpu.device).expect("read")
        };
        let device = measured(&state);
        let cpu = Motion::of(model, &state, up);
        let close = |a: f64, b: f64, tol: f64| (a - b).abs() <= tol * b.abs();
        assert!(device.motion.finite);
        assert!(close(device.motion.speed as f64, cpu.speed as f64, 1e-6));
        assert!(
            close(device.motion.joules, cpu.joules, 1e-5),
            "{device:?} {cpu:?}"
        );
        assert!(close(device.motion.lowest as f64, cpu.lowest as f64, 1e-6));
        let stretch = strain(&scene, &state);
        assert!(stretch > 0.01, "the jitter stretches springs");
        assert!(
            close(device.strain as f64, stretch as f64, 1e-5),
            "{device:?} {stretch}"
        );
        let last = state.pos.len() - 1;
        for (which, value) in [(0, f32::NAN), (1, f32::INFINITY)] {
            let mut bad = state.clone();
            match which {
                0 => bad.vel[last].y = value,
                _ => bad.pos[last / 2].x = value,
            }
            assert!(!measured(&bad).motion.finite, "{which}: {value}");
        }
    }

    /// The bench cloth (16 particles a side) is a grid: its substep gathers the springs from
    /// the index, and ends where the gather over the spring ends takes it, to 10⁻⁶ m after
    /// 1 s (the sums in another order; measured 0.48 µm); with each link given the next
    /// one's rest length it ends 2.2 m away.
    #[test]
    fn the_grid_gather_steps_the_cloth_the_general_one_does() {
        let gpu = HeadlessDevice::open(AdapterPreference::Software).expect("an adapter");
        let scene =
            crate::bench::bench_scene(16, IntegratorKind::SemiImplicitEuler).expect("scene");
        let (model, params) = (&scene.model, &scene.params);
        let run = |grid: bool| {
            let mut stepper =
                GpuStepper::new(&gpu.device, &gpu.queue, model, params, &scene.effects, true)
                    .expect("stepper");
            assert_eq!(
                stepper.params.grid[0], 16,
                "the bench cloth is found a grid"
            );
            if !grid {
                stepper.grid_path = false;
                stepper.sent = None;
                stepper.configure(model, params, &scene.effects, Changes::STRENGTHS);
                assert_eq!(stepper.params.grid[0], 0);
            }
            let mut state = scene.initial.clone();
            for _ in 0..60 {
                stepper.frame(model, &mut state).expect("frame");
            }
            state
        };
        let (grid, general) = (run(true), run(false));
        let worst = (grid.pos.iter().zip(&general.pos))
            .map(|(a, b)| a.distance(*b))
            .fold(0.0f32, f32::max);
        let moved = (grid.pos.iter().zip(&scene.initial.pos))
            .map(|(a, b)| a.distance(*b))
            .fold(0.0f32, f32::max);
        eprintln!("grid against general: {worst:e} m of {moved} m");
        assert!(moved > 0.005 && worst < 1e-6, "{worst} m apart");
    }

    /// A strength change that keeps which springs share a class (every kind scaled alike,
    /// or the damping of a kind that has a class of its own) sends only the class table;
    /// one that splits or merges classes sends the ends again, once.
    #[test]
    fn the_spring_ends_are_sent_again_only_when_their_classes_change() {
        use crate::device::{AdapterPreference, HeadlessDevice};
        let gpu = HeadlessDevice::open(AdapterPreference::Software).expect("an adapter");
        // The bench scene: one stiffness and damping for every kind of spring.
        let scene = crate::scene::Scene::builtin("hanging-bench").expect("scene");
        let (model, effects) = (&scene.model, &scene.effects);
        let mut params = scene.params.clone();
        let mut stepper = GpuStepper::new(&gpu.device, &gpu.queue, model, &params, effects, true)
            .expect("stepper");
        let mut change = |edit: &dyn Fn(&mut SimParams), sends: u32| {
            let before = params.clone();
            edit(&mut params);
            stepper.configure(model, &params, effects, before.changes_to(&params));
            assert_eq!(
                stepper.ends_sent, sends,
                "after {:?}",
                params.material.stiffness
            );
        };
        change(&|_| (), 1);
        change(
            &|p| p.material.stiffness = p.material.stiffness.map(|k| 3.0 * k),
            1,
        );
        // The shear springs leave the one class all kinds shared: a class of their own,
        // whose damping then moves alone.
        change(&|p| p.material.stiffness[1] *= 0.5, 2);
        change(&|p| p.material.damping[1] *= 2.0, 2);
        // The structural springs leave the bend springs' class.
        change(&|p| p.material.stiffness[0] *= 2.0, 3);
        // Back to one stiffness (shear still damped apart), then one strength: merges.
        change(&|p| p.material.stiffness = [p.material.stiffness[0]; 3], 4);
        change(&|p| p.material.damping = [p.material.damping[0]; 3], 5);
        change(&|_| (), 5);
        // The bend springs switched off: their ends go.
        let unbent = unbent(effects);
        stepper.configure(model, &params, &unbent, Changes::EFFECTS);
        assert_eq!(stepper.ends_sent, 6);
    }

    /// The 16 × 16 bench cloth under semi-implicit Euler, with the guard on.
    fn guarded_bench() -> Scene {
        let mut scene =
            crate::bench::bench_scene(16, IntegratorKind::SemiImplicitEuler).expect("scene");
        scene.params.guard.enabled = true;
        scene
    }

    /// A stepper for `scene` on `gpu`'s device, reading back every frame.
    fn stepper_on(gpu: &HeadlessDevice, scene: &Scene) -> GpuStepper {
        let (model, params, effects) = (&scene.model, &scene.params, &scene.effects);
        GpuStepper::new(&gpu.device, &gpu.queue, model, params, effects, true).expect("stepper")
    }

    /// A device of the first adapter with its compute limits changed by `limit`.
    fn limited_device(limit: impl FnOnce(&mut wgpu::Limits)) -> (wgpu::Device, wgpu::Queue) {
        let gpu = HeadlessDevice::open(AdapterPreference::Software).expect("an adapter");
        let mut limits = crate::device::compute_limits(&gpu.adapter);
        limit(&mut limits);
        pollster::block_on(gpu.adapter.request_device(&wgpu::DeviceDescriptor {
            required_limits: limits,
            ..Default::default()
        }))
        .expect("a device with those limits")
    }

    /// Steps `scene` one frame on `device` (the semi-implicit step runs), switches to `kind`
    /// and returns why each of the next two frames failed; they keep the state.
    fn refused_on_switch(
        (device, queue): &(wgpu::Device, wgpu::Queue),
        scene: &Scene,
        kind: IntegratorKind,
    ) -> Vec<String> {
        let (model, effects) = (&scene.model, &scene.effects);
        let mut params = scene.params.clone();
        let mut stepper = GpuStepper::new(device, queue, model, &params, effects, true)
            .expect("the semi-implicit step runs");
        let mut state = scene.initial.clone();
        stepper.frame(model, &mut state).expect("a frame");
        let before = state.clone();
        params.step.integrator = kind;
        stepper.configure(model, &params, effects, Changes::INTEGRATOR);
        (0..2)
            .map(|_| {
                let err = stepper.frame(model, &mut state).expect_err("refused");
                assert_eq!(state.pos, before.pos);
                err.reason
            })
            .collect()
    }

    /// On a device that binds at most 32 KiB, the 16 × 16 bench cloth's state and spring
    /// ends fit (8 and 22 KiB) but XPBD's constraints (36 KiB), VBD's stencil (55 KiB) and
    /// implicit Euler's solve (41 KiB) do not: switching to any of them fails the next frame
    /// with the sizes, keeps the state, and every later frame says the same, where the
    /// buffers would have failed validation.
    #[test]
    fn a_solver_too_big_for_the_device_is_refused_with_its_size() {
        let small = limited_device(|l| {
            l.max_storage_buffer_binding_size = 32 << 10;
            l.max_buffer_size = 32 << 10;
        });
        let scene = guarded_bench();
        for (kind, what) in [
            (IntegratorKind::Xpbd, "XPBD constraints"),
            (IntegratorKind::Vbd, "VBD stencil"),
            (IntegratorKind::ImplicitEuler, "implicit Euler's solve"),
        ] {
            for said in refused_on_switch(&small, &scene, kind) {
                assert!(
                    said.contains(what) && said.contains("(32768 bytes)"),
                    "{said}"
                );
            }
        }
    }

    /// Implicit Euler's solve binds an eighth storage buffer (its indirect dispatches'
    /// counts): on a device that offers seven a stage, the substep runs but switching to
    /// implicit Euler fails the next frames with the counts, keeping the state.
    #[test]
    fn implicit_euler_on_a_device_with_seven_storage_buffers_is_refused() {
        let seven = limited_device(|l| l.max_storage_buffers_per_shader_stage = 7);
        let scene = guarded_bench();
        for said in refused_on_switch(&seven, &scene, IntegratorKind::ImplicitEuler) {
            assert!(
                said.contains("8 storage buffers") && said.contains("offers 7"),
                "{said}"
            );
        }
    }

    /// A device lost mid-run (destroyed here) stops the run with the device's message and
    /// keeps the last state the caller had; every later frame says the same.
    #[test]
    fn a_lost_device_stops_the_run_and_keeps_the_last_state() {
        let gpu = HeadlessDevice::open(AdapterPreference::Software).expect("an adapter");
        let scene = guarded_bench();
        let model = &scene.model;
        let mut stepper = stepper_on(&gpu, &scene);
        let mut state = scene.initial.clone();
        for _ in 0..3 {
            stepper.frame(model, &mut state).expect("a frame");
        }
        let kept = state.clone();
        gpu.device.destroy();
        for _ in 0..2 {
            let err = stepper.frame(model, &mut state).expect_err("no device");
            eprintln!("{err}");
            assert_eq!(err.cause, crate::sim::Cause::Backend, "{err}");
            assert_eq!(state.pos, kept.pos);
        }
    }
}
