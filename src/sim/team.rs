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
        if pace.runs_alone() {
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
        pace.record(start.elapsed());
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
        let members = self.members();
        // The next untaken piece of each member's share (on its own cache line, so that a
        // member taking its own pieces does not move the others' counters between cores).
        let next: [Padded; MAX_MEMBERS] =
            std::array::from_fn(|i| Padded(AtomicUsize::new(share(pieces, members, i).start)));
        self.run(&|i| {
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
        });
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
        if parallel && self.members() > 1 {
            self.run_pieces(pieces, work);
        } else {
            (0..pieces).for_each(|piece| work(0, piece));
        }
    }
}

/// Sections over which a team's time per section is measured.
const WINDOW: u32 = 64;
/// Windows run the chosen way between two that try the other, after a switch; each probe
/// that loses doubles it, up to [`PROBE_EVERY_MOST`].
const PROBE_EVERY: u32 = 8;
/// The most windows between two probes (at N = 64 about 2 000 substeps, a tenth of a second).
const PROBE_EVERY_MOST: u32 = 64;

/// Whether a team's sections run shared with its helpers or on the caller alone, chosen by
/// timing. Now and then a window of [`WINDOW`] sections tries the other way, which is taken
/// when it took at least 10 % less time than the last window run the chosen way (a probe
/// that has used up that time ends early, lost). Probes come [`PROBE_EVERY`] windows after
/// a switch and ever more rarely while they lose; while sharing, they come only once its
/// windows have slowed (and at the start, and every 512 windows). Each costs the slower
/// way's time and the helpers' caches warmed again: at one probe in nine windows that
/// added about 3 µs to a 30 µs substep.
#[derive(Debug, Default)]
struct Pace {
    /// The way chosen: the caller alone (the helpers did not pay when last tried).
    alone: bool,
    /// The current window tries the way not chosen.
    probing: bool,
    /// Sections in the current window so far, and the time they took.
    sections: u32,
    spent: Duration,
    /// Windows run the chosen way since the last probe, and how many come between probes
    /// now (0 until the first probe: [`PROBE_EVERY`]).
    since_probe: u32,
    probe_every: u32,
    /// Time per section of the last window run the chosen way.
    chosen: Option<Duration>,
    /// The shared way's fastest time per section lately (rising 1 % a window): a shared
    /// window 25 % slower than this has a busy machine behind it.
    quiet: Option<Duration>,
}

impl Pace {
    /// Whether the next section runs on the caller alone.
    fn runs_alone(&self) -> bool {
        self.alone != self.probing
    }

    /// Counts a section that took `took`, run the way [`Pace::runs_alone`] said.
    fn record(&mut self, took: Duration) {
        self.spent += took;
        self.sections += 1;
        // A clear win only: the two ways' times swing from window to window, and a switch
        // on noise would run the slower way until the next probe. A probe that has spent
        // what would lose already ends at once (the slower way costs only until then).
        let to_beat = self.chosen.map(|chosen| chosen * WINDOW * 9 / 10);
        let lost = self.probing && to_beat.is_some_and(|to_beat| self.spent >= to_beat);
        if self.sections < WINDOW && !lost {
            return;
        }
        let per_section = self.spent / WINDOW;
        (self.sections, self.spent) = (0, Duration::ZERO);
        if self.probing {
            self.probing = false;
            // A probe comes after a window run the chosen way, so it had a time to beat: a
            // probe that did not lose won.
            if lost {
                self.probe_every = (self.probe_every.max(PROBE_EVERY) * 2).min(PROBE_EVERY_MOST);
            } else {
                self.alone = !self.alone;
                self.chosen = Some(per_section);
                self.probe_every = PROBE_EVERY;
            }
        } else {
            self.chosen = Some(per_section);
            if !self.alone {
                let lately = self.quiet.map_or(per_section, |quiet| quiet * 101 / 100);
                self.quiet = Some(lately.min(per_section));
            }
            self.since_probe += 1;
            // Sharing is probed only once it has slowed (a quiet machine pays nothing for
            // probes), at the start, and now and then whatever the times say.
            let slowed = self.alone
                || self.probe_every == 0
                || self.since_probe >= 8 * PROBE_EVERY_MOST
                || self.quiet.is_some_and(|quiet| per_section * 4 > quiet * 5);
            if slowed && self.since_probe >= self.probe_every.max(PROBE_EVERY) {
                (self.since_probe, self.probing) = (0, true);
            }
        }
    }
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

/// A slice that members take disjoint parts of, each its own.
pub struct Disjoint<'a, T> {
    start: *mut T,
    len: usize,
    _slice: std::marker::PhantomData<&'a mut [T]>,
}

// SAFETY: members only reach the elements through `part`, whose contract keeps their
// parts disjoint; `T: Send` lets each part be used on another thread.
unsafe impl<T: Send> Sync for Disjoint<'_, T> {}

impl<'a, T> Disjoint<'a, T> {
    pub fn new(slice: &'a mut [T]) -> Self {
        Self {
            start: slice.as_mut_ptr(),
            len: slice.len(),
            _slice: std::marker::PhantomData,
        }
    }

    /// The first element, for kernels that gather through raw pointers (they must keep
    /// [`Disjoint::part`]'s contract themselves).
    pub fn as_ptr(&self) -> *mut T {
        self.start
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Elements `range` (clamped to the slice).
    ///
    /// # Safety
    /// No two parts in use at the same time may overlap.
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn part(&self, range: std::ops::Range<usize>) -> &mut [T] {
        let range = clamped(range, self.len);
        // SAFETY: in bounds (clamped); disjoint from other parts by the caller's contract.
        unsafe { std::slice::from_raw_parts_mut(self.start.add(range.start), range.len()) }
    }

    /// Element `i`.
    ///
    /// # Safety
    /// As [`Disjoint::part`]: no other member uses element `i` at the same time; `i` is in
    /// bounds.
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn at(&self, i: usize) -> &mut T {
        debug_assert!(i < self.len);
        // SAFETY: by the caller's contract.
        unsafe { &mut *self.start.add(i) }
    }
}

/// Elements (particles) from which [`each_part`] shares its loop out between the team's
/// members: 64 × 64 particles (the spring blocks go parallel from here too). On the 2-core
/// virtual machine this was measured on, the 64 × 64 bench cloth's median frame took 18 %
/// less on two threads than on one once the caller could run a share its helper was late
/// for (implicit Euler's step 13 % less); below that size the data moving between the
/// cores' caches cost more than the second core gained.
pub const PARALLEL_ELEMENTS: usize = 4096;

/// Calls `part(range, slices)` with `arrays` cut at `range`, for ranges that cover
/// `0..len` (`len` the shortest array's length): one range per member of the current team,
/// run in parallel, from [`PARALLEL_ELEMENTS`] elements on; else the one range `0..len`
/// here. Ranges are whole cache lines (16 floats) long but the last. For loops in which
/// each element's work is its own, so the result is the same however they are cut.
pub fn each_part<const K: usize>(
    arrays: [&mut [f32]; K],
    part: impl Fn(std::ops::Range<usize>, [&mut [f32]; K]) + Sync,
) {
    const LINE: usize = 16;
    let len = arrays.iter().map(|a| a.len()).min().unwrap_or(0);
    let team = Team::current();
    if len < PARALLEL_ELEMENTS || team.members() == 1 {
        part(0..len, arrays.map(|a| &mut a[..len]));
        return;
    }
    let arrays = arrays.map(Disjoint::new);
    let members = team.members();
    team.run(&|i| {
        let lines = share(len.div_ceil(LINE), members, i);
        let range = (lines.start * LINE).min(len)..(lines.end * LINE).min(len);
        // SAFETY: the members' ranges are disjoint (shares of whole lines).
        let mine = std::array::from_fn(|k| unsafe { arrays[k].part(range.clone()) });
        part(range, mine);
    });
}

/// `slice[range]`, cut short where `slice` ends: for arrays read beside those that
/// [`each_part`] cuts, which may be shorter.
pub fn within<T>(slice: &[T], range: std::ops::Range<usize>) -> &[T] {
    &slice[clamped(range, slice.len())]
}

/// `range` cut short at `len` (empty where it starts past it).
fn clamped(range: std::ops::Range<usize>, len: usize) -> std::ops::Range<usize> {
    let end = range.end.min(len);
    range.start.min(end)..end
}

/// `0..len` cut into `parts` nearly equal ranges; the `i`-th.
pub fn share(len: usize, parts: usize, i: usize) -> std::ops::Range<usize> {
    let parts = parts.max(1);
    (len * i / parts)..(len * (i + 1) / parts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicU64;

    #[test]
    fn every_member_runs_its_share_once_per_section_and_the_caller_waits_for_all() {
        for members in [1, 2, 3] {
            let team = Team::new(members);
            assert_eq!(team.members(), members);
            let sums: Vec<AtomicU64> = (0..members).map(|_| AtomicU64::new(0)).collect();
            for round in 0..2000u64 {
                team.run(&|i| {
                    // Work long enough that an early return would be caught.
                    let mut x = round;
                    for _ in 0..200 {
                        x = std::hint::black_box(x.wrapping_mul(6364136223846793005) + 1);
                    }
                    let _ = x;
                    sums[i].fetch_add(round + 1, Ordering::SeqCst);
                });
                let want = (round + 1) * (round + 2) / 2;
                for (i, s) in sums.iter().enumerate() {
                    assert_eq!(s.load(Ordering::SeqCst), want, "member {i}, round {round}");
                }
            }
        }
    }

    /// Story: the machine holds a helper off its core; the caller runs that member's share
    /// itself rather than wait, each share still once, and the section ends.
    #[test]
    fn the_caller_runs_the_shares_no_helper_came_for() {
        let team = Arc::new(Team::new(3));
        team.shared.helpers_stay_away.store(true, Ordering::SeqCst);
        let (sent, got) = std::sync::mpsc::channel();
        // On its own thread, so that a caller left waiting fails the test, not hangs it.
        let caller = Arc::clone(&team);
        std::thread::spawn(move || {
            let ran = Mutex::new(Vec::new());
            for _ in 0..3 {
                caller.run(&|i| ran.lock().unwrap().push((i, std::thread::current().id())));
            }
            let _ = sent.send(ran.into_inner().unwrap());
        });
        let ran = got
            .recv_timeout(Duration::from_secs(20))
            .expect("the section ends without its helpers");
        let shares: Vec<usize> = ran.iter().map(|&(i, _)| i).collect();
        assert_eq!(shares, [0, 1, 2, 0, 1, 2, 0, 1, 2]);
        assert!(ran.iter().all(|&(_, t)| t == ran[0].1), "all on the caller");
        // Helpers that come back take their shares again.
        team.shared.helpers_stay_away.store(false, Ordering::SeqCst);
        let hits = AtomicUsize::new(0);
        for _ in 0..100 {
            team.run(&|_| {
                hits.fetch_add(1, Ordering::SeqCst);
            });
        }
        assert_eq!(hits.load(Ordering::SeqCst), 300);
    }

    /// Story: a helper is held up in its first piece; the caller, done with its own share,
    /// takes the rest of the helper's pieces instead of waiting, and every piece runs once.
    #[test]
    fn run_pieces_runs_each_piece_once_and_the_caller_takes_a_slow_helpers_rest() {
        let team = Team::new(2);
        let caller = std::thread::current().id();
        for round in 0..50 {
            let ran: Vec<AtomicUsize> = (0..13).map(|_| AtomicUsize::new(0)).collect();
            team.run_pieces(13, &|_, piece| {
                ran[piece].fetch_add(1, Ordering::SeqCst);
            });
            assert!(ran.iter().all(|r| r.load(Ordering::SeqCst) == 1), "{round}");
        }
        let on_helper = Mutex::new(Vec::new());
        let helper_began = AtomicBool::new(false);
        let ran = AtomicUsize::new(0);
        team.run_pieces(8, &|member, piece| {
            if std::thread::current().id() == caller {
                // The caller's first piece lasts until the helper is in its own first one.
                let start = Instant::now();
                while !helper_began.load(Ordering::SeqCst) && start.elapsed().as_secs() < 10 {
                    std::hint::spin_loop();
                }
            } else {
                on_helper.lock().unwrap().push((member, piece));
                helper_began.store(true, Ordering::SeqCst);
                std::thread::sleep(Duration::from_millis(200));
            }
            ran.fetch_add(1, Ordering::SeqCst);
        });
        assert_eq!(ran.load(Ordering::SeqCst), 8);
        // The helper ran the first piece of its share (4..8); the caller took the others.
        assert_eq!(on_helper.into_inner().unwrap(), [(1, 4)]);
    }

    #[test]
    fn run_pieces_on_the_caller_alone_runs_them_in_order() {
        let team = Team::new(3);
        team.shared.helpers_stay_away.store(true, Ordering::SeqCst);
        let order = Mutex::new(Vec::new());
        team.run_pieces(10, &|_, piece| order.lock().unwrap().push(piece));
        assert_eq!(order.into_inner().unwrap(), (0..10).collect::<Vec<_>>());
        // Not shared out: every piece in order on the caller, as member 0.
        team.shared.helpers_stay_away.store(false, Ordering::SeqCst);
        let (caller, ran) = (std::thread::current().id(), Mutex::new(Vec::new()));
        team.run_pieces_if(false, 6, &|member, piece| {
            let here = std::thread::current().id() == caller;
            ran.lock().unwrap().push((member, piece, here));
        });
        let want: Vec<_> = (0..6).map(|piece| (0, piece, true)).collect();
        assert_eq!(ran.into_inner().unwrap(), want);
    }

    /// Feeds `pace` one window of sections that take `micros` each, until it ends; returns
    /// whether they ran alone (the same for the whole window).
    fn window(pace: &mut Pace, micros: u64) -> bool {
        let alone = pace.runs_alone();
        for _ in 0..WINDOW {
            assert_eq!(pace.runs_alone(), alone, "a window runs one way");
            pace.record(Duration::from_micros(micros));
            if pace.sections == 0 {
                break;
            }
        }
        alone
    }

    /// A probe that cannot win any more ends early: here after the 18 µs sections have
    /// used up 90 % of a 10 µs window (32 of 64), and the team shares again.
    #[test]
    fn a_losing_probe_ends_as_soon_as_it_has_lost() {
        let mut pace = Pace::default();
        for _ in 0..PROBE_EVERY * WINDOW {
            pace.record(Duration::from_micros(10));
        }
        assert!(pace.runs_alone(), "probing");
        let mut sections = 0;
        while pace.runs_alone() {
            pace.record(Duration::from_micros(18));
            sections += 1;
        }
        assert_eq!(sections, 32);
        assert!(!pace.alone);
    }

    /// Story: the helpers pay in a quiet spell, stop paying in a busy one and pay again
    /// after it; the team follows within one probe each time, and a probe that loses
    /// changes nothing.
    #[test]
    fn a_team_runs_alone_while_its_helpers_do_not_pay_and_shares_again_when_they_do() {
        let mut pace = Pace::default();
        // Quiet: shared takes 10 µs a section, alone 18. The first probe (after eight
        // windows) loses, and while sharing keeps its pace no other comes.
        let probe_at = PROBE_EVERY as usize;
        let ways: Vec<bool> = (0..100)
            .map(|_| {
                let alone = pace.runs_alone();
                window(&mut pace, if alone { 18 } else { 10 })
            })
            .collect();
        let want: Vec<bool> = (0..100).map(|w| w == probe_at).collect();
        assert_eq!(ways, want, "one probe, at the start");
        // Busy: shared now takes 30 µs, alone 20. The team probes at once and goes alone,
        // probing sharing ever more rarely.
        let most = PROBE_EVERY_MOST as usize;
        let ways: Vec<bool> = (0..2 * most)
            .map(|_| {
                let alone = pace.runs_alone();
                window(&mut pace, if alone { 20 } else { 30 })
            })
            .collect();
        let first_alone = ways.iter().position(|&a| a).expect("goes alone");
        assert_eq!(first_alone, 1, "{ways:?}");
        let shared_probes = ways[first_alone..].iter().filter(|&&a| !a).count();
        assert!((1..=4).contains(&shared_probes), "{ways:?}");
        assert!(pace.alone);
        // Quiet again: sharing wins its next probe (at most PROBE_EVERY_MOST windows on),
        // and the team shares from then on, with no probe while it keeps its pace.
        let ways: Vec<bool> = (0..2 * most)
            .map(|_| {
                let alone = pace.runs_alone();
                window(&mut pace, if alone { 18 } else { 10 })
            })
            .collect();
        let first_shared = ways.iter().position(|&a| !a).expect("shares again");
        assert!(first_shared <= most, "{ways:?}");
        assert!(ways[first_shared..].iter().all(|&a| !a), "{ways:?}");
        assert!(!pace.alone, "{ways:?}");
    }

    /// Story: sharing keeps its pace, so the slow-down gate never opens, but running alone
    /// has become faster (the first probe lost); the probe that comes every
    /// `8 × PROBE_EVERY_MOST` windows whatever the times say finds it, and the team goes
    /// alone.
    #[test]
    fn a_steady_team_still_tries_alone_now_and_then() {
        let mut pace = Pace::default();
        let mut alone_from = None;
        for w in 0..600 {
            let alone = pace.runs_alone();
            if alone && w > PROBE_EVERY as usize && alone_from.is_none() {
                alone_from = Some(w);
            }
            // Alone loses the first probe (18 µs), and would win every later one (8 µs).
            let micros = match (alone, w <= PROBE_EVERY as usize) {
                (false, _) => 10,
                (true, true) => 18,
                (true, false) => 8,
            };
            window(&mut pace, micros);
        }
        let rechecked = PROBE_EVERY + 1 + 8 * PROBE_EVERY_MOST;
        assert_eq!(alone_from, Some(rechecked as usize));
        assert!(pace.alone);
    }

    /// Story: the machine keeps the helper slow (each of its shares takes 3 ms; the
    /// caller's own share 500 µs, the helper's share 20 µs on the caller); after one probe
    /// the team runs its sections on the caller alone, every share still once.
    ///
    /// The caller's long share gives the helper 500 µs to come for its own before the
    /// caller takes it: a helper that comes for none (held off its core while other tests
    /// run) would make sharing as fast as going alone, and the team rightly stays. Sharing
    /// loses its window once the helper comes for 3 % of the sections.
    #[test]
    fn a_team_whose_helper_is_slow_goes_on_alone() {
        let team = Team::new(2);
        let caller = std::thread::current().id();
        let on_helper = AtomicUsize::new(0);
        let shares = AtomicUsize::new(0);
        let section = |share: usize| {
            if std::thread::current().id() == caller {
                let took = Duration::from_micros(if share == 0 { 500 } else { 20 });
                let start = Instant::now();
                while start.elapsed() < took {
                    std::hint::spin_loop();
                }
            } else {
                on_helper.fetch_add(1, Ordering::SeqCst);
                std::thread::sleep(Duration::from_millis(3));
            }
            shares.fetch_add(1, Ordering::SeqCst);
        };
        let sections = (PROBE_EVERY + 1) * WINDOW;
        for _ in 0..sections {
            team.run(&section);
        }
        assert!(
            on_helper.load(Ordering::SeqCst) > 0,
            "the helper took part at first"
        );
        assert!(
            team.busy.lock().unwrap().alone,
            "alone after the first probe"
        );
        let before = on_helper.load(Ordering::SeqCst);
        let later = (PROBE_EVERY - 1) * WINDOW;
        for _ in 0..later {
            team.run(&section);
        }
        assert_eq!(
            on_helper.load(Ordering::SeqCst),
            before,
            "no share on the helper"
        );
        let total = (sections + later) as usize * team.members();
        assert_eq!(shares.load(Ordering::SeqCst), total, "every share once");
    }

    #[test]
    fn helpers_that_fell_asleep_wake_for_the_next_section() {
        let team = Team::new(2);
        let hits = AtomicUsize::new(0);
        for _ in 0..3 {
            std::thread::sleep(SPIN * 4);
            team.run(&|_| {
                hits.fetch_add(1, Ordering::SeqCst);
            });
        }
        assert_eq!(hits.load(Ordering::SeqCst), 6);
    }

    #[test]
    fn a_panic_in_a_helper_reaches_the_caller_and_the_team_goes_on() {
        let team = Team::new(2);
        let caught = catch_unwind(AssertUnwindSafe(|| {
            team.run(&|i| assert!(i != 1, "member 1 fails"));
        }));
        assert!(caught.is_err());
        let hits = AtomicUsize::new(0);
        team.run(&|_| {
            hits.fetch_add(1, Ordering::SeqCst);
        });
        assert_eq!(hits.load(Ordering::SeqCst), 2);
    }

    #[test]
    fn a_second_caller_at_the_same_time_runs_every_share_itself() {
        let team = Team::new(2);
        let inner = AtomicUsize::new(0);
        team.run(&|i| {
            if i == 0 {
                // The team is busy with this section: all of the nested one runs here.
                team.run(&|_| {
                    inner.fetch_add(1, Ordering::SeqCst);
                });
            }
        });
        assert_eq!(inner.load(Ordering::SeqCst), 2);
    }

    #[test]
    fn each_part_cuts_every_array_alike_into_whole_lines_one_per_member() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .expect("a pool of 3");
        for len in [0, 5, PARALLEL_ELEMENTS - 1, PARALLEL_ELEMENTS + 37] {
            // The shorter array sets the length; the longer one's tail is left alone.
            let (mut a, mut b) = (vec![0.0f32; len], vec![0.0f32; len + 5]);
            let parts = Mutex::new(Vec::new());
            pool.install(|| {
                each_part([&mut a, &mut b], |range, [a, b]| {
                    assert_eq!((a.len(), b.len()), (range.len(), range.len()));
                    for (k, (a, b)) in a.iter_mut().zip(b.iter_mut()).enumerate() {
                        *a += (range.start + k) as f32;
                        *b += 1.0;
                    }
                    parts.lock().unwrap().push(range);
                })
            });
            assert!(a.iter().enumerate().all(|(i, &x)| x == i as f32), "{len}");
            assert!(b[..len].iter().all(|&x| x == 1.0) && b[len..].iter().all(|&x| x == 0.0));
            let mut parts = parts.into_inner().unwrap();
            parts.sort_by_key(|r| r.start);
            let members = if len >= PARALLEL_ELEMENTS { 3 } else { 1 };
            assert_eq!(parts.len(), members, "{len}");
            assert!(
                parts
                    .iter()
                    .all(|r| r.start % 16 == 0 && !r.is_empty() || len == 0)
            );
            assert!(parts.windows(2).all(|w| w[0].end == w[1].start));
            assert_eq!((parts[0].start, parts[members - 1].end), (0, len));
        }
    }

    #[test]
    fn within_cuts_a_range_short_where_the_slice_ends() {
        let s = [1, 2, 3, 4, 5];
        assert_eq!(within(&s, 1..3), &[2, 3]);
        assert_eq!(within(&s, 3..9), &[4, 5]);
        assert!(within(&s, 7..9).is_empty());
    }

    #[test]
    fn shares_cover_the_range_in_order() {
        for (len, parts) in [(10, 3), (0, 2), (7, 7), (5, 8)] {
            let covered: Vec<usize> = (0..parts).flat_map(|i| share(len, parts, i)).collect();
            assert_eq!(covered, (0..len).collect::<Vec<_>>());
        }
    }
}
