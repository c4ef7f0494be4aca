//! Self-contact on the GPU (run here on the software adapter): the cloth's pairs found
//! through a hashed grid built on the device, pushed a thickness apart, and their motion
//! cut short where they could meet, so that a cloth free of intersections never gets one.
//! Checked as the CPU's guarantee is: the exact intersection test finds no two triangles
//! of the cloth through each other after any frame, while the cloth folds onto itself.

use glam::Vec3;

use crate::device::{AdapterPreference, HeadlessDevice, read_buffer};
use crate::gpu::implicit::MOVED_FLAG;
use crate::gpu::kernel::{WORKGROUP, shader_const};
use crate::gpu::stepper::GpuStepper;
use crate::scene::{Scene, SceneFile, Simulation};
use crate::sim::{FrameOutcome, StepBackend};

/// The host's copies of the shader's counter layout are the shader's: where the buckets
/// start and where the most entries and pairs a submission asked for, the pairs it forced
/// and its fastest particle are read from; each round of cuts has its two counters, clear
/// of those; the pair kernels' indirect dispatches are sized by the workgroup they run in;
/// a particle has as many push words, and the number of every push round of a substep
/// fits above a key's depth and hash; the word that says whether the pushes moved anything
/// is where the mesh obstacles read it, and `clear` does not zero it.
#[test]
fn the_host_and_the_shader_agree_on_the_counters() {
    let c = |name: &str| shader_const(super::SOURCE, name);
    assert_eq!(c("COUNTERS"), super::COUNTERS);
    assert_eq!(4 * u64::from(c("MOST_ENTRIES")), super::MOST_AT);
    assert_eq!(c("MOST_PAIRS"), c("MOST_ENTRIES") + 1);
    assert_eq!(c("FORCED"), c("MOST_PAIRS") + 1);
    assert_eq!(c("FASTEST"), c("FORCED") + 1);
    let read = c("FASTEST") + 1 - c("MOST_ENTRIES");
    assert_eq!(super::MOST_BYTES, 4 * u64::from(read));
    assert!(c("FASTEST") < c("COUNTERS"));
    // The mesh obstacles read whether the pushes moved anything; `clear` leaves it.
    assert_eq!(c("PUSHES_MOVED"), super::PUSHES_MOVED);
    assert!(c("MOST_ENTRIES") <= c("PUSHES_MOVED") && c("PUSHES_MOVED") < c("COUNTERS"));
    assert!(
        c("IMPACTS") + super::ROUNDS <= c("STUCK"),
        "the rounds' impacts fit"
    );
    assert!(
        c("STUCK") + super::ROUNDS <= c("MOST_ENTRIES"),
        "the rounds' stuck fit"
    );
    assert_eq!(c("WIDTH"), WORKGROUP);
    assert_eq!(u64::from(c("PUSH_WORDS")), super::PUSH_WORDS);
    let round_bits = 32 - c("KEY_DEPTH_BITS") - c("KEY_HASH_BITS");
    assert!(
        super::PUSH_SWEEPS * super::PUSH_ROUNDS < 1 << round_bits,
        "every push round's number fits the top of its keys"
    );
}

/// The spheres' face kernel leaves a face as the CPU's pass does: within the same share of
/// the offset inside the reach, it touches and is not pushed.
#[test]
fn the_face_kernel_leaves_a_touching_face_as_the_cpu_does() {
    let line = format!(
        "const FACE_TOUCHING: f32 = {:e};",
        crate::sim::FACE_TOUCHING
    );
    assert!(super::SOURCE.contains(&line), "the shader lacks `{line}`");
}

/// A GPU stepper for `scene` on its own headless device; with `pushes` false its
/// self-contact only cuts; `together` says whether one workgroup runs it (`None`: as the
/// cloth's size says).
fn stepper(scene: &Scene, pushes: bool, together: Option<bool>) -> GpuStepper {
    let gpu = HeadlessDevice::open(AdapterPreference::Software).expect("an adapter");
    let (model, params, effects) = (&scene.model, &scene.params, &scene.effects[..]);
    let mut stepper =
        GpuStepper::new(&gpu.device, &gpu.queue, model, params, effects, true).expect("runs");
    let own = stepper.contacts.own.as_mut().expect("self-contact");
    own.forced = together;
    if !pushes {
        own.sweeps = 0;
    }
    stepper
}

/// `scene` stepped on the GPU (see [`stepper`]).
fn trial(scene: Scene, pushes: bool, together: Option<bool>) -> Simulation {
    let gpu = stepper(&scene, pushes, together);
    Simulation::with_backend(scene, Box::new(gpu))
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
    // Each particle's particles within two edges (itself among them), sorted.
    let near: Vec<Vec<u32>> = (0..pos.len())
        .map(|i| {
            let mut within = vec![i as u32];
            for &j in &next[i] {
                within.push(j);
                within.extend(&next[j as usize]);
            }
            within.sort_unstable();
            within.dedup();
            within
        })
        .collect();
    let mut best = f32::INFINITY;
    for (p, near) in pos.iter().zip(&near) {
        let apart = |t: &&[u32; 3]| !t.iter().any(|k| near.binary_search(k).is_ok());
        for t in triangles.iter().filter(apart) {
            let [a, b, c] = t.map(|k| pos[k as usize]);
            best = best.min(p.distance(closest_on_triangle(*p, a, b, c)));
        }
    }
    best
}

/// The height of the lowest particle, m.
fn lowest_of(pos: &[Vec3]) -> f32 {
    pos.iter().fold(f32::INFINITY, |m, p| m.min(p.y))
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

/// Runs `scene` for `frames` frames, the first `on_cpu` of them on the CPU (whose
/// self-contact keeps the same guarantee, its own tests' business) and the rest on `gpu`:
/// after every one of those, no two of the cloth's triangles pass through each other, nor
/// any through a solid, and `each` sees the frame's number, how it went and the simulation.
/// (Checked after the CPU's frames too, the checks took a third of the flap test's time.)
fn cpu_then_gpu(
    scene: Scene,
    gpu: GpuStepper,
    (on_cpu, frames): (usize, usize),
    mut each: impl FnMut(usize, FrameOutcome, &mut Simulation),
) -> Simulation {
    let mut gpu = Some(gpu);
    let mut sim = Simulation::new(scene);
    for frame in 0..frames {
        if let Some(gpu) = gpu.take_if(|_| frame == on_cpu) {
            sim.set_backend(Box::new(gpu)).expect("on the gpu");
        }
        let outcome = sim.step_frame().expect("a frame");
        if frame < on_cpu {
            continue;
        }
        let found = sim.intersections();
        assert_eq!(found.total(), 0, "frame {frame}: {found:?}");
        each(frame, outcome, &mut sim);
    }
    assert_eq!(sim.backend_name(), "gpu", "the last frames ran on the gpu");
    sim
}

/// [`cpu_then_gpu`] with self-contact's pushes or without. Returns the simulation and the
/// nearest its layers came to each other after any frame.
fn never_passes_through(scene: Scene, frames: (usize, usize), pushes: bool) -> (Simulation, f32) {
    let gpu = stepper(&scene, pushes, None);
    let mut closest = f32::INFINITY;
    let sim = cpu_then_gpu(scene, gpu, frames, |_, _, sim| {
        let now = closest_layers(&sim.model().triangles, &sim.state().pos);
        closest = closest.min(now);
    });
    (sim, closest)
}

/// `crumple` at 12 quads: dropped from 2 m onto its sphere and the ground under implicit
/// Euler at 4 substeps (it meets the sphere at frame 36; on the GPU for frames 38 and 39,
/// from 14 cm above the ground), with the pass after every substep, it comes down to the
/// ground (a pass that held the cloth where each substep started fails here) and never
/// passes through itself. At this size it does not fold onto itself (its layers come no
/// nearer than 10 cm in 60 frames, and with the pass left out nothing crosses either):
/// the guarantee itself is tested by the twisting strip.
#[test]
fn a_crumpling_cloth_comes_down_and_never_passes_through_itself_on_the_gpu() {
    let scene = Scene::open_resized("crumple", None, &Default::default(), Some(12)).unwrap();
    let (gpu, closest) = never_passes_through(scene, (38, 40), true);
    let lowest = lowest_of(&gpu.state().pos);
    eprintln!("crumple: lowest {lowest}, closest layers {closest}");
    assert!(
        lowest < 0.02,
        "the cloth has come down over the sphere to the ground: {lowest}"
    );
}

/// `twist` at 12 quads, turned twice as fast (a full turn in 2 s) under XPBD at 16
/// substeps: the strip winds round itself from about frame 49 (the tests step it on the
/// GPU from frame 45 or 50).
fn twisting_strip() -> Scene {
    edited(
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
    )
}

/// The twisting strip's layers are kept the thickness (5 mm) apart by the pushes, and
/// never pass through (on the GPU to frame 62). Measured: they come no nearer than 5.2 mm.
#[test]
fn a_twisting_strip_never_passes_through_itself_on_the_gpu() {
    let thickness = 0.005;
    let (_, closest) = never_passes_through(twisting_strip(), (45, 62), true);
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

/// With no pushes, the cuts alone hold the twisting strip (on the GPU from frame 50 to 74):
/// its layers are pressed together substep after substep and stop at the floor the check
/// keeps (a few µm, from frame 70), never through. A floor that let a pair below it creep
/// closer by half its distance each substep let the strip through at frame 57.
#[test]
fn the_cuts_alone_keep_a_pressed_strip_from_passing_through_itself_on_the_gpu() {
    let (_, closest) = never_passes_through(twisting_strip(), (50, 74), false);
    eprintln!("twist without pushes: closest layers {closest}");
    assert!(closest < 1e-4, "the layers are pressed together: {closest}");
    assert!(closest > 1e-6, "they stop at the floor: {closest}");
}

/// `layers` at 3 quads with six cloths 4 cm apart under XPBD at 8 substeps falls onto its
/// sphere; the CPU steps it until all six have landed on each other (frame 17) and the GPU
/// steps the frame after, the stack pressed onto the sphere: it never passes through
/// itself, nor through the sphere (its triangles' interiors kept out as well as its
/// particles, and what the pushes press into the sphere put back out), and the pushes hold
/// its layers apart. Measured: they come no nearer than 5.4 mm (the CPU's own frame 18:
/// 4.9 mm; the thickness is 6 mm).
/// - The triangles are kept out of the sphere before the pushes as well as after, and what
///   that lifts is held as resting on the sphere, as the CPU holds what its solids moved:
///   left free, the lowest layer was pushed down into the sphere by the layer above,
///   lifted back into it after the pushes, and held pressed there by the cuts, substep
///   after substep: 0.66 mm apart.
/// - The deepest pairs claim their particles first in each round of pushes: with the
///   claims in an order that ignores depth (its bits in the key zero), 2.6 mm.
///
/// (Six cloths of 3 quads, not five of 6, and one frame on the GPU, not four, so that the
/// test takes under half a second on the software adapter; five cloths of 3 quads did not
/// catch the depth-blind order.)
#[test]
fn a_stack_of_cloths_on_a_sphere_never_passes_through_on_the_gpu() {
    let (_, closest) = never_passes_through(stack(3, 6, None), (18, 19), true);
    eprintln!("layers: closest layers {closest}");
    assert!(closest < 0.006, "the layers land on each other: {closest}");
    assert!(
        closest > 0.003,
        "the pushes hold them apart (half the thickness): {closest}"
    );
}

/// `layers` at `quads` quads with `cloths` cloths under XPBD at 8 substeps, dropped onto
/// `solid` (a scene file's effect) instead of its sphere.
fn stack(quads: u32, cloths: u32, solid: Option<&str>) -> Scene {
    let cloths = format!("layers = {cloths},");
    let mut edits = vec![
        ("integrator = \"implicit-euler\"", "integrator = \"xpbd\""),
        ("substeps = 4", "substeps = 8"),
        ("layers = 5,", &cloths),
    ];
    if let Some(solid) = solid {
        edits.push((
            "type = \"sphere\"\ncenter = [0.0, 0.3, 0.0]\nradius = 0.3",
            solid,
        ));
    }
    edited(
        include_str!("../../../assets/scenes/layers.toml"),
        &edits,
        quads,
    )
}

/// Five cloths of 3 quads dropped onto the table (a mesh obstacle) instead of the sphere:
/// they land on it at frame 11 and on each other after, and the GPU steps frame 14, the
/// stack pressed onto the table. After that frame the lowest layer rests on the table top,
/// where its pass keeps the cloth (10 mm above), and the layers above are held apart. What
/// the table's pass moved before the pushes is held as resting on it, as the CPU holds what
/// its solids moved: left free, it was pushed down into the table by the layer above and
/// put back into that layer by the table's pass after the pushes (the CPU's recheck runs
/// every solid again), and the layers came within 3.7 mm; with that second pass left out as
/// well, the lowest layer was pressed 2 mm into the table's 10 mm. With the pushes' claims
/// in an order that ignores depth, 4.1 mm. Measured: the lowest particle 10 mm above the
/// table top to 0.1 µm, the layers no nearer than 5.3 mm (the CPU's own frame 14: 5.6 mm).
/// And the frame is stepped once (with room for 16 pairs a triangle to start with, twice).
#[test]
fn a_stack_of_cloths_on_a_table_never_passes_through_it_on_the_gpu() {
    let table = format!(
        "type = \"obstacle\"\nobj = \"{}/assets/meshes/table.obj\"",
        env!("CARGO_MANIFEST_DIR")
    );
    let scene = stack(3, 5, Some(&table));
    let gpu = stepper(&scene, true, None);
    let (mut closest, mut lowest, mut steps) = (f32::INFINITY, f32::INFINITY, 0);
    cpu_then_gpu(scene, gpu, (14, 15), |_, _, sim| {
        let pos = &sim.state().pos;
        closest = closest.min(closest_layers(&sim.model().triangles, pos));
        lowest = lowest.min(lowest_of(pos));
        steps = sim.take_stats().steps;
    });
    eprintln!("layers on the table: closest layers {closest}, lowest {lowest}, {steps} substeps");
    // The GPU's frame fits the room for pairs a small cloth starts with (about 2 300 pairs
    // for 90 triangles; 16 a triangle would be 1 440), so it is stepped once, its 8
    // substeps (16 with that room: run out, grown, redone).
    assert_eq!(steps, 8, "the frame was stepped again with more room");
    // The table top is at 0.75 m, and its pass keeps the cloth 10 mm off it.
    assert!(
        (lowest - 0.76).abs() < 1e-4,
        "the lowest layer rests on the table top: {lowest}"
    );
    assert!(
        (0.0045..0.006).contains(&closest),
        "the layers land on each other and are held apart: {closest}"
    );
}

/// One workgroup a phase of a substep's self-contact (the small cloth's path) and the wide
/// path, a dispatch a step of each round, take the same steps in the same order, each
/// result a fixed-point sum, an atomic extreme or one owner's write: they give the same
/// bits, rounds that find nothing to do skipped by the one and dispatched by the other.
/// `layers` at 4 quads (five cloths 4 cm apart) under XPBD at 8 substeps, dropped onto its
/// sphere, on the GPU for frames 15 to 17 (the CPU's frames before that are the same for
/// both), with `pushes` or with the cuts alone: the pushes, the sphere's second pass and
/// the cuts all act from frame 15, and the layers come within the thickness (6 mm) of each
/// other by 17. Returns how near they came. (Measured too: `crumple` at 32 quads, the same
/// bits for 60 frames.)
fn same_bits(pushes: bool) -> f32 {
    let scene = || stack(4, 5, None);
    let mut cpu = Simulation::new(scene());
    for _ in 0..15 {
        cpu.step_frame().expect("cpu frame");
    }
    let from_there = |together: bool| {
        let mut scene = scene();
        scene.initial = cpu.state().clone();
        trial(scene, pushes, Some(together))
    };
    let (mut wide, mut together) = (from_there(false), from_there(true));
    let bits = |v: &[Vec3]| -> Vec<u32> {
        v.iter()
            .flat_map(|p| p.to_array().map(f32::to_bits))
            .collect()
    };
    for frame in 15..18 {
        wide.step_frame().expect("gpu frame");
        together.step_frame().expect("gpu frame");
        let (a, b) = (wide.state(), together.state());
        assert!(bits(&a.pos) == bits(&b.pos), "frame {frame}: positions");
        assert!(bits(&a.vel) == bits(&b.vel), "frame {frame}: velocities");
    }
    let closest = closest_layers(&wide.model().triangles, &wide.state().pos);
    assert!(closest < 0.006, "the layers have met: {closest}");
    closest
}

/// [`same_bits`] with the pushes: one workgroup's sweep ends at a round in which no pair
/// claims a particle, and its pushes at a sweep whose first round is so (with any such
/// round ending the pushes, frame 16 differs).
#[test]
fn one_workgroup_and_the_wide_path_give_the_same_bits() {
    let closest = same_bits(true);
    eprintln!("same bits: closest layers {closest}");
}

/// [`same_bits`] with the cuts alone, which press the layers together (measured: 7 µm
/// apart by frame 17, a thousandth of the thickness), so that the rounds of cuts run on: one
/// workgroup's end after a round that cut nothing (stopped after the second round instead,
/// frame 16 differs).
#[test]
fn one_workgroup_and_the_wide_path_give_the_same_bits_with_the_cuts_alone() {
    let closest = same_bits(false);
    eprintln!("same bits, the cuts alone: closest layers {closest}");
    assert!(
        closest < 2e-4,
        "the cuts alone press the layers together: {closest}"
    );
}

/// [`cpu_then_gpu`] in which every frame on the GPU also stands as stepped, with
/// `push_rounds` rounds of pushes a sweep; `each` sees the simulation after each of them.
fn clean_frames(
    scene: Scene,
    frames: (usize, usize),
    push_rounds: u32,
    mut each: impl FnMut(&Simulation),
) -> Simulation {
    let mut gpu = stepper(&scene, true, None);
    (gpu.contacts.own.as_mut().expect("self-contact")).push_rounds = push_rounds;
    cpu_then_gpu(scene, gpu, frames, |frame, outcome, sim| {
        assert_eq!(outcome, FrameOutcome::Stepped, "frame {frame}");
        each(sim);
    })
}

/// Two cloths 4 cm apart (`layers` at 4 quads with two layers and no sphere) fall flat onto
/// the ground at 4.1 m/s in frame 27, on the GPU from frame 26 to 28, under `integrator`
/// at `substeps`, with `push_rounds` rounds of pushes a sweep: the lower one lands and
/// rests on the ground, and the upper one lands on it a substep later, moving about a
/// thickness a substep. After every frame: no guard event and no intersection. What rests
/// on the ground moves only where nothing else in its pair can, so the upper cloth is
/// pushed up by the whole gap and the two stay the thickness (6 mm) apart (measured: to 1
/// nm; with that rule left out, 5.66–5.96 mm apart). And nothing moves faster than 1.1
/// times the landing speed (measured: nothing faster than the landing itself, 4.13 m/s).
fn lands_a_thickness_apart(integrator: &str, substeps: u32, push_rounds: u32) {
    let thickness = 0.006;
    let mut fastest = 0.0f32;
    let scene = two_cloths(integrator, substeps);
    let sim = clean_frames(scene, (26, 29), push_rounds, |sim| {
        let speed = (sim.state().vel.iter()).fold(0.0f32, |m, v| m.max(v.length()));
        fastest = fastest.max(speed);
    });
    let lowest = lowest_of(&sim.state().pos);
    let closest = closest_layers(&sim.model().triangles, &sim.state().pos);
    eprintln!("{integrator}: lowest {lowest}, closest layers {closest}, fastest {fastest} m/s");
    assert!(
        lowest < 0.011,
        "the lower cloth rests on the ground: {lowest}"
    );
    assert!(
        fastest < 1.1 * 4.2,
        "nothing moves much faster than the cloth lands (4.1 m/s): {fastest}"
    );
    assert!(
        (closest - thickness).abs() < 0.005 * thickness,
        "the cloths rest a thickness apart: {closest}"
    );
}

/// `fast-fold` at 16 quads (a cloth on the ground, its front edge pinned, its back edge
/// flung over onto it at 10 m/s by a handle; implicit Euler at 4 substeps), on the GPU for
/// frames 26 and 27, as the flap lands on the cloth: every frame stands as stepped, nothing
/// passes through, and the pushes hold the flap off the cloth. Measured: 5.96 mm apart
/// (the thickness is 6 mm); without the pushes, 33 µm; without the pushes and the cuts, 63
/// pairs of triangles through each other in frame 26.
#[test]
fn a_flap_flung_over_at_10_m_per_s_folds_without_a_guard_event_on_the_gpu() {
    let scene = Scene::open_resized("fast-fold", None, &Default::default(), Some(16)).unwrap();
    let mut closest = f32::INFINITY;
    clean_frames(scene, (26, 28), super::PUSH_ROUNDS, |sim| {
        closest = closest.min(closest_layers(&sim.model().triangles, &sim.state().pos));
    });
    eprintln!("fast-fold: closest layers {closest}");
    assert!(closest < 0.0065, "the flap lands on the cloth: {closest}");
    assert!(closest > 0.003, "the pushes hold it apart: {closest}");
}

/// `layers` at 4 quads with two cloths and no sphere, stepped by `integrator` at
/// `substeps` a frame: they fall flat onto the ground from 1 m, the lower one first.
fn two_cloths(integrator: &str, substeps: u32) -> Scene {
    edited(
        include_str!("../../../assets/scenes/layers.toml"),
        &[
            (
                "integrator = \"implicit-euler\"",
                &format!("integrator = \"{integrator}\""),
            ),
            ("substeps = 4", &format!("substeps = {substeps}")),
            ("layers = 5", "layers = 2"),
            (
                "[[effects]]\ntype = \"sphere\"\ncenter = [0.0, 0.3, 0.0]\nradius = 0.3\nfriction = 0.5\n\n",
                "",
            ),
        ],
        4,
    )
}

#[test]
fn a_cloth_landing_on_another_rests_on_it_a_thickness_apart_under_xpbd_on_the_gpu() {
    lands_a_thickness_apart("xpbd", 8, super::PUSH_ROUNDS);
}

#[test]
fn a_cloth_landing_on_another_rests_on_it_a_thickness_apart_under_vbd_on_the_gpu() {
    lands_a_thickness_apart("vbd", 8, super::PUSH_ROUNDS);
}

#[test]
fn a_cloth_landing_on_another_rests_on_it_a_thickness_apart_under_implicit_euler_on_the_gpu() {
    lands_a_thickness_apart("implicit-euler", 4, super::PUSH_ROUNDS);
}

#[test]
fn a_cloth_landing_on_another_rests_on_it_a_thickness_apart_under_semi_implicit_euler_on_the_gpu() {
    lands_a_thickness_apart("semi-implicit-euler", 12, super::PUSH_ROUNDS);
}

/// [`lands_a_thickness_apart`] under XPBD with no rounds: every pair pushed side by side,
/// as a crowded contact leaves its pairs after the rounds (here the rounds, deepest pair
/// first, leave none). Each particle takes the average of its pairs' changes of velocity,
/// not half their sum: each pair takes away the whole of its sides' approach, and with half
/// the sum the landing frame broke the guard's limits and was redone; and half the sum of
/// their moves, but no further than its longest push: a particle landing within the
/// thickness of a dozen of the other cloth's triangles and edges is pushed by each, and
/// without that bound it reached 5.8 m/s.
#[test]
fn a_cloth_landing_on_another_pushed_side_by_side_rests_on_it_a_thickness_apart_on_the_gpu() {
    lands_a_thickness_apart("xpbd", 8, 0);
}

/// The knob the test above turns takes effect: the two cloths of [`lands_a_thickness_apart`]
/// landing under XPBD (frames 26 and 27 on the GPU) end elsewhere with no rounds of pushes
/// than with the rounds (where it left the rounds in, both runs would give the same bits).
#[test]
fn no_rounds_of_pushes_lands_the_cloths_otherwise_than_the_rounds_do_on_the_gpu() {
    let [none, rounds] = [0, super::PUSH_ROUNDS]
        .map(|rounds| clean_frames(two_cloths("xpbd", 8), (26, 28), rounds, |_| {}));
    let moved = (none.state().pos.iter().zip(&rounds.state().pos))
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        moved > 0,
        "no rounds, and the same end: the knob did nothing"
    );
}

/// Self-contact's room for grid entries and pairs running out: the two cloths of
/// [`lands_a_thickness_apart`] (on the GPU for frames 26 and 27) with room for 64 entries
/// and 8 pairs to start with, where they need about 100–220 entries from the first frame
/// and 226 pairs once they are near each other. A submission that runs out leaves the cloth
/// where it started the substeps concerned; the guard's frame then grows the room and
/// redoes the frame, so the run is the one that had room enough from the start, to the bit,
/// after every frame, at the cost of the substeps redone. (With the frame taken as it ran
/// out instead, and on the GPU from frame 10, the cloth stopped dead in the air at frames
/// 10, 11 and 21 and had not reached the ground at frame 40.) One workgroup runs it: with
/// its search not recording what it asked for, frame 26 differs.
#[test]
fn a_frame_whose_room_for_pairs_ran_out_is_redone_with_more_on_the_gpu() {
    let [(roomy, plain), (tight, redone)] = [None, Some([8, 64])].map(|room| {
        let scene = two_cloths("xpbd", 8);
        let mut gpu = stepper(&scene, true, None);
        let own = gpu.contacts.own.as_mut().expect("self-contact");
        // One workgroup (the replay's test in `gpu::guarded` runs the wide path).
        (own.room, own.forced) = (room, Some(true));
        let mut states = Vec::new();
        let mut sim = cpu_then_gpu(scene, gpu, (26, 28), |frame, outcome, sim| {
            assert_eq!(outcome, FrameOutcome::Stepped, "frame {frame}");
            states.push((sim.state().pos.clone(), sim.state().vel.clone()));
        });
        // The GPU's substeps: its stats start when it takes over.
        (states, sim.take_stats().steps)
    });
    let lowest = lowest_of(&roomy[1].0);
    assert!(lowest < 0.011, "the cloths have landed: {lowest}");
    for (frame, (a, b)) in (26..).zip(roomy.iter().zip(&tight)) {
        assert!(
            a == b,
            "frame {frame}: the run with too little room differs"
        );
    }
    // With room enough, each of the two frames is stepped once (8 substeps).
    assert_eq!(plain, 16, "the roomy run redid a frame");
    assert!(
        redone > plain,
        "frames were redone: {redone} substeps against {plain}"
    );
}

/// VBD's first guess of a substep starts from the acceleration each particle took over the
/// last one, so that acceleration must include what self-contact did to it after VBD's
/// descent (the pushes and the cuts change velocities; `tell_solver` adds their change over
/// the substep, as the CPU's VBD measures its acceleration after its contacts). The two
/// cloths of [`lands_a_thickness_apart`] under VBD, on the GPU substep by substep through
/// the upper one landing on the lower (three frames of 8 substeps each from frame 26; the
/// landing decelerates particles at up to 2 026 m/s²): after every substep, each free
/// particle's remembered acceleration is its change of velocity over the substep divided
/// by the substep's length (checked to 1 mm/s², one f32 step of a 4 m/s velocity over the
/// 2 ms substep being 0.23 mm/s²; measured: to the bit; without self-contact's change of
/// velocity in the memory, 2 034 m/s² off).
#[test]
fn vbd_remembers_the_acceleration_self_contact_left_on_the_gpu() {
    let scene = two_cloths("vbd", 8);
    let mut gpu = stepper(&scene, true, None);
    let mut sim = Simulation::new(scene);
    for _ in 0..26 {
        sim.step_frame().expect("a frame");
    }
    let model = sim.model().clone();
    let mut state = sim.state().clone();
    let h = gpu.substep_length();
    let n = model.particle_count() as u32;
    let mut worst = 0.0f32;
    let mut most = 0.0f32;
    for _ in 0..24 {
        let before = state.vel.clone();
        gpu.substep(&model, &mut state).expect("a substep");
        // Where the memory starts is known once the first substep has built the stencil.
        let at = u64::from(gpu.vbd.starts[2]) * 4;
        let memory: Vec<u32> = read_buffer(
            &gpu.device,
            &gpu.queue,
            &gpu.vbd.stencil,
            at,
            4 * n as usize,
        );
        for i in (0..n as usize).filter(|&i| model.inv_mass[i] > 0.0) {
            let kept = glam::Vec3::from_array([0, 1, 2].map(|c| f32::from_bits(memory[4 * i + c])));
            let taken = (state.vel[i] - before[i]) / h;
            worst = worst.max((kept - taken).length());
            most = most.max(taken.length());
        }
    }
    eprintln!("remembered against taken: {worst} m/s² at most, of {most}");
    assert!(most > 1000.0, "the cloths landed: {most} m/s² at most");
    assert!(worst < 1e-3, "VBD remembers what it took: {worst} m/s² off");
}

/// Implicit Euler's first guess of a substep extrapolates the last substeps' changes of
/// velocity, which is no guess where a contact changed them after the solve: self-contact
/// then sets the solve's flag (`tell_solver`), and the next solve starts without history,
/// as the CPU's does after its contacts. The two cloths of [`lands_a_thickness_apart`]
/// with no ground, the upper one thrown down at 1 m/s onto the lower (4 cm below), on the
/// GPU substep by substep (4 a frame): before they come near, no substep sets the flag
/// (nothing else does here: no collider); every substep in which contact changed a
/// particle's velocity by more than 0.1 m/s from its fall sets it; and the substep after a
/// flagged one starts its guess afresh (its history counts one substep, not two).
#[test]
fn implicit_euler_forgets_its_guess_where_self_contact_changed_velocities_on_the_gpu() {
    let mut scene = two_cloths("implicit-euler", 4);
    scene
        .effects
        .retain(|e| !matches!(e, crate::sim::Effect::Plane(_)));
    let pos = &scene.initial.pos;
    let middle = pos.iter().map(|p| p.y).sum::<f32>() / pos.len() as f32;
    for (v, p) in scene.initial.vel.iter_mut().zip(&scene.initial.pos) {
        if p.y > middle {
            v.y = -1.0;
        }
    }
    let mut gpu = stepper(&scene, true, None);
    let model = scene.model.clone();
    let mut state = scene.initial.clone();
    let h = gpu.substep_length();
    let gravity = crate::sim::gravity_of(&scene.effects) * h;
    let (mut apart, mut struck, mut afresh) = (0, 0, 0);
    let mut flagged_before = false;
    for substep in 0..40 {
        let before = state.vel.clone();
        // Within the thickness (6 mm) and what 2.5 m/s, more than they close at, covers in
        // a substep.
        let near = closest_layers(&model.triangles, &state.pos) < 0.006 + 2.5 * h;
        gpu.substep(&model, &mut state).expect("a substep");
        let solve = &gpu.implicit.as_ref().expect("the solve").solve;
        // The flag, and the word before it: how many substeps the next guess looks back on.
        let at = 4 * u64::from(MOVED_FLAG - 1);
        let words: Vec<f32> = read_buffer(&gpu.device, &gpu.queue, solve, at, 2);
        let (history, flag) = (words[0], words[1]);
        if flagged_before {
            assert_eq!(history, 1.0, "substep {substep}: the guess starts afresh");
            afresh += 1;
        }
        flagged_before = flag > 0.5;
        let jolt = (state.vel.iter().zip(&before))
            .map(|(v, b)| (*v - *b - gravity).length())
            .fold(0.0f32, f32::max);
        if !near {
            assert!(
                !flagged_before,
                "substep {substep}: flagged, the cloths apart"
            );
            apart += 1;
        }
        if jolt > 0.1 {
            assert!(
                flagged_before,
                "substep {substep}: a jolt of {jolt} m/s unflagged"
            );
            struck += 1;
        }
    }
    eprintln!("{apart} substeps apart, {struck} struck, {afresh} started afresh");
    assert!(
        apart >= 4 && struck >= 1 && afresh >= 1,
        "{apart}, {struck}, {afresh}"
    );
}

/// Story: a blow-up inside a frame could hide from the GPU's guard. Where its substeps asked
/// for more pairs than the room held, they kept the cloth where they started them, so the
/// frame's end looked healthy; the room grew to twice the blown-up ask and the frame was
/// redone, twice over: to half a million pairs for two 12-quad cloths. `layers` at 16
/// quads under symplectic Euler asked for more than one binding holds at 0.27 s, and the run
/// stopped with "the step backend failed". Self-contact now measures each substep's fastest
/// particle before its contacts (the CPU's guard checks every substep), so the guard rolls
/// such a try back and rescues the frame, and the room stays as it was. Here two layers of
/// 12 quads are jolted at up to 1 m/s, which symplectic Euler at 4 substeps cannot take.
#[test]
fn a_blow_up_hidden_by_the_room_running_out_is_caught_on_the_gpu() {
    let layers = include_str!("../../../assets/scenes/layers.toml");
    let edits = [
        (
            "integrator = \"implicit-euler\"",
            "integrator = \"semi-implicit-euler\"",
        ),
        ("layers = 5", "layers = 2"),
    ];
    let mut scene = edited(layers, &edits, 12);
    scene.params.material.stiffness = scene.params.material.stiffness.map(|k| 40.0 * k);
    let mut gpu = stepper(&scene, true, None);
    let room = |gpu: &GpuStepper| {
        let own = gpu.contacts.own.as_ref().expect("self-contact");
        [own.params.more[0], own.params.counts[3]]
    };
    let before = room(&gpu);
    let mut state = scene.initial.clone();
    for (i, v) in state.vel.iter_mut().enumerate() {
        *v = Vec3::new((i as f32).sin(), 0.0, (1.7 * i as f32).cos());
    }
    let outcome = gpu.frame(&scene.model, &mut state).expect("rescued");
    assert_ne!(
        outcome,
        FrameOutcome::Stepped,
        "the jolt blows symplectic Euler up"
    );
    assert_eq!(room(&gpu), before, "the room a blown-up try asked for");
}

mod cuts;
