//! Every integrator against analytic oracles: the stability and energy laws of the undamped
//! spring–mass, convergence orders on the undamped hanging cloth, stiff cloth, and XPBD's
//! inextensible limit.

use glam::Vec3;

use clothsim::cloth::{ClothModel, ClothState, Springs};
use clothsim::mesh::{GridOrientation, GridSpec, MeshBuild, SpringKind};
use clothsim::scene::{Scene, Simulation};
use clothsim::sim::forces::SpringForce;
use clothsim::sim::{
    Effect, Force, ForceSet, IntegratorKind, SolverConfig, StepContext, StepMeter,
};

const K: f32 = 100.0;
const M: f32 = 1.0;

/// Starting displacement, metres. The spring's stretch is `|d| − 1`, computed near 1 m
/// where f32 keeps 1.2e-7 m: 1 cm leaves it a relative precision of 1e-5. The force is
/// exactly linear as long as the mass stays on its side of the pin (x > −1 m).
const X0: f32 = 1e-2;

/// Energy ½mv² + ½kx² of a unit mass on a spring of stiffness `K` (ω = 10 rad/s) after each
/// of up to `steps` steps of `kind` at ωh = `z`, starting `X0` from rest; the run stops once
/// the energy has grown a thousandfold (amplitude 0.3 m). The mass moves along the spring
/// only.
fn oscillator_energies(kind: IntegratorKind, z: f32, steps: usize) -> Vec<f64> {
    let mut springs = Springs::default();
    springs.a.push(0);
    springs.b.push(1);
    springs.rest.push(1.0);
    springs.kind.push(SpringKind::Structural);
    let model = ClothModel::from_springs(
        vec![Vec3::new(-1.0, 0.0, 0.0), Vec3::ZERO],
        springs,
        vec![M, M],
        &[0],
    );
    let forces = ForceSet::from_terms(vec![Force::new(
        "springs",
        SpringForce::new(&model.springs, [K; 3], [0.0; 3]),
    )]);
    let h = z / (K / M).sqrt();
    let mut state = ClothState::at_rest(&model);
    state.pos[1].x += X0;
    let energy = |s: &ClothState| {
        let x = s.pos[1].x as f64;
        let v = s.vel[1].x as f64;
        0.5 * M as f64 * v * v + 0.5 * K as f64 * x * x
    };
    let mut integrator = kind.build();
    let (config, mut meter) = (SolverConfig::default(), StepMeter::default());
    let mut out = vec![energy(&state)];
    for _ in 0..steps {
        let mut ctx = StepContext::new(&model, &forces, &config, &mut meter);
        integrator.step(&mut ctx, &mut state, h).unwrap();
        out.push(energy(&state));
        if out[out.len() - 1] > 1e3 * out[0] {
            break;
        }
    }
    out
}

#[test]
fn explicit_euler_gains_exactly_one_plus_z_squared_per_step() {
    // x' = x + h·v, v' = v − hω²x: the cross terms cancel and E' = E·(1 + z²) exactly.
    for z in [0.1f32, 0.5, 1.0, 3.0] {
        let e = oscillator_energies(IntegratorKind::ExplicitEuler, z, 20);
        assert!(e.len() > 3, "z = {z}: only {} steps", e.len());
        let expected = 1.0 + (z as f64).powi(2);
        for (n, w) in e.windows(2).enumerate() {
            let ratio = w[1] / w[0];
            assert!(
                (ratio - expected).abs() < 1e-4 * expected,
                "z = {z}, step {n}: ratio {ratio}, expected {expected}"
            );
        }
    }
}

#[test]
fn implicit_euler_loses_exactly_one_over_one_plus_z_squared_per_step() {
    // (ωx', v') solves a scaled rotation: |(ωx', v')| = |(ωx, v)| / √(1 + z²), so the
    // energy shrinks by 1/(1 + z²) at any step, however large.
    // Once the amplitude has shrunk below a few mm the stretch `|d| − 1` keeps too few
    // digits in f32 for a 1e-4 comparison: steps are checked while E ≥ 5 % of E₀.
    for z in [0.1f32, 0.5, 2.0, 10.0] {
        let e = oscillator_energies(IntegratorKind::ImplicitEuler, z, 10);
        let expected = 1.0 / (1.0 + (z as f64).powi(2));
        let checked = e.windows(2).take_while(|w| w[0] >= 0.05 * e[0]);
        for (n, w) in checked.enumerate() {
            let ratio = w[1] / w[0];
            assert!(
                (ratio - expected).abs() < 1e-4 * expected,
                "z = {z}, step {n}: ratio {ratio}, expected {expected}"
            );
        }
    }
}

/// Largest energy over the run as a multiple of the start.
fn peak_ratio(energies: &[f64]) -> f64 {
    energies.iter().copied().fold(0.0, f64::max) / energies[0]
}

#[test]
fn symplectic_euler_and_verlet_are_stable_below_z_2_and_blow_up_above() {
    for kind in [IntegratorKind::SemiImplicitEuler, IntegratorKind::Verlet] {
        // Below the limit each conserves a modified energy, so ½mv² + ½kx² stays bounded:
        // from rest at x₀ it peaks at 1/(1 − z/2) = 20 times its start for symplectic Euler
        // and at its start for velocity Verlet, over any number of steps.
        // (1 % more allows for rounding over 5000 steps.)
        let below = peak_ratio(&oscillator_energies(kind, 1.9, 5000));
        assert!(below <= 20.2, "{kind} at z = 1.9: energy grew {below}×");
        // Above it an eigenvalue has modulus 1.88 at z = 2.1: the energy grows 3.5× a step.
        let above = oscillator_energies(kind, 2.1, 40);
        assert!(
            peak_ratio(&above) > 1e3,
            "{kind} at z = 2.1: energy stayed bounded"
        );
        assert!(
            above.len() < 20,
            "{kind} at z = 2.1: took {} steps to grow",
            above.len()
        );
    }
}

#[test]
fn rk4_is_stable_up_to_z_2_83_and_not_beyond() {
    // RK4's amplification on the imaginary axis: |R(iz)|² = 1 − z⁶/72 + z⁸/576, below 1
    // for z < 2√2 ≈ 2.83. At z = 2.7 it is 0.52 (the energy decays), at z = 2.9 it is 1.42.
    let below = oscillator_energies(IntegratorKind::Rk4, 2.7, 2000);
    assert!(peak_ratio(&below) <= 1.0 + 1e-6, "grew at z = 2.7");
    assert!(
        below.last().unwrap() < &(below[0] * 1e-6),
        "RK4 damps at z = 2.7"
    );
    let above = oscillator_energies(IntegratorKind::Rk4, 2.9, 200);
    assert!(peak_ratio(&above) > 1e3, "z = 2.9: energy stayed bounded");
    assert!(
        above.len() < 40,
        "z = 2.9: took {} steps to grow a thousandfold",
        above.len()
    );
}

/// `hanging` without dissipation, with a `quads` × `quads` cloth.
fn undamped_hanging(quads: u32) -> Scene {
    let mesh = GridSpec::square(quads, 1.0, GridOrientation::Horizontal, Vec3::ZERO)
        .build()
        .unwrap();
    let cloth = MeshBuild::from(mesh);
    let mut scene = Scene::with_cloth("hanging", &cloth, "grid").unwrap();
    for e in &mut scene.effects {
        if let Effect::AirDamping(a) = e {
            a.rate = 0.0;
        }
    }
    scene.params.material.damping = [0.0; 3];
    scene
}

/// Positions after `seconds` in `steps` equal steps of `kind` (no guard).
fn positions_after(scene: &Scene, kind: IntegratorKind, seconds: f32, steps: u32) -> Vec<Vec3> {
    let mut scene = scene.clone();
    scene.params.step.integrator = kind;
    scene.params.step.dt = seconds;
    scene.params.step.substeps = steps;
    let mut sim = Simulation::new(scene);
    for _ in 0..steps {
        sim.substep().unwrap();
    }
    sim.state().pos.clone()
}

fn rms_distance(a: &[Vec3], b: &[Vec3]) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| x.distance_squared(*y) as f64)
        .sum();
    (sum / a.len() as f64).sqrt()
}

/// Error ratios `e(h) / e(h/2)` of `kind` over `seconds`, for the step counts `steps`
/// (each the double of the one before), against RK4 with `reference_steps`.
fn halving_ratios(
    scene: &Scene,
    kind: IntegratorKind,
    seconds: f32,
    steps: [u32; 3],
    reference_steps: u32,
) -> [f64; 2] {
    let reference = positions_after(scene, IntegratorKind::Rk4, seconds, reference_steps);
    let e = steps.map(|n| rms_distance(&positions_after(scene, kind, seconds, n), &reference));
    [e[0] / e[1], e[1] / e[2]]
}

/// Halving the step divides a method of order p's error by 2ᵖ once the step is small
/// enough for the leading error term to dominate, and large enough for the error to stay
/// far above f32 rounding (about 1e-6 m after a few hundred steps). With the default 24 × 24
/// cloth at 400 N/m, RK4's error is below that rounding at every step where it is stable,
/// so the scene is `hanging` undamped with a coarse 6 × 6-quad cloth and springs a hundred
/// times softer (4 N/m): its fastest mode allows steps of 10–20 ms. The steps were chosen
/// in the asymptotic range of each method (measured ratios: first order 1.94–2.10, second
/// 4.00–4.12, RK4 15.1–15.2). The bands (±10 % of 2ᵖ, ±20 % for RK4, whose next term is
/// relatively larger) reject a method of any other order.
#[test]
fn halving_the_step_divides_the_error_by_two_to_the_order() {
    let mut scene = undamped_hanging(6);
    scene.params.material.stiffness = scene.params.material.stiffness.map(|k| k * 0.01);
    let cases = [
        (IntegratorKind::ExplicitEuler, 0.5, [400, 800, 1600], 800),
        (
            IntegratorKind::SemiImplicitEuler,
            0.5,
            [400, 800, 1600],
            800,
        ),
        (IntegratorKind::ImplicitEuler, 0.5, [400, 800, 1600], 800),
        (IntegratorKind::Xpbd, 0.5, [400, 800, 1600], 800),
        (IntegratorKind::Vbd, 0.5, [400, 800, 1600], 800),
        (IntegratorKind::Verlet, 0.5, [100, 200, 400], 800),
        (IntegratorKind::Rk2, 0.5, [100, 200, 400], 800),
        (IntegratorKind::Rk4, 1.0, [50, 100, 200], 1600),
    ];
    for (kind, seconds, steps, reference) in cases {
        let expected = 2f64.powi(kind.order() as i32);
        let band = if kind.order() == 4 { 0.2 } else { 0.1 };
        for ratio in halving_ratios(&scene, kind, seconds, steps, reference) {
            assert!(
                (ratio / expected - 1.0).abs() <= band,
                "{kind}: halving the step divided the error by {ratio:.2}, expected {expected} ± {:.0} %",
                100.0 * band
            );
        }
    }
}

/// Runs `scene` for `seconds` with `kind`, substep by substep and without the guard; returns
/// whether it stayed finite and below 100 m/s, the peak speed, and the final state's largest
/// structural strain.
fn unguarded(scene: &Scene, kind: IntegratorKind, seconds: f64) -> (bool, f32, f32) {
    let mut scene = scene.clone();
    scene.params.step.integrator = kind;
    let mut sim = Simulation::new(scene);
    let steps = (seconds / sim.substep_length() as f64).round() as usize;
    let mut peak = 0.0f32;
    for _ in 0..steps {
        if sim.substep().is_err() || !sim.state().is_finite() {
            return (false, f32::INFINITY, f32::INFINITY);
        }
        peak = peak.max(sim.state().max_speed());
        if peak > 100.0 {
            return (false, peak, f32::INFINITY);
        }
    }
    (true, peak, max_strain(&sim, SpringKind::Structural))
}

/// Largest relative extension of the springs of `kind`.
fn max_strain(sim: &Simulation, kind: SpringKind) -> f32 {
    let (s, pos) = (&sim.model().springs, &sim.state().pos);
    (0..s.len())
        .filter(|&e| s.kind[e] == kind)
        .map(|e| pos[s.a[e] as usize].distance(pos[s.b[e] as usize]) / s.rest[e] - 1.0)
        .fold(0.0, f32::max)
}

/// Story: stiff cloth is where explicit methods fail users. At a hundred times the default
/// stiffness and the default 48 substeps, every explicit method passes 100 m/s (or goes
/// non-finite) within a second; implicit Euler stays finite, slow and unstretched.
#[test]
fn implicit_euler_survives_stiffness_where_every_explicit_method_blows_up() {
    let mut scene = Scene::builtin("hanging").unwrap();
    scene.params.material.stiffness = scene.params.material.stiffness.map(|k| k * 100.0);
    for kind in [
        IntegratorKind::ExplicitEuler,
        IntegratorKind::SemiImplicitEuler,
        IntegratorKind::Verlet,
        IntegratorKind::Rk2,
        IntegratorKind::Rk4,
    ] {
        let (bounded, peak, _) = unguarded(&scene, kind, 1.0);
        assert!(
            !bounded,
            "{kind} stayed bounded (peak {peak} m/s): not a step beyond its limit"
        );
    }
    for kind in [IntegratorKind::ImplicitEuler, IntegratorKind::Vbd] {
        let (bounded, peak, strain) = unguarded(&scene, kind, 1.0);
        assert!(bounded, "{kind} blew up");
        // A cloth swinging down from 1.8 m moves at a few m/s (free fall over 1 m: 4.4 m/s).
        assert!(peak < 10.0, "{kind} reached {peak} m/s");
        assert!(strain < 0.01, "{kind} stretched {:.2} %", 100.0 * strain);
    }
}

/// Energy after one step of `kind` over energy before, for two free unit masses on a spring
/// of stiffness `K` (`ω² = 2K/M`) at `ωh = z`, starting stretched `X0` from rest, with
/// `sweeps` sweeps for the iterative methods. The masses move along the spring only, where
/// its force is linear.
fn pair_energy_ratio(kind: IntegratorKind, sweeps: u32, z: f32) -> f64 {
    let mut springs = Springs::default();
    springs.a.push(0);
    springs.b.push(1);
    springs.rest.push(1.0);
    springs.kind.push(SpringKind::Structural);
    let start = vec![Vec3::new(-0.5, 0.0, 0.0), Vec3::new(0.5, 0.0, 0.0)];
    let model = ClothModel::from_springs(start, springs, vec![M, M], &[]);
    let forces = ForceSet::from_terms(vec![Force::new(
        "springs",
        SpringForce::new(&model.springs, [K; 3], [0.0; 3]),
    )]);
    let h = z / (2.0 * K / M).sqrt();
    let mut state = ClothState::at_rest(&model);
    state.pos[0].x -= 0.5 * X0;
    state.pos[1].x += 0.5 * X0;
    let energy = |s: &ClothState| {
        let stretch = (s.pos[1].x - s.pos[0].x) as f64 - 1.0;
        let kinetic: f64 = s.vel.iter().map(|v| v.length_squared() as f64).sum();
        0.5 * M as f64 * kinetic + 0.5 * K as f64 * stretch * stretch
    };
    let config = SolverConfig {
        vbd_iterations: sweeps,
        xpbd_iterations: sweeps,
        tolerance: 1e-6,
        ..SolverConfig::default()
    };
    let before = energy(&state);
    let mut meter = StepMeter::default();
    let mut ctx = StepContext::new(&model, &forces, &config, &mut meter);
    kind.build().step(&mut ctx, &mut state, h).unwrap();
    energy(&state) / before
}

/// Story: VBD minimises implicit Euler's objective one particle at a time, so as its sweeps
/// grow a step keeps what implicit Euler's would: `1/(1 + z²)` of the energy on an
/// undamped spring. Two free masses make each sweep a Gauss–Seidel pass (one free mass
/// would be solved exactly by its first Newton step): the error falls at least tenfold per
/// doubling of the sweeps, from a visible one at a single sweep to f32's floor, as fast as
/// a Newton block with the springs' stiffness in it makes it.
#[test]
fn vbd_approaches_implicit_eulers_energy_law_as_its_sweeps_grow() {
    let z = 1.0;
    let law = 1.0 / (1.0 + (z * z) as f64);
    let implicit = pair_energy_ratio(IntegratorKind::ImplicitEuler, 1, z);
    assert!(
        (implicit / law - 1.0).abs() < 1e-4,
        "implicit Euler kept {implicit}, the law says {law}"
    );
    let errors: Vec<f64> = [1, 2, 4, 8]
        .map(|sweeps| (pair_energy_ratio(IntegratorKind::Vbd, sweeps, z) / law - 1.0).abs())
        .to_vec();
    // Measured: 3.7e-2, 4.5e-4, 1.9e-5, 2.2e-7. Without the springs in the Newton block
    // (a step of −g/m) the sweeps still converge, to 0.38, 8.6e-2, 3.3e-3, 1.1e-5.
    assert!(errors[0] > 1e-2, "one sweep already exact: {errors:?}");
    for pair in errors.windows(2) {
        assert!(pair[1] <= 0.1 * pair[0], "{errors:?}");
    }
    assert!(errors[1] < 1e-3 && errors[3] < 1e-6, "{errors:?}");
}

/// VBD's first guess follows the last step's whole acceleration (scaled down to the
/// external acceleration's size where larger): at N/2 substeps of one sweep, the bench
/// cloth's centre follows the reference's swing (semi-implicit Euler at N substeps, the
/// bench's definition) within 3 mm over the bench's two seconds, in which it swings down
/// 17.8 mm (measured: 1.7 mm). With Chen et al.'s adaptive start (the last acceleration's part along the
/// external one) it was 14.2 mm off in the first second: one sweep a substep let the cloth
/// fall nearly freely. With the whole last acceleration uncapped it was 17 cm off by 2 s:
/// the solve's own error fed back until the cloth blew up.
#[test]
fn vbd_follows_the_bench_cloths_swing_at_half_the_substeps() {
    let n = 24;
    let bench = |kind| Simulation::new(clothsim::bench::bench_scene(n, kind).unwrap());
    let (mut reference, mut vbd) = (
        bench(IntegratorKind::SemiImplicitEuler),
        bench(IntegratorKind::Vbd),
    );
    assert_eq!(vbd.params().step.substeps, n / 2);
    let centre = (n / 2 * n + n / 2) as usize;
    let y0 = reference.state().pos[centre].y;
    let (mut worst, mut deepest) = (0.0f32, 0.0f32);
    for _ in 0..120 {
        reference.step_frame().expect("reference frame");
        vbd.step_frame().expect("vbd frame");
        let sag = |sim: &Simulation| y0 - sim.state().pos[centre].y;
        worst = worst.max((sag(&reference) - sag(&vbd)).abs());
        deepest = deepest.max(sag(&reference));
    }
    eprintln!("VBD's centre at most {worst:e} m off the reference's");
    assert!(deepest > 0.015, "the reference swings down {deepest} m");
    assert!(
        worst < 3e-3,
        "VBD's centre is {worst} m off the reference's"
    );
}

/// A chain of `N` masses `m` below a pin, each link `l` long, settled under gravity with
/// XPBD at link stiffness `k` and `substeps` per 10 ms frame; returns its extension, metres.
fn xpbd_chain_extension(k: f32, substeps: u32) -> f32 {
    const N: usize = 10;
    let (m, l) = (0.1f32, 0.1f32);
    let pos: Vec<Vec3> = (0..=N)
        .map(|i| Vec3::new(0.0, -(i as f32) * l, 0.0))
        .collect();
    let mut springs = Springs::default();
    for i in 0..N as u32 {
        springs.a.push(i);
        springs.b.push(i + 1);
        springs.rest.push(l);
        springs.kind.push(SpringKind::Structural);
    }
    let model = ClothModel::from_springs(pos, springs, vec![m; N + 1], &[0]);
    let params = clothsim::sim::SimParams {
        step: clothsim::sim::StepConfig {
            integrator: IntegratorKind::Xpbd,
            dt: 0.01,
            substeps,
        },
        material: clothsim::sim::Material {
            stiffness: [k; 3],
            damping: [0.5; 3],
            ..Default::default()
        },
        ..Default::default()
    };
    let effects = [
        Effect::Gravity(Default::default()),
        Effect::Springs(Default::default()),
        Effect::AirDamping(clothsim::sim::AirDamping { rate: 1.0 }),
    ];
    let mut stepper = clothsim::sim::CpuStepper::new(&model, &params, &effects);
    let mut state = ClothState::at_rest(&model);
    use clothsim::sim::StepBackend;
    for _ in 0..3000 {
        stepper.frame(&model, &mut state).unwrap();
    }
    // At rest to within f32's resolution of a velocity rebuilt from a displacement
    // (a rounding unit of a position near 1 m over a 0.25 ms step is 0.2 mm/s).
    assert!(
        state.max_speed() < 1e-3,
        "k = {k}: not at rest ({} m/s)",
        state.max_speed()
    );
    (state.pos[0].y - state.pos[N].y) - N as f32 * l
}

/// XPBD sees a spring of stiffness k as a constraint of compliance 1/k. At rest its links
/// stretch as springs do — link i carries (N − i) weights, so the chain stretches
/// m·g·N(N+1)/(2k) — up to an error of order (ωh)² (ω = √(k/m)): checked at ωh ≤ 0.1
/// (k ≤ 1000 N/m; at k = 1e4, ωh = 0.32, it stretches 8.6 % more). As the compliance goes
/// to zero the chain becomes inextensible.
#[test]
fn xpbd_matches_spring_statics_and_approaches_the_inextensible_limit() {
    let statics = |k: f32| 0.1 * 9.81 * 55.0 / k;
    let mut last = f32::INFINITY;
    for k in [1e2f32, 1e3, 1e4, 1e6, 1e9] {
        let extension = xpbd_chain_extension(k, 10);
        assert!(
            extension < last,
            "k = {k}: {extension} m is not below {last} m"
        );
        last = extension;
        if k <= 1e3 {
            let expected = statics(k);
            assert!(
                (extension - expected).abs() < 0.02 * expected,
                "k = {k}: stretched {extension} m, springs stretch {expected} m"
            );
        }
    }
    // What stretch remains at zero compliance comes from the step: each substep gravity
    // moves every particle g·h² before the one sweep, about N(N+1)/2·g·h² = 0.54 mm over
    // the chain at h = 1 ms. It is under 0.1 % of the chain's length, and shrinks as h²:
    // four times the substeps leave a sixteenth.
    assert!(
        last < 1e-3,
        "at compliance 1e-9 m/N the chain still stretches {last} m"
    );
    let finer = xpbd_chain_extension(1e9, 40);
    assert!(
        finer < last / 10.0,
        "with h/4 the stretch went from {last} m only to {finer} m"
    );
}

/// Semi-implicit Euler sums the usual scene's forces on one array per component (a vector
/// loop per term, fused with the update per range of particles); the general path sums them
/// per vector. Same operations in the same order: the same bits, step after step, with pins,
/// air damping, bend springs and motion in all three directions, on one thread below the
/// parallel size and on two above it (the spring blocks and the ranges shared out).
#[test]
fn semi_implicit_euler_on_component_arrays_matches_the_general_path_bit_for_bit() {
    const { assert!(64 * 64 >= clothsim::parallel::PARALLEL_ELEMENTS) };
    for (n, threads) in [(24, 1), (64, 2)] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| component_arrays_match_the_general_path(n));
    }
}

fn component_arrays_match_the_general_path(n: u32) {
    use clothsim::sim::integrator::SemiImplicitEuler;
    use clothsim::sim::{Effect, Integrator};
    let scene = clothsim::bench::bench_scene(n, IntegratorKind::SemiImplicitEuler).unwrap();
    let model = &scene.model;
    // The scene's terms (springs first: the fused path overwrites the forces with them),
    // springs and gravity alone, and gravity first (the forces zeroed before it).
    let mut springs_and_gravity = scene.effects.clone();
    springs_and_gravity.retain(|e| matches!(e, Effect::Springs(_) | Effect::Gravity(_)));
    let mut gravity_first = scene.effects.clone();
    gravity_first.retain(|e| !matches!(e, Effect::Gravity(_)));
    gravity_first.insert(0, Effect::Gravity(Default::default()));
    for effects in [scene.effects.clone(), springs_and_gravity, gravity_first] {
        let forces = ForceSet::new(model, &scene.params.material, &effects);
        assert!(forces.takes_components(), "{effects:?}");
        let mut start = scene.initial.clone();
        for (p, v) in start.vel.iter_mut().enumerate() {
            let s = (p as f32 * 0.37).sin();
            *v = Vec3::new(0.3 * s, -0.2 * s * s, 0.5 * (p as f32 * 0.11).cos());
        }
        let (config, mut meter) = (SolverConfig::default(), StepMeter::default());
        // The bench's substep for this size (stable).
        let h = 1.0 / (60.0 * n as f32);
        let mut run = |mut integrator: SemiImplicitEuler| {
            let mut state = start.clone();
            for _ in 0..300 {
                let mut ctx = StepContext::new(model, &forces, &config, &mut meter);
                integrator.step(&mut ctx, &mut state, h).unwrap();
            }
            state
        };
        let (fast, general) = (
            run(SemiImplicitEuler::default()),
            run(SemiImplicitEuler::whole_vectors()),
        );
        let moved = fast.pos.iter().zip(&start.pos).map(|(a, b)| a.distance(*b));
        assert!(moved.fold(0.0, f32::max) > 0.01, "the cloth hardly moved");
        assert!(
            fast.pos == general.pos && fast.vel == general.vel,
            "{n} × {n}: {effects:?}"
        );
        assert_eq!(fast.time, general.time);
    }
}

/// Checks that the bench cloth of `n` × `n` particles under `kind`, advanced by `advance`,
/// ends in the same bits on two threads as on one, and that it moved.
fn same_bits_on_two_threads(n: u32, kind: IntegratorKind, advance: fn(&mut Simulation)) {
    let scene = || clothsim::bench::bench_scene(n, kind).unwrap();
    let run = |threads: usize| {
        let mut sim = Simulation::new(scene());
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| advance(&mut sim));
        sim.state().clone()
    };
    let (one, two) = (run(1), run(2));
    let start = scene().initial;
    let moved = (one.pos.iter().zip(&start.pos)).map(|(a, b)| a.distance(*b));
    assert!(
        moved.fold(0.0, f32::max) > 1e-4,
        "{kind}: the cloth hardly moved"
    );
    assert!(one.pos == two.pos && one.vel == two.vel, "{kind}");
}

/// XPBD sweeps the two halves of the cloth at the same time on two threads, then shares out
/// the seam's large colours; what runs at the same time shares no particle, so two threads
/// give the same bits as one.
#[test]
fn xpbd_on_two_threads_gives_the_same_bits_as_on_one() {
    same_bits_on_two_threads(48, IntegratorKind::Xpbd, |sim| {
        for _ in 0..60 {
            sim.substep().unwrap();
        }
    });
}

/// VBD shares each colour of at least 1 024 particles out between threads in fixed pieces
/// (a 128 × 128 cloth's colours hold about 1 400); a colour's particles share no spring,
/// so two threads give the same bits as one.
#[test]
fn vbd_on_two_threads_gives_the_same_bits_as_on_one() {
    same_bits_on_two_threads(128, IntegratorKind::Vbd, |sim| {
        for _ in 0..20 {
            sim.substep().unwrap();
        }
    });
}

/// [`same_bits_on_two_threads`] over three frames of an `n` × `n` cloth, large enough for
/// the per-particle loops to be shared.
fn frames_on_two_threads(n: u32, kind: IntegratorKind) {
    assert!((n * n) as usize >= clothsim::parallel::PARALLEL_ELEMENTS);
    same_bits_on_two_threads(n, kind, |sim| {
        for _ in 0..3 {
            sim.step_frame().unwrap();
        }
    });
}

/// From 64 × 64 particles implicit Euler's conjugate gradients share each iteration's
/// loops over particles between threads in pieces of whole blocks, and the dot products add
/// the blocks' sums in order; so two threads give the same bits as one, frame after frame.
#[test]
fn implicit_euler_on_two_threads_gives_the_same_bits_as_on_one() {
    frames_on_two_threads(72, IntegratorKind::ImplicitEuler);
}

/// From 64 × 64 particles semi-implicit Euler shares out its per-particle loops
/// (forces of gravity and air, the update) as well as the springs between threads; each
/// particle's work is its own, so two threads give the same bits as one, frame after frame.
#[test]
fn semi_implicit_euler_on_two_threads_gives_the_same_bits_as_on_one() {
    frames_on_two_threads(96, IntegratorKind::SemiImplicitEuler);
}

/// The explicit integrators get their accelerations through `StepContext::accelerations`,
/// which sums them on component arrays when every term allows it: along a moving cloth's
/// trajectory they are the same bits as the general per-vector sum (`ForceSet::accelerations`),
/// so every explicit integrator steps exactly as before.
#[test]
fn accelerations_on_component_arrays_match_the_general_path_bit_for_bit() {
    let scene = clothsim::bench::bench_scene(20, IntegratorKind::SemiImplicitEuler).unwrap();
    let model = &scene.model;
    let forces = ForceSet::new(model, &scene.params.material, &scene.effects);
    assert!(forces.takes_components());
    let mut state = scene.initial.clone();
    for (p, v) in state.vel.iter_mut().enumerate() {
        let s = (p as f32 * 0.23).sin();
        *v = Vec3::new(0.4 * s, 0.1 * s * s, -0.3 * (p as f32 * 0.07).cos());
    }
    let start = state.clone();
    let (config, mut meter) = (SolverConfig::default(), StepMeter::default());
    let mut rk4 = IntegratorKind::Rk4.build();
    let (mut fast, mut general) = (Vec::new(), Vec::new());
    for step in 0..100 {
        let mut ctx = StepContext::new(model, &forces, &config, &mut meter);
        ctx.accelerations(&state.pos, &state.vel, &mut fast);
        forces.accelerations(model, &state.pos, &state.vel, &mut general);
        let bits = |a: &[Vec3]| -> Vec<[u32; 3]> {
            a.iter().map(|v| v.to_array().map(f32::to_bits)).collect()
        };
        assert!(bits(&fast) == bits(&general), "step {step}");
        rk4.step(&mut ctx, &mut state, 1.0 / 2400.0).unwrap();
    }
    let moved = state
        .pos
        .iter()
        .zip(&start.pos)
        .map(|(x, y)| x.distance(*y));
    assert!(moved.fold(0.0, f32::max) > 0.005, "the cloth hardly moved");
}

/// Implicit Euler on the bench cloth (24 × 24, 5 substeps a frame) for `steps` steps from
/// `start`: the end state and the conjugate-gradient iterations it took.
fn implicit_run(
    integrator: &mut clothsim::sim::integrator::ImplicitEuler,
    start: &ClothState,
    steps: usize,
) -> (ClothState, u32) {
    implicit_run_at(integrator, start, steps, 1.0 / 300.0)
}

/// As [`implicit_run`], with steps of `h` seconds.
fn implicit_run_at(
    integrator: &mut clothsim::sim::integrator::ImplicitEuler,
    start: &ClothState,
    steps: usize,
    h: f32,
) -> (ClothState, u32) {
    use clothsim::sim::Integrator;
    let scene = clothsim::bench::bench_scene(24, IntegratorKind::ImplicitEuler).unwrap();
    let forces = ForceSet::new(&scene.model, &scene.params.material, &scene.effects);
    let (config, mut meter) = (SolverConfig::default(), StepMeter::default());
    let (mut state, mut iterations) = (start.clone(), 0);
    for _ in 0..steps {
        let mut ctx = StepContext::new(&scene.model, &forces, &config, &mut meter);
        integrator.step(&mut ctx, &mut state, h).unwrap();
        iterations += meter.solver_iterations;
    }
    (state, iterations)
}

/// Each implicit step's solve starts from the last two steps' Δv extrapolated: fewer
/// iterations than from the last Δv alone, to the same tolerance, so the same cloth.
#[test]
fn implicit_euler_extrapolated_guess_saves_iterations_and_changes_nothing_else() {
    use clothsim::sim::integrator::ImplicitEuler;
    let scene = clothsim::bench::bench_scene(24, IntegratorKind::ImplicitEuler).unwrap();
    let (extrapolated, fewer) = implicit_run(&mut ImplicitEuler::default(), &scene.initial, 300);
    let (last, more) = implicit_run(&mut ImplicitEuler::last_step_guess(), &scene.initial, 300);
    assert!(
        (fewer as f64) < 0.95 * more as f64,
        "{fewer} iterations extrapolated vs {more} from the last Δv"
    );
    let sag = |s: &ClothState| {
        let moved = s
            .pos
            .iter()
            .zip(&scene.initial.pos)
            .map(|(a, b)| a.distance(*b));
        moved.fold(0.0, f32::max)
    };
    let apart = extrapolated
        .pos
        .iter()
        .zip(&last.pos)
        .map(|(a, b)| a.distance(*b));
    let apart = apart.fold(0.0, f32::max);
    assert!(sag(&last) > 5e-3, "the cloth hardly moved: {}", sag(&last));
    // (1.2e-7 m here: both solves stop within the tolerance of the same solution.)
    assert!(apart < 1e-4 * sag(&last), "{apart} m apart");
}

/// After the state was changed outside (`invalidate`), the next solve starts from zero:
/// the same bits as a fresh integrator, where a guess from the earlier steps would not be.
#[test]
fn implicit_euler_forgets_its_guess_when_the_state_changes_outside() {
    use clothsim::sim::Integrator;
    use clothsim::sim::integrator::ImplicitEuler;
    let scene = clothsim::bench::bench_scene(24, IntegratorKind::ImplicitEuler).unwrap();
    let mut used = ImplicitEuler::default();
    let (mut moved, _) = implicit_run(&mut used, &scene.initial, 40);
    for v in &mut moved.vel {
        *v = -*v;
    }
    let (fresh, _) = implicit_run(&mut ImplicitEuler::default(), &moved, 1);
    let mut stale = ImplicitEuler::default();
    implicit_run(&mut stale, &scene.initial, 40);
    let (guessed, _) = implicit_run(&mut stale, &moved, 1);
    assert!(guessed.pos != fresh.pos, "the guess made no difference");
    used.invalidate();
    let (after, _) = implicit_run(&mut used, &moved, 1);
    assert!(after.pos == fresh.pos && after.vel == fresh.vel);
    // Nor is a history of other step lengths a guess (Δv scales with the step): a step of
    // half the length starts from zero too.
    let half = 1.0 / 600.0;
    let (fresh, _) = implicit_run_at(&mut ImplicitEuler::default(), &moved, 1, half);
    let (after, _) = implicit_run_at(&mut stale, &moved, 1, half);
    assert!(
        after.pos == fresh.pos && after.vel == fresh.vel,
        "half the step"
    );
}

/// A material change in a running simulation (stiffness, damping, density) takes only the
/// parts it changes: the springs are retuned in place, the masses rescaled, whatever an
/// integrator derived from them dropped. The next frames are then the same bits as those of
/// a simulation built afresh with the new material from the same state, under every
/// integrator (each keeps something: Verlet its acceleration, implicit Euler its warm
/// start, XPBD its constraints' compliances).
#[test]
fn a_material_change_mid_run_steps_as_a_fresh_build_would() {
    type Edit = fn(&mut clothsim::sim::Material);
    let edits: [(&str, Edit); 3] = [
        ("stiffness", |m| m.stiffness = m.stiffness.map(|k| 3.0 * k)),
        ("damping", |m| m.damping[0] *= 4.0),
        ("density", |m| m.density *= 2.0),
    ];
    for kind in IntegratorKind::ALL {
        for (what, edit) in edits {
            let mut scene = Scene::builtin("sphere-drop").unwrap();
            scene.params.step.integrator = kind;
            // Within each method's stable step at the stiffer setting: the guard stays out
            // (substeps it raised would stay in the running simulation, not in a fresh one).
            scene.params.step.substeps = match kind {
                IntegratorKind::ExplicitEuler => 2048,
                IntegratorKind::Rk2 => 256,
                _ => 96,
            };
            let mut running = Simulation::new(scene);
            for _ in 0..10 {
                running.step_frame().unwrap();
            }
            let mut params = running.params().clone();
            edit(&mut params.material);
            running.set_params(params).unwrap();
            let mut fresh = running.fork();
            for _ in 0..10 {
                running.step_frame().unwrap();
                fresh.step_frame().unwrap();
            }
            let bits = |s: &Simulation| -> Vec<[u32; 3]> {
                (s.state().pos.iter())
                    .map(|p| p.to_array().map(f32::to_bits))
                    .collect()
            };
            let events = [running.take_guard_events(), fresh.take_guard_events()];
            assert_eq!(events, [vec![], vec![]], "{kind:?}, new {what}");
            assert!(
                bits(&running) == bits(&fresh),
                "{kind:?}, new {what}: the running simulation and a fresh build differ"
            );
        }
    }
}
