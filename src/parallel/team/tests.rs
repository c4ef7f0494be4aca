//! The team's tests: every share once, the caller's claims, pieces, pacing, parts.

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
/// The helper's hold-up is made, not waited for: its first piece lasts until every other
/// piece has run, and the caller's first lasts until the helper is in its own.
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
    let wait_for = |done: &dyn Fn() -> bool| {
        let start = Instant::now();
        while !done() {
            assert!(start.elapsed().as_secs() < 60, "never came");
            std::thread::yield_now();
        }
    };
    team.run_pieces(8, &|member, piece| {
        if std::thread::current().id() == caller {
            wait_for(&|| helper_began.load(Ordering::SeqCst));
        } else {
            on_helper.lock().unwrap().push((member, piece));
            helper_began.store(true, Ordering::SeqCst);
            wait_for(&|| ran.load(Ordering::SeqCst) == 7);
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

/// While the pace says the helpers do not pay, every share of a section runs on the caller,
/// in order, and each section is timed once (the timing itself, and when the pace turns,
/// are the pace's own tests).
#[test]
fn a_team_that_goes_alone_gives_its_helpers_no_share_and_times_every_section() {
    let team = Team::new(3);
    team.busy.lock().unwrap().alone = true;
    let caller = std::thread::current().id();
    let ran = Mutex::new(Vec::new());
    for _ in 0..5 {
        team.run(&|i| {
            ran.lock()
                .unwrap()
                .push((i, std::thread::current().id() == caller))
        });
    }
    let want: Vec<(usize, bool)> = (0..5).flat_map(|_| (0..3).map(|i| (i, true))).collect();
    assert_eq!(ran.into_inner().unwrap(), want);
    assert_eq!(team.busy.lock().unwrap().sections, 5, "five sections timed");
}

/// Large pieces are handed to the helpers even while the pace runs the caller alone (the
/// section's epoch is bumped, which only a shared section does), each piece runs once, and
/// the pace does not time them.
#[test]
fn large_pieces_are_shared_whatever_the_pace_and_not_timed() {
    let team = Team::new(2);
    team.busy.lock().unwrap().alone = true;
    let runs: Vec<AtomicUsize> = (0..40).map(|_| AtomicUsize::new(0)).collect();
    let before = team.shared.epoch.load(Ordering::SeqCst);
    team.run_large_pieces(runs.len(), &|_, piece| {
        runs[piece].fetch_add(1, Ordering::SeqCst);
    });
    assert_eq!(
        team.shared.epoch.load(Ordering::SeqCst),
        before + 1,
        "handed over"
    );
    assert!(runs.iter().all(|r| r.load(Ordering::SeqCst) == 1));
    assert_eq!(team.busy.lock().unwrap().sections, 0, "not timed");
    // A paced section still runs alone and is timed.
    team.run_pieces(4, &|_, _| {});
    assert_eq!(
        team.shared.epoch.load(Ordering::SeqCst),
        before + 1,
        "run alone"
    );
    assert_eq!(team.busy.lock().unwrap().sections, 1);
}
