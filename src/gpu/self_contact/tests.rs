//! Self-contact on the GPU (run here on the software adapter): the cloth's pairs found
//! through a hashed grid built on the device, pushed a thickness apart, and their motion
//! cut short where they could meet, so that a cloth free of intersections never gets one.
//! Checked as the CPU's guarantee is: the exact intersection test finds no two triangles
//! of the cloth through each other after any frame, while the cloth folds onto itself.

use glam::Vec3;

use crate::device::{AdapterPreference, HeadlessDevice};
use crate::gpu::stepper::GpuStepper;
use crate::scene::{Scene, SceneFile, Simulation};

/// `scene` on its own headless device, its self-contact run on the GPU.
fn trial(scene: Scene) -> Simulation {
    let gpu = HeadlessDevice::open(AdapterPreference::Any).expect("an adapter");
    let what = (&scene.model, &scene.params, &scene.effects[..]);
    let stepper = GpuStepper::trying(&gpu.device, &gpu.queue, what, true, true).expect("runs");
    Simulation::with_backend(scene, Box::new(stepper))
}

/// A built-in scene's file (`text`) with `edits` (text replaced) made to it, at `quads`
/// quads.
fn edited(text: &str, edits: &[(&str, &str)], quads: u32) -> Scene {
    let text = edits.iter().fold(text.to_string(), |t, (a, b)| {
        assert!(t.contains(a), "the scene has no `{a}`");
        t.replace(a, b)
    });
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes");
    let mut file = SceneFile::parse(&text, &dir.join("edited.toml")).expect("parses");
    file.resize_grid(quads).expect("a grid");
    Scene::from_file(file, None).expect("loads")
}

/// The nearest any particle comes to a triangle of another layer of the cloth (none of
/// whose corners is within two edges of it), metres.
fn closest_layers(triangles: &[[u32; 3]], pos: &[Vec3]) -> f32 {
    let mut next: Vec<Vec<u32>> = vec![Vec::new(); pos.len()];
    for t in triangles {
        for k in 0..3 {
            next[t[k] as usize].extend([t[(k + 1) % 3], t[(k + 2) % 3]]);
        }
    }
    let mut best = f32::INFINITY;
    for (i, &p) in pos.iter().enumerate() {
        let ring = &next[i];
        let near = |k: u32| {
            k as usize == i
                || ring
                    .iter()
                    .any(|&j| j == k || next[j as usize].contains(&k))
        };
        for t in triangles.iter().filter(|t| !t.iter().any(|&k| near(k))) {
            let [a, b, c] = t.map(|k| pos[k as usize]);
            best = best.min(p.distance(closest_on_triangle(p, a, b, c)));
        }
    }
    best
}

/// The point of triangle (a, b, c) nearest to `p`.
fn closest_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let n = (b - a).cross(c - a);
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|&(u, v)| (v - u).cross(p - u).dot(n) >= 0.0);
    if inside && n != Vec3::ZERO {
        return p - n * ((p - a).dot(n) / n.length_squared());
    }
    let on = |u: Vec3, v: Vec3| {
        let d = v - u;
        u + d * ((p - u).dot(d) / d.length_squared().max(f32::MIN_POSITIVE)).clamp(0.0, 1.0)
    };
    [on(a, b), on(b, c), on(c, a)]
        .into_iter()
        .min_by(|x, y| p.distance(*x).total_cmp(&p.distance(*y)))
        .unwrap_or(a)
}

/// Runs `scene` on the GPU for `frames` frames: after every one, no two of the cloth's
/// triangles pass through each other. Returns the simulation and the nearest its layers
/// came to each other after any frame.
fn never_passes_through(scene: Scene, frames: usize) -> (Simulation, f32) {
    let mut gpu = trial(scene);
    let mut closest = f32::INFINITY;
    for frame in 0..frames {
        gpu.step_frame().expect("gpu frame");
        let found = gpu.intersections();
        assert_eq!(found.self_pairs, 0, "frame {frame}: {found:?}");
        let now = closest_layers(&gpu.model().triangles, &gpu.state().pos);
        closest = closest.min(now);
    }
    (gpu, closest)
}

/// `crumple` at 12 quads: dropped from 2 m onto its sphere and the ground under implicit
/// Euler at 4 substeps, with the pass after every substep, it comes down to the ground (a
/// pass that held the cloth where each substep started fails here) and never passes
/// through itself. At this size it does not fold onto itself (its layers come no nearer
/// than 10 cm in 60 frames, and with the pass left out nothing crosses either): the
/// guarantee itself is tested by the twisting strip.
#[test]
fn a_crumpling_cloth_comes_down_and_never_passes_through_itself_on_the_gpu() {
    let scene = Scene::open_resized("crumple", None, &Default::default(), Some(12)).unwrap();
    let (gpu, closest) = never_passes_through(scene, 60);
    let lowest = (gpu.state().pos.iter())
        .map(|p| p.y)
        .fold(f32::INFINITY, f32::min);
    eprintln!("crumple: lowest {lowest}, closest layers {closest}");
    assert!(
        lowest < 0.02,
        "the cloth has come down over the sphere to the ground: {lowest}"
    );
}

/// `twist` at 12 quads, turned twice as fast (a full turn in 2 s) under XPBD at 16
/// substeps: the strip winds round itself, its layers kept the thickness (5 mm) apart by
/// the pushes, and never through. Measured: the layers meet from frame 55 and come no
/// nearer than 5.0 mm.
#[test]
fn a_twisting_strip_never_passes_through_itself_on_the_gpu() {
    let scene = edited(
        include_str!("../../../assets/scenes/twist.toml"),
        &[
            ("time = 4.0", "time = 2.0"),
            (
                "integrator = \"semi-implicit-euler\"",
                "integrator = \"xpbd\"",
            ),
            ("substeps = 64", "substeps = 16"),
        ],
        12,
    );
    let thickness = 0.005;
    let (_, closest) = never_passes_through(scene, 80);
    eprintln!("twist: closest layers {closest}");
    assert!(
        closest < 2.0 * thickness,
        "the strip winds onto itself: {closest}"
    );
    assert!(
        closest > 0.8 * thickness,
        "its layers are kept apart: {closest}"
    );
}
