//! The simulation's own thread. The UI keeps a replica of the simulation for everything it
//! shows and edits (parameters, effects, pins, the latest finished state); the stepping
//! thread owns the copy that steps. Every edit is applied to both, in the order it was made;
//! the thread steps the frames the UI's clock says are due and publishes each finished
//! state, which the UI adopts on its next frame. So the UI never waits for a frame to be
//! computed: a slider or an orbit stays smooth however long a frame takes.
//!
//! A backend that steps a copy of its own (the GPU backend, which the view draws from
//! directly) is read back only now and then: every [`SYNC_EVERY`] while running and once
//! the stepping stops (for the kinetic energy shown), after every edit, and when the UI asks
//! ([`SimThread::catch_up`]: picking, export).
//!
//! Where the user turned the exact intersection check on, the thread runs it after every
//! frame it steps (reading a GPU backend's copy back first), so the UI never waits for it.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender, TryRecvError};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::cloth::ClothState;
use crate::scene::Simulation;
use crate::sim::{GuardEvent, IntegratorKind, Intersections, PhaseTimings};

/// Frames the stepping thread may owe at most; beyond, the backlog is dropped and the run
/// is reported as slower than real time (a quarter of a second at 60 frames per second).
const MAX_BACKLOG: u32 = 15;

/// While a backend's own copy runs ahead of the state, the state is read back this often.
const SYNC_EVERY: Duration = Duration::from_millis(250);
/// ... and once no job came for this long after a frame (the run paused or stepped once).
const SYNC_WHEN_STILL: Duration = Duration::from_millis(30);

/// A change to the simulation; `Some(text)` is an error to show.
pub(super) type Edit = Box<dyn FnOnce(&mut Simulation) -> Option<String> + Send>;

enum Job {
    Edit(Edit),
    /// Frames that became due.
    Advance(u32),
    /// Forget the frames owed (paused).
    Hold,
    Quit,
}

/// What the stepping thread's copy has in effect now.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InEffect {
    /// "cpu" or "gpu".
    pub backend: &'static str,
    /// Substeps per frame: the requested count, or more if the guard raised it.
    pub substeps: u32,
    /// The substep, seconds.
    pub substep_length: f32,
    /// The requested integrator, or the guard's fallback.
    pub integrator: IntegratorKind,
    /// The pairs of the cloth prescribed motion (a grab, pins, a handle) forced together
    /// since the simulation began (0 without self-collision).
    pub forced: u64,
}

impl InEffect {
    /// Whether the copy steps on the GPU (its state is then read back only now and then,
    /// and the view draws from the GPU's buffer).
    pub fn on_gpu(&self) -> bool {
        self.backend == "gpu"
    }

    fn of(sim: &Simulation) -> Self {
        Self {
            backend: sim.backend_name(),
            substeps: sim.substeps(),
            substep_length: sim.substep_length(),
            integrator: sim.integrator_in_effect(),
            forced: sim.forced_pairs().unwrap_or(0),
        }
    }
}

/// What the stepping thread reports; the UI takes it once per frame.
pub(super) struct Report {
    /// Jobs done, in the order sent.
    pub done: u64,
    /// No frames owed and the state is current: the thread waits for the next job.
    pub idle: bool,
    /// The latest finished state, the frames at it, and the jobs done when it was
    /// published; `fresh` until the UI took it.
    pub state: ClothState,
    pub frames: u64,
    pub state_done: u64,
    pub fresh: bool,
    /// What happened since the UI last took it.
    pub news: News,
    pub in_effect: InEffect,
}

/// What happened on the stepping thread since the UI last looked.
#[derive(Default)]
pub(super) struct News {
    /// Frames stepped, their timings and guard events.
    pub stepped: u32,
    pub timings: PhaseTimings,
    pub guard_events: Vec<GuardEvent>,
    /// A frame that could not be stepped (the thread stopped stepping until asked again).
    pub failed: Option<String>,
    /// Errors from edits (a backend that could not be changed).
    pub notes: Vec<String>,
    /// Frames became due while more than one was still owed, or a backlog was dropped:
    /// the simulation runs slower than real time.
    pub behind: bool,
    /// What the intersection check found after the frames it checked (none: it checked
    /// none since the UI last looked, or only frames of a run since replaced).
    pub checked: Option<Checked>,
    /// The jobs done when the first and the last of those frames were checked.
    checked_at: [u64; 2],
}

/// What the exact intersection check found after some frames.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Checked {
    /// After the latest of them.
    pub last: Intersections,
    /// The most of each count after any of them.
    pub most: Intersections,
}

impl Checked {
    /// `self`, and then `later`: what was found after frames checked after these.
    pub fn then(self, later: Checked) -> Checked {
        Checked {
            most: self.most.max(&later.most),
            last: later.last,
        }
    }

    /// Sets `found` to what it held, and then `later` ([`Checked::then`]; `later` alone
    /// where it held nothing).
    pub fn add(found: &mut Option<Checked>, later: Checked) {
        *found = Some(match found.take() {
            Some(before) => before.then(later),
            None => later,
        });
    }
}

impl From<Intersections> for Checked {
    fn from(found: Intersections) -> Checked {
        Checked {
            most: found.clone(),
            last: found,
        }
    }
}

struct Shared {
    report: Mutex<Report>,
    changed: Condvar,
    /// Whether the frames stepped from now on are checked for intersections.
    check: AtomicBool,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, Report> {
        self.report.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// The stepping thread and the UI's end of it.
pub(super) struct SimThread {
    jobs: Sender<Job>,
    shared: Arc<Shared>,
    handle: Option<JoinHandle<()>>,
    /// Jobs sent so far.
    sent: u64,
    /// The job count from which published states include the last edit that replaced the
    /// state outright (a reset, a new scene): earlier ones are not shown.
    barrier: u64,
}

impl SimThread {
    /// Starts a thread stepping `sim` (the UI keeps its own replica).
    pub fn start(sim: Simulation) -> Self {
        let shared = Arc::new(Shared {
            report: Mutex::new(Report {
                done: 0,
                idle: true,
                state: sim.state().clone(),
                frames: sim.frames(),
                state_done: 0,
                fresh: false,
                news: News::default(),
                in_effect: InEffect::of(&sim),
            }),
            changed: Condvar::new(),
            check: AtomicBool::new(false),
        });
        let (jobs, rx) = mpsc::channel();
        let worker = Arc::clone(&shared);
        let handle = std::thread::Builder::new()
            .name("clothsim-step".into())
            .spawn(move || run(sim, &rx, &worker))
            .ok();
        Self {
            jobs,
            shared,
            handle,
            sent: 0,
            barrier: 0,
        }
    }

    fn send(&mut self, job: Job) -> Result<(), String> {
        self.jobs
            .send(job)
            .map_err(|_| "the simulation thread stopped; reset or switch scene".to_string())?;
        self.sent += 1;
        Ok(())
    }

    /// Applies `edit` on the stepping thread after everything sent before it.
    pub fn edit(&mut self, edit: Edit) -> Result<(), String> {
        self.send(Job::Edit(edit))
    }

    /// Like [`SimThread::edit`] for an edit that replaces the state outright: states
    /// finished before it are no longer shown.
    pub fn edit_state(&mut self, edit: Edit) -> Result<(), String> {
        self.send(Job::Edit(edit))?;
        self.barrier = self.sent;
        Ok(())
    }

    /// `frames` more frames are due.
    pub fn advance(&mut self, frames: u32) -> Result<(), String> {
        self.send(Job::Advance(frames))
    }

    /// Drops the frames owed.
    pub fn hold(&mut self) -> Result<(), String> {
        self.send(Job::Hold)
    }

    /// What happened since the last call, and what is in effect; shows the latest state
    /// (through `adopt`) only if it includes every state-replacing edit.
    pub fn take(&mut self, mut adopt: impl FnMut(&ClothState, u64)) -> (News, InEffect) {
        let mut r = self.shared.lock();
        if r.fresh && r.state_done >= self.barrier {
            adopt(&r.state, r.frames);
            r.fresh = false;
        }
        let mut news = std::mem::take(&mut r.news);
        // What was found in a run since replaced is not this one's: where the frames
        // checked run across the replacement, only the last is kept.
        let [first, last] = news.checked_at;
        if first < self.barrier {
            news.checked = (news.checked.take())
                .filter(|_| last >= self.barrier)
                .map(|c| c.last.into());
        }
        (news, r.in_effect)
    }

    /// Has the thread bring its state up to date with its backend's own copy (after the
    /// frame it is stepping, not the ones owed after it) and waits until it published it,
    /// or stopped. For what must see the frame the view shows (picking on the GPU backend,
    /// whose state is otherwise read back only now and then).
    pub fn catch_up(&mut self) -> Result<(), String> {
        // The thread syncs after every edit.
        self.edit(Box::new(|_| None))?;
        let sent = self.sent;
        self.wait_until(|r| r.done >= sent);
        Ok(())
    }

    /// Checks every frame stepped from now on for intersections, or none (`on` false).
    pub fn check_intersections(&self, on: bool) {
        self.shared.check.store(on, Ordering::Relaxed);
    }

    /// What the stepping copy has in effect, as last published.
    pub fn in_effect(&self) -> InEffect {
        self.shared.lock().in_effect
    }

    /// Waits until the thread has done every job sent and owes no frames (tests, and
    /// anything that must see the result of a step), or it stopped.
    pub fn settle(&self) {
        let sent = self.sent;
        self.wait_until(|r| r.done >= sent && r.idle);
    }

    /// Waits until the thread's report satisfies `ready`, or the thread stopped.
    fn wait_until(&self, ready: impl Fn(&Report) -> bool) {
        let mut r = self.shared.lock();
        while !ready(&r) {
            if self.handle.as_ref().is_none_or(|h| h.is_finished()) {
                return;
            }
            r = match (self.shared.changed).wait_timeout(r, Duration::from_millis(50)) {
                Ok((r, _)) => r,
                Err(e) => e.into_inner().0,
            };
        }
    }
}

impl Drop for SimThread {
    fn drop(&mut self) {
        let _ = self.jobs.send(Job::Quit);
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

/// The stepping thread: applies jobs in order, steps one owed frame at a time (taking new
/// jobs between frames) and publishes after each.
fn run(mut sim: Simulation, jobs: &Receiver<Job>, shared: &Shared) {
    let (mut owed, mut done) = (0u32, 0u64);
    let mut synced = Instant::now();
    loop {
        let job = if owed == 0 {
            let next = if sim.state_behind() {
                jobs.recv_timeout(SYNC_WHEN_STILL)
            } else {
                jobs.recv().map_err(|_| RecvTimeoutError::Disconnected)
            };
            match next {
                Ok(job) => Some(job),
                Err(RecvTimeoutError::Timeout) => {
                    let mut published = Published::default();
                    sync(&mut sim, &mut synced, &mut published);
                    published.write(&mut sim, shared, done, owed);
                    continue;
                }
                Err(RecvTimeoutError::Disconnected) => return,
            }
        } else {
            match jobs.try_recv() {
                Ok(job) => Some(job),
                Err(TryRecvError::Empty) => None,
                Err(TryRecvError::Disconnected) => return,
            }
        };
        let mut published = Published::default();
        match job {
            Some(Job::Quit) => return,
            Some(Job::Edit(edit)) => {
                done += 1;
                published.note = edit(&mut sim);
                // A backend with its own copy takes the edited state now (what it draws).
                sync(&mut sim, &mut synced, &mut published);
            }
            Some(Job::Advance(n)) => {
                done += 1;
                let want = owed.saturating_add(n);
                published.behind = owed > 1 || want > MAX_BACKLOG;
                owed = want.min(MAX_BACKLOG);
            }
            Some(Job::Hold) => {
                done += 1;
                owed = 0;
            }
            None => {
                owed -= 1;
                let outcome = sim.step_frame();
                published.stepped = true;
                published.state = true;
                let check = shared.check.load(Ordering::Relaxed);
                if let Err(e) = outcome {
                    published.failed = Some(format!("{e} Paused."));
                } else if check || synced.elapsed() >= SYNC_EVERY {
                    // The check reads the state: a backend's own copy is read back first.
                    sync(&mut sim, &mut synced, &mut published);
                }
                if check && published.failed.is_none() {
                    published.checked = Some(sim.intersections());
                }
            }
        }
        if published.failed.is_some() {
            owed = 0;
        }
        published.write(&mut sim, shared, done, owed);
    }
}

/// Brings the state up to date with the backend's own copy (or the copy with the state),
/// to be published.
fn sync(sim: &mut Simulation, synced: &mut Instant, published: &mut Published) {
    if let Err(e) = sim.sync_state() {
        published.failed = Some(format!("{e} Paused."));
    }
    *synced = Instant::now();
    published.state = true;
}

/// What one pass of the stepping loop has to publish.
#[derive(Default)]
struct Published {
    state: bool,
    stepped: bool,
    behind: bool,
    failed: Option<String>,
    note: Option<String>,
    checked: Option<Intersections>,
}

impl Published {
    fn write(self, sim: &mut Simulation, shared: &Shared, done: u64, owed: u32) {
        let (timings, events) = if self.stepped {
            (sim.take_timings(), sim.take_guard_events())
        } else {
            (PhaseTimings::default(), Vec::new())
        };
        {
            let mut r = shared.lock();
            r.done = done;
            r.idle = owed == 0 && !sim.state_behind();
            if self.state {
                r.state.clone_from(sim.state());
                r.frames = sim.frames();
                r.state_done = done;
                r.fresh = true;
            }
            let news = &mut r.news;
            if self.stepped {
                news.stepped += 1;
                news.timings.merge(&timings);
                news.guard_events.extend(events);
            }
            if let Some(f) = self.failed {
                news.failed = Some(f);
            }
            news.notes.extend(self.note);
            news.behind |= self.behind;
            if let Some(found) = self.checked {
                if news.checked.is_none() {
                    news.checked_at[0] = done;
                }
                Checked::add(&mut news.checked, found.into());
                news.checked_at[1] = done;
            }
            r.in_effect = InEffect::of(sim);
        }
        shared.changed.notify_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    fn hanging() -> Simulation {
        Simulation::new(Scene::builtin("hanging").unwrap())
    }

    /// Holds the thread inside an edit (a frame that takes long) until the returned sender
    /// sends.
    fn keep_busy(thread: &mut SimThread) -> mpsc::Sender<()> {
        let (go, wait) = mpsc::channel::<()>();
        thread
            .edit(Box::new(move |_| {
                let _ = wait.recv();
                None
            }))
            .unwrap();
        go
    }

    /// The replica's view of the thread after it settled: the adopted state and frames.
    fn settled(thread: &mut SimThread, replica: &mut Simulation) -> (News, InEffect) {
        thread.settle();
        thread.take(|state, frames| replica.adopt_state(state, frames))
    }

    /// Frames are checked for intersections only while the check is on (the hanging
    /// cloth: none found, and no solid); what was checked in a run replaced since is not
    /// reported.
    #[test]
    fn the_thread_checks_the_frames_it_steps_while_asked() {
        let mut replica = hanging();
        let mut thread = SimThread::start(replica.fork());
        thread.advance(2).unwrap();
        assert_eq!(settled(&mut thread, &mut replica).0.checked, None);
        thread.check_intersections(true);
        thread.advance(3).unwrap();
        let (news, _) = settled(&mut thread, &mut replica);
        assert_eq!((news.stepped, news.checked), (3, Some(Checked::default())));
        // Checked, then the run replaced before the UI looked.
        thread.advance(1).unwrap();
        thread.settle();
        thread
            .edit_state(Box::new(|s| {
                s.reset();
                None
            }))
            .unwrap();
        assert_eq!(settled(&mut thread, &mut replica).0.checked, None);
        thread.check_intersections(false);
        thread.advance(2).unwrap();
        assert_eq!(settled(&mut thread, &mut replica).0.checked, None);
    }

    /// The hanging scene with a strip (held by two corners) and a free square through it.
    fn crossed() -> Scene {
        let dir = tempfile::tempdir().unwrap();
        let obj = dir.path().join("crossed.obj");
        let crossed = "v -1 0 -0.2\nv 1 0 -0.2\nv 1 0 0.2\nv -1 0 0.2\n\
                       v -0.2 -0.2 0\nv 0.2 -0.2 0\nv 0.2 0.2 0\nv -0.2 0.2 0\n\
                       f 1 2 3\nf 1 3 4\nf 5 6 7\nf 5 7 8\n";
        std::fs::write(&obj, crossed).unwrap();
        let options = crate::mesh::ImportOptions::default();
        Scene::open_resized("hanging", Some(&obj), &options, None).unwrap()
    }

    /// Frames checked on both sides of a run's replacement before the UI looked: only the
    /// last frame's counts are reported (the most would mix the two runs): a strip with a
    /// square through it (the hanging scene with that cloth), then the plain hanging cloth.
    #[test]
    fn counts_checked_across_a_replacement_keep_only_the_last() {
        let scene = crossed();
        let mut replica = Simulation::new(scene);
        let mut thread = SimThread::start(replica.fork());
        thread.check_intersections(true);
        thread.advance(1).unwrap();
        let (news, _) = settled(&mut thread, &mut replica);
        let through = news.checked.expect("checked").last;
        assert!(through.self_pairs > 0, "{through:?}");
        thread.advance(2).unwrap();
        thread.settle();
        thread
            .edit_state(Box::new(|s| {
                *s = hanging();
                None
            }))
            .unwrap();
        thread.advance(1).unwrap();
        let (news, _) = settled(&mut thread, &mut replica);
        assert_eq!(news.checked, Some(Checked::default()));
    }

    #[test]
    fn frames_stepped_on_the_thread_are_the_frames_a_direct_run_steps() {
        let mut direct = hanging();
        let mut replica = hanging();
        let mut thread = SimThread::start(replica.fork());
        // An edit takes effect at the next frame boundary after it arrives: here, after the
        // third frame.
        thread.advance(3).unwrap();
        thread.settle();
        // More air damping, 0.5 → 2 1/s.
        let more_drag = |s: &mut Simulation| {
            let mut effects = s.effects().to_vec();
            for e in &mut effects {
                if let crate::sim::Effect::AirDamping(a) = e {
                    a.rate = 2.0;
                }
            }
            s.set_effects(effects)
        };
        thread
            .edit(Box::new(move |s| more_drag(s).err().map(|e| e.to_string())))
            .unwrap();
        thread.advance(2).unwrap();
        let (taken, _) = settled(&mut thread, &mut replica);
        for _ in 0..3 {
            direct.step_frame().unwrap();
        }
        more_drag(&mut direct).unwrap();
        for _ in 0..2 {
            direct.step_frame().unwrap();
        }
        assert_eq!(replica.frames(), 5);
        assert_eq!(taken.stepped, 5);
        let same =
            replica.state().pos == direct.state().pos && replica.state().vel == direct.state().vel;
        assert!(same, "the thread's frames differ from a direct run's");
        assert!(taken.timings.get("springs").is_some_and(|p| p.calls > 0));
        assert!(!taken.behind);
    }

    #[test]
    fn a_state_from_before_a_reset_is_never_shown() {
        let mut replica = hanging();
        let mut thread = SimThread::start(replica.fork());
        // The thread is held inside an edit while it has a stepped state published.
        thread.advance(2).unwrap();
        thread.settle();
        let go = keep_busy(&mut thread);
        replica.reset();
        thread
            .edit_state(Box::new(|s| {
                s.reset();
                None
            }))
            .unwrap();
        // The published state has 2 frames but predates the reset: not adopted.
        let mut adopted = false;
        let _ = thread.take(|_, _| adopted = true);
        assert!(!adopted, "a stale state was shown");
        assert_eq!(replica.frames(), 0);
        go.send(()).unwrap();
        settled(&mut thread, &mut replica);
        assert_eq!(replica.frames(), 0);
        assert_eq!(replica.state().pos, replica.initial().pos);
    }

    /// Story: the UI must never wait for the simulation. With the thread stuck in a long
    /// frame (here: held inside an edit), the UI still takes reports at once and its edits
    /// queue; they are applied, in order, when the thread is free.
    #[test]
    fn the_ui_never_waits_for_a_busy_simulation() {
        let mut replica = hanging();
        let mut thread = SimThread::start(replica.fork());
        let go = keep_busy(&mut thread);
        thread.advance(4).unwrap();
        for substeps in [50, 60, 70] {
            let (taken, _) = thread.take(|_, _| {});
            assert_eq!(taken.stepped, 0, "nothing finished while busy");
            thread
                .edit(Box::new(move |s| {
                    let mut p = s.params().clone();
                    p.step.substeps = substeps;
                    s.set_params(p).err().map(|e| e.to_string())
                }))
                .unwrap();
        }
        go.send(()).unwrap();
        let (taken, in_effect) = settled(&mut thread, &mut replica);
        assert_eq!(in_effect.substeps, 70, "the last edit is in effect");
        assert_eq!(taken.stepped, 4);
    }

    #[test]
    fn a_backlog_beyond_a_quarter_second_is_dropped_and_reported() {
        let mut replica = hanging();
        let mut thread = SimThread::start(replica.fork());
        thread.advance(100).unwrap();
        let (taken, _) = settled(&mut thread, &mut replica);
        assert_eq!(taken.stepped, MAX_BACKLOG);
        assert_eq!(replica.frames(), MAX_BACKLOG as u64);
        assert!(taken.behind, "slower than real time is said");
        // Holding drops what is owed.
        let go = keep_busy(&mut thread);
        thread.advance(5).unwrap();
        thread.hold().unwrap();
        go.send(()).unwrap();
        let (taken, _) = settled(&mut thread, &mut replica);
        assert_eq!(taken.stepped, 0);
        assert!(!taken.behind);
    }

    #[test]
    fn a_frame_that_cannot_be_saved_stops_the_stepping_and_says_why() {
        let mut scene = Scene::builtin("hanging").unwrap();
        scene.params.step.integrator = IntegratorKind::ExplicitEuler;
        scene.params.step.substeps = 1;
        scene.params.guard.max_refinements = 0;
        scene.params.guard.fallback = None;
        let mut replica = Simulation::new(scene);
        let mut thread = SimThread::start(replica.fork());
        thread.advance(10).unwrap();
        let (taken, _) = settled(&mut thread, &mut replica);
        let failed = taken.failed.expect("the failure is reported");
        assert!(failed.ends_with("Paused."), "{failed}");
        assert!(taken.stepped < 10, "it stopped at the failing frame");
        assert!(replica.state().is_finite(), "the last good state is shown");
    }

    /// On the GPU backend, as the window runs it (its state not read back every frame),
    /// each frame checked is the GPU's: a square starts through a strip and flies out of it
    /// at 10 m/s (two frames of 1/60 s take it past its half-width), so the first frame is
    /// counted crossed and the third clear (checking the state at the start, not read
    /// back, counts all three crossed).
    #[test]
    fn the_thread_checks_the_gpus_frames() {
        let mut scene = crossed();
        // The square (the last four particles, free; the strip hangs by two corners).
        for p in 4..8 {
            assert!(scene.model.inv_mass[p] > 0.0, "particle {p} is free");
            scene.initial.vel[p] = glam::Vec3::new(0.0, 10.0, 0.0);
        }
        let mut replica = Simulation::new(scene.clone());
        let software = crate::device::AdapterPreference::Software;
        let (gpu, _) = crate::gpu::gpu_simulation_on(scene, false, software).expect("GPU backend");
        let mut thread = SimThread::start(gpu);
        thread.check_intersections(true);
        thread.advance(3).unwrap();
        let (news, _) = settled(&mut thread, &mut replica);
        let checked = news.checked.expect("checked");
        assert_eq!(news.stepped, 3);
        assert!(checked.most.self_pairs > 0, "{checked:?}");
        assert_eq!(checked.last, Default::default(), "{checked:?}");
    }

    /// On a backend that steps its own copy (the GPU, not read back every frame),
    /// `catch_up` publishes the state of the latest frame at once: the UI picks what the view
    /// shows.
    #[test]
    fn catch_up_publishes_the_gpu_state_of_the_latest_frame() {
        let scene = crate::bench::bench_scene(16, IntegratorKind::SemiImplicitEuler).unwrap();
        let (gpu, _) = crate::gpu::gpu_simulation(scene.clone(), false).expect("GPU backend");
        let (mut direct, mut replica) = (Simulation::new(scene.clone()), Simulation::new(scene));
        let mut thread = SimThread::start(gpu);
        thread.advance(3).unwrap();
        // Once the third frame is published (its positions not read back yet, unless the
        // thread's own timer came first), catch up.
        for _ in 0..10_000 {
            thread.take(|state, frames| replica.adopt_state(state, frames));
            if replica.frames() == 3 {
                break;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        thread.catch_up().unwrap();
        thread.take(|state, frames| replica.adopt_state(state, frames));
        for _ in 0..3 {
            direct.step_frame().unwrap();
        }
        assert_eq!(replica.frames(), 3);
        let worst = (replica.state().pos.iter().zip(&direct.state().pos))
            .map(|(a, b)| a.distance(*b))
            .fold(0.0f32, f32::max);
        assert!(
            worst < 1e-5,
            "the published state is {worst} m from the latest frame"
        );
    }
}
