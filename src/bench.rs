//! The speed benchmark behind `clothsim bench`: the `hanging-bench` scene (the one the peer
//! frameworks in `../shared/peers` run too) at N × N particles, timed per substep, with the
//! sag that says whether the speed bought the right answer.

use std::time::Instant;

use serde::Serialize;

use crate::gpu::GpuError;
use crate::scene::{OneOrTwo, Scene, SceneError, Simulation, scenario};
use crate::sim::{IntegratorKind, Precision};

/// The bench scene's name.
pub const BENCH_SCENE: &str = "hanging-bench";

/// Simulated seconds of a bench run unless told otherwise (the sag is read at its end, and
/// [`REFERENCE_SAG`] is for this time).
pub const BENCH_SECONDS: f64 = 2.0;

/// Sag after 2 s of the reference solution (semi-implicit Euler at `dt = 1/(60 N)`, from
/// `../shared/peers/scene.py`; N = 512 and 700 from `benches/sag_reference.py` in float64 on
/// a GPU, where Warp and Taichi agree within 0.02 %), metres, by N.
pub const REFERENCE_SAG: [(u32, f64); 6] = [
    (32, 0.01055),
    (64, 0.01247),
    (128, 0.0135),
    (256, 0.01478),
    (512, 0.016173),
    (700, 0.015759),
];

/// The reference sag of the bench cloth at `n` particles a side after `seconds`: only at
/// [`BENCH_SECONDS`], the time [`REFERENCE_SAG`] is for, and only at its sizes.
pub fn reference_sag(n: u32, seconds: f64) -> Option<f64> {
    (REFERENCE_SAG.iter())
        .find(|(m, _)| *m == n && seconds == BENCH_SECONDS)
        .map(|(_, s)| *s)
}

/// How close the sag must be for a speed to count: 1 %, 5 % for implicit Euler, XPBD and VBD
/// (which trade accuracy for their large steps).
pub fn sag_tolerance(integrator: IntegratorKind) -> f64 {
    match integrator {
        IntegratorKind::ImplicitEuler | IntegratorKind::Xpbd | IntegratorKind::Vbd => 0.05,
        _ => 0.01,
    }
}

/// The integrators `clothsim bench` runs on the CPU unless told which: one explicit, one
/// implicit, and the two that solve implicit steps iteratively (XPBD's constraints, VBD's
/// particles).
pub const BENCH_INTEGRATORS: [IntegratorKind; 4] = [
    IntegratorKind::SemiImplicitEuler,
    IntegratorKind::ImplicitEuler,
    IntegratorKind::Xpbd,
    IntegratorKind::Vbd,
];

/// Substeps per 1/60 s frame the bench gives each integrator: N (so `dt = 1/(60 N)`, the
/// scene's definition), five large steps for implicit Euler, N/2 for VBD (one sweep each:
/// small steps; docs/performance.md has the other settings measured).
pub fn bench_substeps(integrator: IntegratorKind, n: u32) -> u32 {
    match integrator {
        IntegratorKind::ImplicitEuler => 5,
        IntegratorKind::Vbd => (n / 2).max(1),
        _ => n,
    }
}

/// Gauss–Seidel sweeps per substep the bench gives XPBD: one sweep leaves the cloth 9–16 %
/// softer than the springs it models (its sag at N = 64 / 128), two bring it within about
/// 1 % (README "Performance").
pub const BENCH_XPBD_SWEEPS: u32 = 2;

/// Descent sweeps per substep the bench gives VBD: one, over N/2 substeps
/// ([`bench_substeps`]; docs/performance.md has the other settings measured). Set here, not
/// left to the scene file's default.
pub const BENCH_VBD_SWEEPS: u32 = 1;

/// One row of the bench table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BenchRow {
    /// Particles per side.
    pub n: u32,
    pub integrator: String,
    /// The backend's name ("cpu", "gpu").
    pub backend: String,
    /// What it computed in ("f32", "f64").
    pub precision: String,
    /// CPU threads the solver may share a step among: the team's members (the pool's size,
    /// at most 16; a cloth under [`crate::parallel::PARALLEL_ELEMENTS`] particles, 64 × 64,
    /// still steps on one of them, and the team runs on one while the others do not pay),
    /// 1 on the GPU (the thread that submits its work).
    pub threads: usize,
    pub substeps_per_frame: u32,
    /// Wall time of the whole run per substep: every pause a busy machine imposes counts.
    pub us_per_substep: f64,
    pub substeps_per_second: f64,
    /// Per substep in the median frame and in the fastest frame (see [`frame_spread`]);
    /// `None` where frames are only queued (the GPU), not finished, when the clock stops.
    pub median_frame_us: Option<f64>,
    pub best_frame_us: Option<f64>,
    /// Downward displacement of the mean of the 4 central particles after 2 s, metres.
    pub sag_m: f64,
    /// The reference sag for this N, if known.
    pub reference_sag_m: Option<f64>,
    /// |sag − reference| / reference.
    pub sag_error: Option<f64>,
    /// Whether the sag is within the integrator's tolerance of the reference.
    pub sag_ok: Option<bool>,
    pub finite: bool,
    /// From building the scene to the end of the first substep, milliseconds.
    pub startup_ms: f64,
}

/// Why a bench run could not start.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error("the bench cloth needs at least 3 × 3 particles, got {0}")]
    TooSmall(u32),
    #[error("a bench run lasts from two frames (1/30 s) to an hour, got {0} s")]
    Seconds(f64),
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// No device, or a scene the GPU backend cannot run.
    #[error(transparent)]
    Gpu(#[from] GpuError),
}

/// The bench scene at `n × n` particles for `integrator`: the built-in file with its grid
/// and substeps changed.
///
/// # Errors
/// [`BenchError::TooSmall`] if `n < 3`.
pub fn bench_scene(n: u32, integrator: IntegratorKind) -> Result<Scene, BenchError> {
    if n < 3 {
        return Err(BenchError::TooSmall(n));
    }
    let mut file = scenario(BENCH_SCENE)
        .ok_or_else(|| SceneError::UnknownScenario {
            name: BENCH_SCENE.into(),
            available: String::new(),
        })?
        .clone();
    if let Some(grid) = file.cloth.grid.as_mut() {
        grid.quads = OneOrTwo::One(n - 1);
    }
    file.solver.integrator = integrator;
    file.solver.substeps = bench_substeps(integrator, n);
    file.solver.xpbd_iterations = BENCH_XPBD_SWEEPS;
    file.solver.vbd_iterations = BENCH_VBD_SWEEPS;
    // Timed as it stands: nothing rolls back or refines behind the figures.
    file.solver.guard.enabled = false;
    Ok(Scene::from_file(file, None)?)
}

/// The 4 particles nearest the middle of the cloth's rest shape: the sag is theirs.
pub fn central(sim: &Simulation) -> Vec<usize> {
    let rest = &sim.model().rest_positions;
    let (lo, hi) = crate::mesh::bounds(rest);
    let mid = 0.5 * (lo + hi);
    let mut order: Vec<usize> = (0..rest.len()).collect();
    order.sort_by(|&a, &b| rest[a].distance(mid).total_cmp(&rest[b].distance(mid)));
    order.truncate(4);
    order
}

/// Runs the bench scene at `n` with `integrator` for [`BENCH_SECONDS`] on the current
/// rayon pool and times it.
///
/// # Errors
/// [`BenchError`] for a bad `n`.
pub fn bench_one(n: u32, integrator: IntegratorKind) -> Result<BenchRow, BenchError> {
    bench_in(n, integrator, Precision::F32, BENCH_SECONDS)
}

/// As [`bench_one`], computing in `precision`, for `seconds` of simulated time (the sag is
/// held against its reference only at [`BENCH_SECONDS`], the time the reference is for).
///
/// # Errors
/// [`BenchError`] for a bad `n` or `seconds`.
pub fn bench_in(
    n: u32,
    integrator: IntegratorKind,
    precision: Precision,
    seconds: f64,
) -> Result<BenchRow, BenchError> {
    bench_for(n, integrator, seconds, |mut scene| {
        scene.params.solver.precision = precision;
        Ok(Simulation::new(scene))
    })
}

/// As [`bench_in`] on the GPU backend, on a headless device of its own
/// ([`crate::gpu::gpu_simulation`]; its state read back at the end only).
///
/// # Errors
/// [`BenchError`] for a bad `n` or `seconds`; [`BenchError::Gpu`] with the reason when
/// there is no device or the GPU backend cannot run the scene.
pub fn bench_gpu(n: u32, integrator: IntegratorKind, seconds: f64) -> Result<BenchRow, BenchError> {
    bench_for(n, integrator, seconds, |scene| {
        Ok(crate::gpu::gpu_simulation(scene, false).map(|(sim, _)| sim)?)
    })
}

/// Frames of a bench run `seconds` long: at least two (the first is not timed), at most an
/// hour's (each frame's time is kept).
///
/// # Errors
/// [`BenchError::Seconds`] for a time outside that (or not a number).
pub fn bench_frames(seconds: f64) -> Result<u64, BenchError> {
    let frames = (seconds * 60.0).round();
    if (2.0..=60.0 * 3600.0).contains(&frames) {
        Ok(frames as u64)
    } else {
        Err(BenchError::Seconds(seconds))
    }
}

/// As [`bench_in`], with the simulation built by `make` (another backend, other settings).
///
/// # Errors
/// [`BenchError`] for a bad `n` or `seconds`, or what `make` returns.
pub fn bench_for(
    n: u32,
    integrator: IntegratorKind,
    seconds: f64,
    make: impl FnOnce(Scene) -> Result<Simulation, BenchError>,
) -> Result<BenchRow, BenchError> {
    let frames = bench_frames(seconds)?;
    let start = Instant::now();
    let mut sim = make(bench_scene(n, integrator)?)?;
    let mut finite = sim.substep().is_ok();
    let startup_ms = start.elapsed().as_secs_f64() * 1e3;
    let centre = central(&sim);
    let y0: f64 = centre
        .iter()
        .map(|&p| sim.initial().pos[p].y as f64)
        .sum::<f64>()
        / 4.0;
    let substeps = sim.params().step.substeps;
    let total = frames * substeps as u64;
    let timer = Instant::now();
    // The first substep is done: the rest of the first frame, then whole frames (one
    // submission each on the GPU).
    for _ in 1..substeps {
        if finite {
            finite = sim.substep().is_ok();
        }
    }
    let mut frame_us = Vec::with_capacity(frames as usize);
    for _ in 1..frames {
        if !finite {
            break;
        }
        let frame = Instant::now();
        finite = sim.step_frame().is_ok();
        frame_us.push(frame.elapsed().as_secs_f64() * 1e6 / substeps.max(1) as f64);
    }
    // A backend still behind its state (the GPU's queue) only queued the frames it timed.
    let frames_finished = !sim.state_behind();
    // Waits for a GPU to finish: its time counts. A state that cannot be read is no result.
    finite &= sim.sync_state().is_ok();
    let wall = timer.elapsed().as_secs_f64();
    finite &= sim.state().is_finite();
    let y: f64 = centre
        .iter()
        .map(|&p| sim.state().pos[p].y as f64)
        .sum::<f64>()
        / 4.0;
    let sag = y0 - y;
    let reference = reference_sag(n, seconds);
    let error = reference.map(|r| (sag - r).abs() / r);
    let us = wall * 1e6 / (total - 1).max(1) as f64;
    let spread = frame_spread(&mut frame_us).filter(|_| frames_finished);
    Ok(BenchRow {
        n,
        integrator: integrator.name().to_string(),
        backend: sim.backend_name().to_string(),
        precision: sim.params().solver.precision.to_string(),
        threads: sim.cpu_threads(),
        substeps_per_frame: substeps,
        us_per_substep: us,
        substeps_per_second: 1e6 / us,
        median_frame_us: spread.map(|s| s.median),
        best_frame_us: spread.map(|s| s.best),
        sag_m: sag,
        reference_sag_m: reference,
        sag_error: error,
        sag_ok: error.map(|e| finite && e <= sag_tolerance(integrator)),
        finite,
        startup_ms,
    })
}

/// The median and the least of some frames' times.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameSpread {
    /// The middle time (the mean of the two middle ones for an even count).
    pub median: f64,
    pub best: f64,
}

/// The spread of per-frame times (sorted in place); `None` for no frames.
///
/// On a shared machine (a virtual machine whose cores other guests also use) the mean over
/// a run counts every frame in which the simulation's threads were held off their cores;
/// the median frame is what a run usually gets, and the best frame what the code costs when
/// nothing else runs. The bench prints all three.
pub fn frame_spread(times: &mut [f64]) -> Option<FrameSpread> {
    times.sort_by(f64::total_cmp);
    let n = times.len();
    let best = *times.first()?;
    let median = if n % 2 == 1 {
        times[n / 2]
    } else {
        0.5 * (times[n / 2 - 1] + times[n / 2])
    };
    Some(FrameSpread { median, best })
}
