//! The GPU backend (wgpu compute, run here on the software adapter) against the CPU solver:
//! the same scene after the same simulated time.

use clothsim::bench::BENCH_SECONDS;
use clothsim::device::{AdapterPreference, HeadlessDevice};
use clothsim::gpu::{Backend, gpu_support};
use clothsim::scene::{Scene, Simulation};
use clothsim::sim::{Effect, IntegratorKind, Precision};

mod common;
use common::{WEDGE_RADIUS, farthest, gpu_simulation, wedge};

/// Runs `scene` for `seconds` on both backends; the largest distance between the same
/// particle's positions, and the largest distance any particle moved (for scale).
fn compare(scene: Scene, frames: usize) -> (f32, f32, Simulation) {
    let start = scene.initial.pos.clone();
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend on the software adapter");
    assert_eq!(gpu.backend_name(), "gpu");
    for _ in 0..frames {
        cpu.step_frame().expect("cpu frame");
        gpu.step_frame().expect("gpu frame");
    }
    gpu.sync_state().expect("read back");
    assert!((cpu.state().time - gpu.state().time).abs() < 1e-9);
    let worst = farthest(&cpu.state().pos, &gpu.state().pos);
    let moved = farthest(&cpu.state().pos, &start);
    (worst, moved, gpu)
}

#[test]
fn gpu_and_cpu_agree_on_every_particle_of_the_hanging_cloth_after_one_second() {
    let scene = clothsim::bench::bench_scene(16, IntegratorKind::SemiImplicitEuler).expect("scene");
    let (worst, moved, _) = compare(scene, 60);
    eprintln!("hanging-bench: worst {worst:e} m of {moved} m moved");
    assert!(moved > 0.005, "the cloth sags");
    assert!(worst < 1e-5, "GPU and CPU differ by {worst} m");
}

/// A cloth hitting a sphere at 3 m/s crumples chaotically (on the CPU alone, moving every
/// particle by 1 µm at the start moves the result by millimetres within a second), so the
/// contacts are compared over the frames around the first impact, where the sphere and
/// the plane are resolved on both backends but no fold has amplified rounding yet. The
/// sphere keeps the cloth's faces at the offset, so a particle it holds lies up to a
/// cell's sag above it (0.5–0.9 mm here), not at the offset.
#[test]
fn gpu_and_cpu_resolve_the_same_sphere_contacts_at_impact() {
    let scene = Scene::builtin("sphere-drop").expect("scene");
    let offset = scene.params.contact.offset;
    let sphere = (scene.effects.iter())
        .find(|e| e.is_solid())
        .cloned()
        .expect("a sphere");
    let (worst, moved, gpu) = compare(scene, 20);
    eprintln!("sphere-drop: worst {worst:e} m of {moved} m moved");
    assert!(moved > 0.3, "the cloth falls");
    let touching = gpu
        .state()
        .pos
        .iter()
        .filter(|&&p| sphere.surface(p, 0.0).is_some_and(|s| s.0 < offset + 1e-3))
        .count();
    assert!(
        touching >= 4,
        "the cloth lies on the sphere ({touching} particles)"
    );
    assert!(worst < 1e-5, "GPU and CPU differ by {worst} m");
}

/// `rotating-sphere` at 6 quads (17 cm), without self-collision: its sphere of 40 cm rises
/// 9 mm under a cell's corners, about the offset they keep, and on the GPU as on the CPU
/// each triangle is kept out of it, not only its corners. The exact check finds no
/// triangle through the sphere after any frame of the first second, and over the first
/// 10 frames (6 on the sphere) the backends agree to 10 µm (measured 2.8 µm; the
/// spinning sphere's friction then parts them faster than without the face pass, 12 mm at
/// 1 s against 0.65 mm). Kept out by their particles alone, 12 of the cloth's triangles
/// met the sphere by 0.5 s on both; with each corner taking the whole of a face's change
/// of velocity (where it bears a rounding of the contact, the GPU's or the CPU's), the
/// backends parted by 0.2 mm at the first touch.
#[test]
fn a_coarse_cloth_on_the_gpu_never_meets_its_sphere() {
    let options = clothsim::mesh::ImportOptions::default();
    let scene = Scene::open_resized("rotating-sphere", None, &options, Some(6)).expect("scene");
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend on the software adapter");
    for frame in 0..60 {
        gpu.step_frame().expect("gpu frame");
        let found = gpu.intersections();
        assert_eq!(found.total(), 0, "frame {frame}: {found:?}");
        if frame < 10 {
            cpu.step_frame().expect("cpu frame");
        }
        if frame == 9 {
            let apart = farthest(&cpu.state().pos, &gpu.state().pos);
            eprintln!("rotating-sphere at 6 quads: {apart:e} m apart");
            assert!(apart < 1e-5, "GPU and CPU differ by {apart} m");
        }
    }
}

#[test]
fn gpu_backend_refuses_what_it_cannot_run_with_a_clear_reason() {
    let f32 = Precision::F32;
    // Self-collision runs there now.
    let fold = Scene::builtin("self-fold").expect("scene");
    gpu_support(&fold.params.step, f32, &fold.effects).expect("self-collision runs");
    let mut rk4 = Scene::builtin("hanging").expect("scene");
    rk4.params.step.integrator = IntegratorKind::Rk4;
    let err = gpu_support(&rk4.params.step, f32, &rk4.effects).expect_err("RK4 is CPU only");
    let err = err.to_string();
    let runs = "runs Semi-implicit Euler, Implicit Euler (CG), XPBD, VBD (vertex block descent) only, \
                not RK4";
    assert!(err.contains(runs), "{err}");
    assert_eq!(Backend::default(), Backend::Cpu);
    // Switching the integrator of a running GPU simulation fails the next frame, with the
    // reason, and keeps the state.
    let (mut sim, _) =
        gpu_simulation(Scene::builtin("hanging").expect("scene"), true).expect("gpu");
    sim.step_frame().expect("frame");
    let before = sim.state().clone();
    let mut params = sim.params().clone();
    params.step.integrator = IntegratorKind::Rk4;
    sim.set_params(params).expect("valid parameters");
    let err = sim.step_frame().expect_err("unsupported");
    assert!(err.reason.contains(runs), "{}", err.reason);
    assert_eq!(sim.state().pos, before.pos);
    // So does f64: refused up front with the reason, and mid-run on the next frame.
    let mut precise = Scene::builtin("hanging").expect("scene");
    precise.params.solver.precision = Precision::F64;
    let err = gpu_simulation(precise, true).err().expect("f64 refused");
    assert!(err.to_string().contains("f32 only, not f64"), "{err}");
    let mut params = sim.params().clone();
    params.step.integrator = IntegratorKind::SemiImplicitEuler;
    sim.set_params(params.clone()).expect("valid parameters");
    sim.step_frame().expect("back to what it runs");
    let before = sim.state().clone();
    params.solver.precision = Precision::F64;
    sim.set_params(params).expect("valid parameters");
    let err = sim.step_frame().expect_err("unsupported");
    assert!(err.reason.contains("f32 only, not f64"), "{}", err.reason);
    assert_eq!(sim.state().pos, before.pos);
}

/// A parameter change on a running GPU simulation reaches the shader: new spring
/// strengths, substeps and gravity, then a pin and a push, then one kind's strengths alone
/// and two effects switched off, applied mid-run on both backends, keep them together, and
/// so does a new density. Also when the GPU's state is not read back every frame (as the
/// app runs it): each edit must start from the GPU's latest frame, not from the stale copy
/// on the CPU, and a change of strengths, gravity or effects reads nothing back.
#[test]
fn a_parameter_change_mid_run_reaches_the_gpu() {
    for read_every_frame in [true, false] {
        parameter_change_mid_run(read_every_frame);
    }
}

fn parameter_change_mid_run(read_every_frame: bool) {
    let scene = clothsim::bench::bench_scene(16, IntegratorKind::SemiImplicitEuler).expect("scene");
    let mut cpu = Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, read_every_frame).expect("gpu");
    for sim in [&mut cpu, &mut gpu] {
        for _ in 0..10 {
            sim.step_frame().expect("frame");
        }
        let mut params = sim.params().clone();
        params.material.stiffness = params.material.stiffness.map(|k| 3.0 * k);
        params.step.substeps = 24;
        let behind = sim.state_behind();
        sim.set_params(params).expect("valid");
        assert_eq!(
            sim.state_behind(),
            behind,
            "a new stiffness reads nothing back"
        );
        let mut effects = sim.effects().to_vec();
        for e in &mut effects {
            if let Effect::Gravity(g) = e {
                g.acceleration = glam::Vec3::new(2.0, -5.0, 1.0);
            }
        }
        sim.set_effects(effects).unwrap();
        assert_eq!(sim.state_behind(), behind, "new gravity reads nothing back");
        for _ in 0..20 {
            sim.step_frame().expect("frame");
        }
        // Pin edits and a push, each after frames of its own.
        sim.toggle_pin(8 * 16 + 8);
        for _ in 0..5 {
            sim.step_frame().expect("frame");
        }
        sim.modify_state(|s| s.vel[20] += glam::Vec3::new(0.0, 0.0, 0.5));
        for _ in 0..5 {
            sim.step_frame().expect("frame");
        }
        // One kind's strengths apart from the others' (the GPU packs its springs anew), and
        // the bend springs and air damping switched off: the GPU keeps stepping its own
        // state, read nothing back.
        let mut params = sim.params().clone();
        params.material.stiffness[1] *= 0.25;
        params.material.damping[1] *= 4.0;
        sim.set_params(params).expect("valid");
        let mut effects = sim.effects().to_vec();
        let all = effects.len();
        effects.retain(|e| !matches!(e, Effect::Bending(_) | Effect::AirDamping(_)));
        assert_eq!(effects.len(), all - 2, "{effects:?}");
        let behind = sim.state_behind();
        sim.set_effects(effects).unwrap();
        assert_eq!(sim.state_behind(), behind, "new effects read nothing back");
        for _ in 0..5 {
            sim.step_frame().expect("frame");
        }
        // A new density rescales the masses of the latest frame, read back first.
        let mut params = sim.params().clone();
        params.material.density *= 1.5;
        sim.set_params(params).expect("valid");
        assert!(!sim.state_behind(), "the masses change on the latest state");
        for _ in 0..5 {
            sim.step_frame().expect("frame");
        }
    }
    assert_eq!(gpu.substeps(), 24);
    assert_eq!(gpu.state_behind(), !read_every_frame);
    gpu.sync_state().expect("read back");
    let worst = farthest(&cpu.state().pos, &gpu.state().pos);
    let drift = cpu
        .state()
        .pos
        .iter()
        .map(|p| p.z.abs())
        .fold(0.0, f32::max);
    assert!(drift > 1e-3, "the sideways gravity acted ({drift} m)");
    assert!(
        worst < 1e-5,
        "GPU and CPU differ by {worst} m after the change (read every frame: {read_every_frame})"
    );
}

/// The view draws the GPU backend's cloth from the stepper's display buffer: after half a
/// second stepped with nothing read back, the picture drawn from the buffer is the picture
/// of the state read back afterwards, and not that of the stale copy on the CPU.
#[test]
fn the_gpu_cloth_is_drawn_from_its_buffer_without_a_read_back() {
    use clothsim::device::AdapterPreference;
    use clothsim::gpu::GpuStepper;
    use clothsim::render::{DevicePositions, Offscreen, RenderOptions};
    use clothsim::view;

    let mut off = Offscreen::new(160, 120, AdapterPreference::Software).expect("offscreen");
    let scene = Scene::builtin("sphere-drop").expect("scene");
    let mut stepper = GpuStepper::new(
        &off.gpu.device,
        &off.gpu.queue,
        &scene.model,
        &scene.params,
        &scene.effects,
        false,
    )
    .expect("stepper");
    let display = stepper.display_buffer();
    let mut sim = Simulation::with_backend(scene, Box::new(stepper));
    let camera = view::default_camera(&sim, off.aspect());
    let options = RenderOptions::default();
    let on_device = DevicePositions {
        buffer: &display,
        stride: GpuStepper::DISPLAY_STRIDE,
    };
    // Before any step the buffer holds the uploaded start.
    sim.sync_state().expect("upload");
    let start = off
        .render(&view::frame(&sim), &camera, &options)
        .expect("image");
    let mut frame = view::frame(&sim);
    frame.device_positions = Some(on_device);
    let first = off.render(&frame, &camera, &options).expect("image");
    assert_eq!(start.as_raw(), first.as_raw(), "the buffer holds the start");

    for _ in 0..30 {
        sim.step_frame().expect("frame");
    }
    assert!(sim.state_behind(), "nothing was read back while stepping");
    let mut frame = view::frame(&sim);
    frame.device_positions = Some(on_device);
    let drawn = off.render(&frame, &camera, &options).expect("image");
    assert!(sim.state_behind(), "drawing read nothing back");
    let stale = off
        .render(&view::frame(&sim), &camera, &options)
        .expect("image");
    sim.sync_state().expect("read back");
    let latest = off
        .render(&view::frame(&sim), &camera, &options)
        .expect("image");
    let differing =
        |a: &[u8], b: &[u8]| a.iter().zip(b).filter(|(x, y)| x.abs_diff(**y) > 1).count();
    assert_eq!(
        differing(drawn.as_raw(), latest.as_raw()),
        0,
        "drawn from the buffer = drawn from the state read back"
    );
    let moved = differing(stale.as_raw(), latest.as_raw());
    assert!(
        moved > 1000,
        "the cloth fell in the picture ({moved} bytes)"
    );
}

/// The GPU's frames are only queued when the bench's clock stops after each: the row has
/// the run's mean (the last frame waited for) but no median or best frame, and the same
/// sag as the CPU row within the backends' agreement. Each row names its backend and the
/// CPU threads that stepped it: the pool's for the CPU, the one submitting thread for the
/// GPU, whatever pool the bench runs in.
#[test]
fn gpu_bench_row_has_the_run_mean_but_no_frame_spread() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .expect("a pool of 3");
    let (gpu, cpu) = pool.install(|| {
        let gpu = clothsim::bench::bench_gpu(16, IntegratorKind::SemiImplicitEuler, BENCH_SECONDS)
            .expect("GPU bench on the software adapter");
        let cpu = clothsim::bench::bench_one(16, IntegratorKind::SemiImplicitEuler).expect("cpu");
        (gpu, cpu)
    });
    assert_eq!((gpu.backend.as_str(), gpu.threads), ("gpu", 1));
    assert_eq!((cpu.backend.as_str(), cpu.threads), ("cpu", 3));
    assert!(gpu.finite && gpu.us_per_substep > 0.0);
    assert_eq!((gpu.median_frame_us, gpu.best_frame_us), (None, None));
    assert!(cpu.median_frame_us.is_some() && cpu.best_frame_us.is_some());
    assert!(
        (gpu.sag_m - cpu.sag_m).abs() < 1e-5,
        "{} vs {}",
        gpu.sag_m,
        cpu.sag_m
    );
}

/// Without `--integrators`, `bench --backend gpu` has a row for every integrator the GPU
/// runs (each a quarter second: two seconds took 0.6 s on the software adapter).
#[test]
fn gpu_bench_cli_defaults_to_the_integrators_it_runs() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_clothsim"))
        .args(["bench", "--backend", "gpu", "--sizes", "8"])
        .args(["--seconds", "0.25", "--json"])
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{}: {stderr}", out.status);
    let rows: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("one JSON object per line"))
        .collect();
    let integrators: Vec<&str> = rows
        .iter()
        .filter_map(|r| r["integrator"].as_str())
        .collect();
    assert_eq!(
        integrators,
        ["semi-implicit-euler", "implicit-euler", "xpbd", "vbd"],
        "{rows:?}"
    );
    for row in &rows {
        assert_eq!(row["backend"], "gpu");
        assert_eq!(row["finite"], true);
    }
}

/// On a device that binds at most the bytes the 40 × 40 bench cloth's spring ends take (8
/// bytes each, in one buffer), that cloth is built and the 41 × 41 one is refused with its
/// size, where its buffer would have failed validation: the limit is the device's, to the
/// byte. (The sizes against llvmpipe's own 128 MiB are `gpu::support`'s test: a 1 000 ×
/// 1 000 cloth's 91.4 MiB fits, a 1 200 × 1 200 one's 131.7 MiB does not.)
#[test]
fn a_cloth_is_refused_with_its_size_exactly_where_the_device_cannot_bind_its_springs() {
    use clothsim::gpu::GpuStepper;
    let [fits, over] = [40, 41].map(|n| {
        clothsim::bench::bench_scene(n, IntegratorKind::SemiImplicitEuler).expect("scene")
    });
    let ends = |scene: &Scene| scene.model.springs.len() as u64 * 2 * 8;
    let (most, bytes) = (ends(&fits), ends(&over));
    let gpu = HeadlessDevice::open(AdapterPreference::Software).expect("an adapter");
    let mut limits = clothsim::device::compute_limits(&gpu.adapter);
    limits.max_storage_buffer_binding_size = most;
    limits.max_buffer_size = most;
    let (device, queue) = pollster::block_on(gpu.adapter.request_device(&wgpu::DeviceDescriptor {
        required_limits: limits,
        ..Default::default()
    }))
    .expect("a device that binds less");
    let build =
        |s: &Scene| GpuStepper::new(&device, &queue, &s.model, &s.params, &s.effects, false);
    if let Err(e) = build(&fits) {
        panic!("40 × 40 refused though its {most} bytes fit: {e:#}");
    }
    let text = match build(&over) {
        Ok(_) => panic!("41 × 41 built though its {bytes} bytes exceed {most}"),
        Err(e) => format!("{e:#}"),
    };
    let size = format!(
        "needs {:.1} MiB ({bytes} bytes)",
        bytes as f64 / (1u64 << 20) as f64
    );
    assert!(
        text.contains(&size) && text.contains("spring ends"),
        "{size}: {text}"
    );
}

/// The CPU's wedge (`tests/contact.rs`) on the GPU: a small cloth driven along the ground
/// into the wedge under a sphere resting on it keeps both collision offsets after every
/// frame, and with self-collision (whose cuts come after the colliders) stays outside
/// both. Its colliders acting one after the other, the ground lifted a squeezed particle
/// into the sphere.
#[test]
fn a_cloth_driven_into_the_wedge_on_the_gpu_keeps_clear_of_the_sphere_and_the_ground() {
    let centre = glam::Vec3::new(0.0, WEDGE_RADIUS, 0.0);
    for own in [
        "",
        "[[effects]]\ntype = \"self-collision\"\nthickness = 0.004\n",
    ] {
        let (mut gpu, _) =
            gpu_simulation(wedge(own), true).expect("GPU backend on the software adapter");
        let mut closest = f32::INFINITY;
        for frame in 1..=30 {
            gpu.step_frame().expect("gpu frame");
            gpu.sync_state().expect("read back");
            // Both offsets (1 cm) to their rounding; with self-collision, whose cuts come
            // after the colliders here, outside both surfaces.
            let kept = if own.is_empty() { 0.0099 } else { 0.0 };
            for (i, p) in gpu.state().pos.iter().enumerate() {
                closest = closest.min(p.x.hypot(p.z));
                let (r, y) = (p.distance(centre), p.y);
                assert!(
                    r >= WEDGE_RADIUS + kept && y >= kept,
                    "frame {frame}: particle {i} at {p} is {} m from the sphere's surface, \
                     {y} m above the ground ({own:?})",
                    r - WEDGE_RADIUS
                );
            }
        }
        assert!(
            closest < 0.111,
            "the cloth kept {closest} m from the axis ({own:?})"
        );
    }
}
