//! A small team of threads that stays awake between the many tiny parallel sections of a
//! simulation step.
//!
//! A substep of a 64 × 64 cloth is tens of microseconds of work, split a few times between
//! threads. On the 2-core virtual machine this was measured on, rayon's fork–join gained
//! nothing there: its idle workers yield and fall asleep between sections, and waking one
//! costs about as much as the work. A team's helpers instead spin for a while after each
//! section (a fraction of a millisecond, so a running simulation keeps them awake and an
//! idle one lets them sleep), and a section is handed over by bumping a counter.
//!
//! Work is split by a member's index only, never by who finishes first, so callers that
//! give each member a fixed share get the same result on any number of threads. A share is
//! *claimed* before it runs: its helper claims it as it arrives, and the caller, done with
//! its own, claims and runs those no helper came for. On a virtual machine whose cores other
//! guests also use, a helper is now and then held off its core for milliseconds; the section
//! then takes twice the caller's time instead of waiting for it.
//!
//! On such a machine the helpers do not always pay: in a busy spell a 64 × 64 cloth stepped
//! faster on one thread than on two in 9 of 12 alternating runs. So a team times its
//! sections and, now and then, runs a short window of them on the caller alone (`Pace`);
//! while that is faster, the caller goes on alone, and tries its helpers again later. Which
//! way a section runs never changes its result (the shares are the same either way).

use std::any::Any;
use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, OnceLock, TryLockError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::pace::Pace;
use super::ranges::share;

/// How long a helper spins for the next section before it sleeps.
const SPIN: Duration = Duration::from_micros(300);
/// Most members a team has.
const MAX_MEMBERS: usize = 16;

/// A section: called once per member with the member's index.
type Section<'a> = dyn Fn(usize) + Sync + 'a;

/// What the caller and the helpers share.
struct Shared {
    /// Bumped to hand a new section over.
    epoch: AtomicUsize,
    /// The current section (a `*const &Section`, valid until every helper is done).
    section: AtomicPtr<()>,
    /// Shares of the current section done (the caller's own not counted).
    done: AtomicUsize,
    /// Per share: the last epoch it was claimed in (see [`claim`]).
    claims: [AtomicUsize; MAX_MEMBERS],
    /// Helpers leave every share to the caller (tests of the caller's claims).
    #[cfg(test)]
    helpers_stay_away: AtomicBool,
    /// Helpers asleep (or about to be), so the caller knows it must wake them.
    asleep: AtomicUsize,
    stop: AtomicBool,
    /// A helper's panic, passed on to the caller.
    panic: Mutex<Option<Box<dyn Any + Send>>>,
    bed: Mutex<()>,
    wake: Condvar,
}

/// A team of `members` threads: the caller and `members − 1` helpers.
pub struct Team {
    shared: Arc<Shared>,
    helpers: Vec<JoinHandle<()>>,
    /// Taken by the caller of a section: a second caller at the same time runs alone.
    /// Holds the timing that decides whether the helpers pay.
    busy: Mutex<Pace>,
}

impl Team {
    /// A team of `members` (at least 1, at most 16) threads.
    pub fn new(members: usize) -> Self {
        let members = members.clamp(1, MAX_MEMBERS);
        let shared = Arc::new(Shared {
            epoch: AtomicUsize::new(0),
            section: AtomicPtr::new(std::ptr::null_mut()),
            done: AtomicUsize::new(0),
            claims: [const { AtomicUsize::new(0) }; MAX_MEMBERS],
            #[cfg(test)]
            helpers_stay_away: AtomicBool::new(false),
            asleep: AtomicUsize::new(0),
            stop: AtomicBool::new(false),
            panic: Mutex::new(None),
            bed: Mutex::new(()),
            wake: Condvar::new(),
        });
        // Helpers are members 1, 2, … (as many as could be started).
        let helpers = (1..members)
            .map_while(|index| {
                let shared = Arc::clone(&shared);
                std::thread::Builder::new()
                    .name(format!("clothsim-team-{index}"))
                    .spawn(move || helper(&shared, index))
                    .ok()
            })
            .collect();
        Self {
            shared,
            helpers,
            busy: Mutex::new(Pace::default()),
        }
    }

    /// The shared team for `members` threads (made the first time it is asked for).
    pub fn shared(members: usize) -> &'static Team {
        static TEAMS: [OnceLock<Team>; MAX_MEMBERS] = [const { OnceLock::new() }; MAX_MEMBERS];
        let members = members.clamp(1, MAX_MEMBERS);
        TEAMS[members - 1].get_or_init(|| Team::new(members))
    }

    /// The team for the current rayon pool's thread count (so `--threads` and
    /// `ThreadPool::install` choose it too).
    pub fn current() -> &'static Team {
        Self::shared(rayon::current_num_threads())
    }

    /// How many threads work on a section.
    pub fn members(&self) -> usize {
        self.helpers.len() + 1
    }

    /// Runs `section(i)` for every member `i` at the same time, the caller taking `i = 0`,
    /// and returns when all are done. If another section of this team is running (another
    /// thread's), or while the helpers do not pay (timed: see `Pace`), the caller runs
    /// every member's share itself, in order. A panic in any share is passed on after all
    /// are done.
    pub fn run(&self, section: &Section<'_>) {
        self.run_as(section, Paced::Yes);
    }

    /// [`Team::run`], timed by the pace and run alone while it says so ([`Paced::Yes`]),
    /// or always shared and left out of its timing ([`Paced::No`]).
    fn run_as(&self, section: &Section<'_>, paced: Paced) {
        let mut pace = match self.busy.try_lock() {
            Ok(guard) => guard,
            // A share panicked last time; the team itself is fine.
            Err(TryLockError::Poisoned(poisoned)) => poisoned.into_inner(),
            Err(TryLockError::WouldBlock) => {
                (0..self.members()).for_each(section);
                return;
            }
        };
        if self.helpers.is_empty() {
            section(0);
            return;
        }
        let start = Instant::now();
        let paced = paced == Paced::Yes;
        if paced && pace.runs_alone() {
            (0..self.members()).for_each(section);
            pace.record(start.elapsed());
            return;
        }
        let shared = &*self.shared;
        // The helpers read the section through this pointer until they are done; the wait
        // below (also on unwinding) keeps it alive until then.
        let pointer: *const &Section<'_> = &section;
        shared.section.store(pointer as *mut (), Ordering::SeqCst);
        shared.done.store(0, Ordering::SeqCst);
        let epoch = shared.epoch.fetch_add(1, Ordering::SeqCst) + 1;
        if shared.asleep.load(Ordering::SeqCst) > 0 {
            let _bed = shared.bed.lock().unwrap_or_else(|e| e.into_inner());
            shared.wake.notify_all();
        }
        let waiting = WaitForShares {
            shared,
            others: self.helpers.len(),
        };
        section(0);
        // The shares no helper has come for yet (one held off its core, or asleep).
        for share in 1..self.members() {
            if claim(shared, share, epoch) {
                run_share(shared, section, share);
            }
        }
        drop(waiting);
        if paced {
            pace.record(start.elapsed());
        }
        let panic = shared
            .panic
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take();
        if let Some(payload) = panic {
            resume_unwind(payload);
        }
    }

    /// Runs `work(member, piece)` once for every piece in `0..pieces`, shared between the
    /// members: each first takes its own [`share`] of them, in order, then helps with the
    /// pieces of the others that are still untaken. So a member that comes late (a helper the
    /// machine held off its core for some microseconds) loses only the pieces the others
    /// took meanwhile, not its whole share, while on time each member works on the same
    /// data every section. For work whose result is the same whoever does a piece.
    pub fn run_pieces(&self, pieces: usize, work: &(dyn Fn(usize, usize) + Sync)) {
        self.pieces_as(pieces, work, Paced::Yes);
    }

    /// [`Team::run_pieces`] for work far above what handing a section over costs
    /// (milliseconds, such as self-contact's search of a large cloth): always shared with
    /// the helpers, and left out of the pace's timing. The pace weighs sections of tens of
    /// microseconds, where a helper may not pay; a long one in its window would swamp their
    /// time, and run alone it gave up the helper where it pays most (on a 64 × 64 cloth
    /// landing in `crumple`, 2 threads, 2026-11-26: 1.30 and 1.38 s per simulated second
    /// paced, 1.12 and 1.20 s shared, alternating runs).
    pub fn run_large_pieces(&self, pieces: usize, work: &(dyn Fn(usize, usize) + Sync)) {
        self.pieces_as(pieces, work, Paced::No);
    }

    fn pieces_as(&self, pieces: usize, work: &(dyn Fn(usize, usize) + Sync), paced: Paced) {
        let members = self.members();
        // The next untaken piece of each member's share (on its own cache line, so that a
        // member taking its own pieces does not move the others' counters between cores).
        let next: [Padded; MAX_MEMBERS] =
            std::array::from_fn(|i| Padded(AtomicUsize::new(share(pieces, members, i).start)));
        let section = |i: usize| {
            for owner in (i..members).chain(0..i) {
                let end = share(pieces, members, owner).end;
                loop {
                    let piece = next[owner].0.fetch_add(1, Ordering::Relaxed);
                    if piece >= end {
                        break;
                    }
                    work(i, piece);
                }
            }
        };
        self.run_as(&section, paced);
    }

    /// [`Team::run_pieces`] when `parallel` (and the team has helpers), else every piece in
    /// order on the calling thread, as member 0: for work big enough to share only from
    /// some size on.
    pub fn run_pieces_if(
        &self,
        parallel: bool,
        pieces: usize,
        work: &(dyn Fn(usize, usize) + Sync),
    ) {
        self.pieces_if(parallel, pieces, work, Paced::Yes);
    }

    /// [`Team::run_pieces_if`] for [`Team::run_large_pieces`]' work.
    pub fn run_large_pieces_if(
        &self,
        parallel: bool,
        pieces: usize,
        work: &(dyn Fn(usize, usize) + Sync),
    ) {
        self.pieces_if(parallel, pieces, work, Paced::No);
    }

    fn pieces_if(
        &self,
        parallel: bool,
        pieces: usize,
        work: &(dyn Fn(usize, usize) + Sync),
        paced: Paced,
    ) {
        if parallel && self.members() > 1 {
            self.pieces_as(pieces, work, paced);
        } else {
            (0..pieces).for_each(|piece| work(0, piece));
        }
    }
}

/// Whether a section is timed by the team's pace and may run on the caller alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Paced {
    Yes,
    No,
}

/// A counter alone on its cache line (two lines: neighbouring lines are fetched together).
#[repr(align(128))]
struct Padded(AtomicUsize);

impl Drop for Team {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::SeqCst);
        {
            let _bed = self.shared.bed.lock().unwrap_or_else(|e| e.into_inner());
            self.shared.wake.notify_all();
        }
        for helper in self.helpers.drain(..) {
            let _ = helper.join();
        }
    }
}

/// Claims share `share` of section `epoch` for the thread that calls this: true for exactly
/// one caller per share and section. A share is claimed in every section before the next
/// begins (the caller waits for all), so it holds `epoch − 1` until claimed; a helper late
/// enough to see an old epoch finds it claimed already and runs nothing.
fn claim(shared: &Shared, share: usize, epoch: usize) -> bool {
    shared.claims[share]
        .compare_exchange(
            epoch.wrapping_sub(1),
            epoch,
            Ordering::SeqCst,
            Ordering::SeqCst,
        )
        .is_ok()
}

/// Runs a claimed share (another member's, on a helper or the caller): a panic is kept for
/// the caller, and the share counts as done either way.
fn run_share(shared: &Shared, section: &Section<'_>, share: usize) {
    if let Err(payload) = catch_unwind(AssertUnwindSafe(|| section(share))) {
        *shared.panic.lock().unwrap_or_else(|e| e.into_inner()) = Some(payload);
    }
    shared.done.fetch_add(1, Ordering::SeqCst);
}

/// Waits (when dropped, so also while unwinding) until every other share is done.
struct WaitForShares<'a> {
    shared: &'a Shared,
    /// The shares other than the caller's (one per helper).
    others: usize,
}

impl Drop for WaitForShares<'_> {
    fn drop(&mut self) {
        let mut spins = 0u32;
        while self.shared.done.load(Ordering::SeqCst) < self.others {
            spins = spins.saturating_add(1);
            if spins < 1 << 16 {
                std::hint::spin_loop();
            } else {
                std::thread::yield_now();
            }
        }
    }
}

/// A helper's life: wait for a section, run its share, say so; sleep when idle long.
fn helper(shared: &Shared, index: usize) {
    // The epoch the team was made with (not read here: a section may already be waiting).
    let mut seen = 0;
    loop {
        let idle = Instant::now();
        let mut spins = 0u32;
        while shared.epoch.load(Ordering::SeqCst) == seen {
            if shared.stop.load(Ordering::SeqCst) {
                return;
            }
            spins = spins.wrapping_add(1);
            if !spins.is_multiple_of(64) || idle.elapsed() < SPIN {
                std::hint::spin_loop();
                continue;
            }
            // Asleep until woken (the caller sees `asleep` after bumping the epoch, or this
            // sees the new epoch under the lock); the timeout is only a safety net.
            shared.asleep.fetch_add(1, Ordering::SeqCst);
            let bed = shared.bed.lock().unwrap_or_else(|e| e.into_inner());
            if shared.epoch.load(Ordering::SeqCst) == seen && !shared.stop.load(Ordering::SeqCst) {
                let _ = shared.wake.wait_timeout(bed, Duration::from_millis(50));
            }
            shared.asleep.fetch_sub(1, Ordering::SeqCst);
        }
        seen = shared.epoch.load(Ordering::SeqCst);
        #[cfg(test)]
        if shared.helpers_stay_away.load(Ordering::SeqCst) {
            continue;
        }
        if !claim(shared, index, seen) {
            // The caller ran it (or the section is long over).
            continue;
        }
        let pointer = shared.section.load(Ordering::SeqCst) as *const &Section<'_>;
        // SAFETY: this share of section `seen` was unclaimed, so that section is still
        // running: its pointer (stored before the epoch was bumped) is the one here, and
        // the caller waits for `done` before letting it go.
        let section = unsafe { &*pointer };
        run_share(shared, section, index);
    }
}

#[cfg(test)]
mod tests;
