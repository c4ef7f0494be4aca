//! Once warm, a frame allocates nothing: the stepper, the guard, every effect and
//! self-contact keep their buffers from frame to frame, and grow them only where a motion
//! needs more room than any before it. A test binary of its own: the counting allocator
//! sees every thread of the process, so no other test may run beside it.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use clothsim::mesh::ImportOptions;
use clothsim::scene::{BUILTIN_SCENES, Scene, Simulation};

/// The system allocator, counting the allocations and reallocations made through it.
struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is passed on to the system allocator unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: the caller keeps `GlobalAlloc::alloc`'s contract.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: as for `alloc`.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: as for `alloc`.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static COUNTING: Counting = Counting;

/// The allocations of each of `frames` frames of `sim`, and the pairs self-contact found
/// in its last substep.
fn allocations_per_frame(sim: &mut Simulation, frames: usize) -> Vec<(usize, u64)> {
    (0..frames)
        .map(|frame| {
            let before = ALLOCATIONS.load(Ordering::Relaxed);
            sim.step_frame()
                .unwrap_or_else(|e| panic!("frame {frame}: {e}"));
            let allocated = ALLOCATIONS.load(Ordering::Relaxed) - before;
            let found = sim.self_collision_work().map_or(0, |w| w.candidates);
            (allocated, found)
        })
        .collect()
}

/// Every built-in scene, its grid resized to `quads`² (`layers`' five grids to 8²), run for
/// 1.5 s, reset and run again on one thread: the second run, which asks for no more room
/// than the first, allocates nothing in any frame but its first (where the guard takes
/// its checkpoint again after the reset). On two threads each member of the team fills
/// its own buffer of pairs, with whichever pieces it takes first, so a second run may need
/// a larger buffer in one member than the first did: growth, not a frame's allocation;
/// one thread keeps the runs alike. `layers` at 16² too, whose pairs pass the 4 096 from
/// which the pushes go in groups of slabs, each group with its own lists.
/// `flag` at 64 quads along its length on two threads too, 0.5 s at 96 substeps (at its own
/// 48 the guard refines its first frame, and a rescue allocates): its wind's 5 504
/// triangles are shared with the team (from 4 096), each piece writing its own slots.
#[test]
fn a_warm_frame_allocates_nothing_in_any_scene() {
    let pools = [1, 2].map(|threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
    });
    // The most pairs a frame's last substep found.
    let run_on = |threads: usize, name: &str, quads: u32, seconds: f64, substeps: Option<u32>| {
        let pool = &pools[threads - 1];
        let mut scene = Scene::open_resized(name, None, &ImportOptions::default(), Some(quads))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        if let Some(substeps) = substeps {
            scene.params.step.substeps = substeps;
        }
        let mut sim = Simulation::new(scene);
        let frames = (seconds / sim.params().step.dt as f64).round() as usize;
        let (first, again) = pool.install(|| {
            let first = allocations_per_frame(&mut sim, frames);
            sim.reset();
            (first, allocations_per_frame(&mut sim, frames))
        });
        assert!(
            first[0].0 > 0,
            "{name}: the first frame sets up its buffers"
        );
        let warm: usize = again[1..].iter().map(|f| f.0).sum();
        assert_eq!(
            warm, 0,
            "{name} at {quads}²: frames after the first allocated again: {again:?}"
        );
        again.iter().map(|f| f.1).max().unwrap_or(0)
    };
    let run = |name: &str, quads: u32| run_on(1, name, quads, 1.5, None);
    run_on(2, "flag", 64, 0.5, Some(96));
    for &(name, _) in BUILTIN_SCENES {
        run(name, if name == "layers" { 8 } else { 12 });
    }
    let most = run("layers", 16);
    assert!(most > 4096, "{most} pairs at most");
}
