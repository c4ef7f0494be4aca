//! Mesh obstacles on the GPU (run here on the software adapter) against the CPU's: the
//! same catch of each particle's move through the obstacle's box tree (a rigid one's in its
//! frame at the substep's start and end; a deforming one's surface where the substep ends,
//! a particle near it first carried by its move), and the same sweep of the cloth's edges
//! against its sharp edges, in the same colour order. They agree to micrometres where the
//! cloth meets the table and its rim, unless a row of particles lies exactly over the rim
//! (then which side an edge is on turns on rounding, and they part by tenths of a
//! millimetre); and the catch agrees to rounding even where the obstacle flings the cloth.

use clothsim::scene::{Scene, Simulation};
use clothsim::sim::IntegratorKind;

mod common;
use common::tips::{
    ball, coarse_drop, coarse_drop_at, drop_through_nothing, gentle_obstacles, sprouting_roof,
    tipped_obstacles,
};
use common::{farthest, gpu_simulation};

/// The built-in scene `name` at `quads` quads.
fn scene(name: &str, quads: u32) -> Scene {
    let options = clothsim::mesh::ImportOptions::default();
    Scene::open_resized(name, None, &options, Some(quads)).expect("a grid scene")
}

/// The height of `sim`'s lowest particle, metres.
fn lowest(sim: &Simulation) -> f32 {
    (sim.state().pos.iter())
        .map(|p| p.y)
        .fold(f32::INFINITY, f32::min)
}

/// `frames` frames of `scene` on both backends: how far apart the cloths end, and the
/// CPU's cloth. The guard acts alike on both (where it acts at all).
fn compare(scene: Scene, frames: usize) -> (f32, Simulation) {
    compare_checking(scene, (0, frames), |_, _| {})
}

/// `scene` stepped `from` frames on the CPU (the cloth falling free, as both backends step
/// it alike), and a GPU simulation of it starting where the CPU left it.
fn on_the_gpu_from(mut scene: Scene, from: usize) -> (Simulation, Simulation) {
    let mut cpu = Simulation::new(scene.clone());
    for _ in 0..from {
        cpu.step_frame().expect("cpu frame");
    }
    scene.initial = cpu.state().clone();
    let (gpu, _) = gpu_simulation(scene, true).expect("GPU backend on the software adapter");
    (cpu, gpu)
}

/// [`compare`] from frame `from` on ([`on_the_gpu_from`]); `check` is run on the GPU's
/// simulation after each of its frames (by number).
fn compare_checking(
    scene: Scene,
    (from, frames): (usize, usize),
    check: impl Fn(usize, &Simulation),
) -> (f32, Simulation) {
    let (mut cpu, mut gpu) = on_the_gpu_from(scene, from);
    for frame in from..frames {
        cpu.step_frame().expect("cpu frame");
        gpu.step_frame().expect("gpu frame");
        let events = [cpu.take_guard_events().len(), gpu.take_guard_events().len()];
        assert_eq!(
            events[0], events[1],
            "frame {frame}: guard events (CPU, GPU)"
        );
        check(frame, &gpu);
    }
    (farthest(&cpu.state().pos, &gpu.state().pos), cpu)
}

/// Fails when any cloth triangle passes through a solid of `sim` (the exact check).
fn passes_through_nothing(frame: usize, sim: &Simulation) {
    let found = sim.intersections();
    assert!(
        found.obstacles.iter().all(|&n| n == 0),
        "frame {frame}: {:?}",
        found.obstacles
    );
}

/// `carousel`'s drum, turning at 1 rad/s: the cloth lands on it and is carried round by
/// friction with the drum's surface, and kept off the drum's rim (on the GPU from frame 8,
/// two before it lands). Measured: 0.18 mm apart after 15 frames, when the cloth has lain
/// on the turning drum for five; without the surface's velocity in the catch's response,
/// 6.4 mm; without the edge pass, 14 cm; with every sweep of it run, 5 mm. (The tip pass
/// keeps the rim's vertices off the cloth's triangles, and where two triangles push one
/// particle in a substep the GPU's colour order and the CPU's patch order part the two:
/// without the tip pass they agreed to 4.2 µm.)
#[test]
fn a_turning_drum_carries_the_cloth_as_on_the_cpu() {
    let (apart, cpu) = compare_checking(scene("carousel", 8), (8, 15), |_, _| {});
    let lowest = lowest(&cpu);
    // The drum's top is 0.3 m up: the cloth rests on it, not on the ground.
    assert!(
        lowest > 0.1 && lowest < 0.32,
        "the cloth is on the drum: {lowest}"
    );
    eprintln!("carousel: {apart:e} m apart");
    assert!(apart < 5e-4, "GPU and CPU differ by {apart} m");
}

/// `tablecloth` (9 quads, so that no row of particles lies exactly over the table's rim,
/// where which side of it an edge is on turns on rounding: at 8 quads the backends part by
/// 0.4 mm within two frames of meeting it) under `integrator` at `substeps` a frame
/// (implicit Euler's solve to 10⁻⁵ of its right-hand side in at most `iterations`), 16
/// frames, on both backends from frame 11 (9 cm above the top): the cloth has met the
/// table's top and its rim (a sharp edge the cloth's edges are kept off), and the two are
/// `within` metres.
fn meets_the_table(integrator: IntegratorKind, substeps: u32, iterations: u32, within: f32) {
    let mut s = scene("tablecloth", 9);
    (s.params.step.integrator, s.params.step.substeps) = (integrator, substeps);
    (s.params.solver.tolerance, s.params.solver.max_iterations) = (1e-5, iterations);
    let (apart, cpu) = compare_checking(s, (11, 16), |_, _| {});
    let lowest = lowest(&cpu);
    assert!(lowest < 0.74, "the cloth falls past the rim: {lowest}");
    eprintln!("tablecloth under {integrator:?}: {apart:e} m apart");
    assert!(apart < within, "GPU and CPU differ by {apart} m");
}

/// Semi-implicit Euler at the scene's 48 substeps. Measured: 2.4 µm apart, the last four
/// frames on the table; without the GPU's edge pass, 9.7 cm, and with every sweep of it
/// run (not only those after a sweep that found a crossing), 45 µm.
#[test]
fn a_tablecloth_meets_the_table_and_its_rim_as_on_the_cpu() {
    meets_the_table(IntegratorKind::SemiImplicitEuler, 48, 40, 1e-5);
}

/// XPBD at 12 substeps, which writes a substep's end over its start (so the start is
/// copied first). Measured: 7.8 µm apart (every sweep of the edge pass run: 152 µm);
/// without the copy of the start, the moves are caught from wherever the copy was and the
/// guard steps in.
#[test]
fn a_tablecloth_under_xpbd_meets_the_table_as_on_the_cpu() {
    meets_the_table(IntegratorKind::Xpbd, 12, 40, 3e-5);
}

/// Implicit Euler at 4 substeps, its solve tight (10⁻⁵ of the right-hand side, at most 40
/// iterations): the contacts follow its solve. Measured: 0.44 µm apart (every sweep of the
/// edge pass run: 0.6 mm).
#[test]
fn a_tablecloth_under_implicit_euler_meets_the_table_as_on_the_cpu() {
    meets_the_table(IntegratorKind::ImplicitEuler, 4, 40, 5e-6);
}

/// Implicit Euler cut off after two iterations, where the first guess decides much of the
/// step: where the table moves a particle the next guess forgets its history, as the CPU's
/// does. Measured: 0.27 µm apart; with the history kept on the GPU, 5.3 mm.
#[test]
fn implicit_euler_forgets_its_guess_where_the_table_moves_the_cloth_as_on_the_cpu() {
    meets_the_table(IntegratorKind::ImplicitEuler, 4, 2, 5e-6);
}

/// VBD at 12 substeps, which writes a substep's end over its start as XPBD does, and
/// counts its substeps (the count's dispatch binds the substep's group again after the
/// contacts' own); the contacts' change of velocity joins its memory of each particle's
/// last acceleration, which its next first guess reads, as the CPU's reads the velocity
/// after the contacts. Measured: 0.19 µm apart; without the change in the memory, 90 µm.
#[test]
fn a_tablecloth_under_vbd_meets_the_table_as_on_the_cpu() {
    meets_the_table(IntegratorKind::Vbd, 12, 40, 5e-6);
}

/// Draped on the GPU, the cloth never crosses the table: the exact intersection check
/// finds no cloth triangle through it after any frame. The CPU steps it to frame 12, 2 cm
/// above the top; the GPU from there to frame 21, as it lands on the top and falls over the
/// rim.
#[test]
fn a_tablecloth_on_the_gpu_never_passes_through_the_table() {
    drapes_over_the_rim(8, 12..21, 0.5);
}

/// `tablecloth` at `quads` stepped on the CPU to the first of `frames` and on the GPU
/// through them, no cloth triangle through the table after any, and the cloth's lowest
/// particle at the end below `below` metres (over the rim, the top 0.75 m up).
fn drapes_over_the_rim(quads: u32, frames: std::ops::Range<usize>, below: f32) {
    let (_, mut gpu) = on_the_gpu_from(scene("tablecloth", quads), frames.start);
    for frame in frames {
        gpu.step_frame().expect("gpu frame");
        passes_through_nothing(frame, &gpu);
    }
    let lowest = lowest(&gpu);
    assert!(lowest < below, "the cloth hangs over the rim: {lowest}");
}

/// `tablecloth` at 6 quads (27 cm), whose table's corners poke up between the cloth's
/// particles as it falls over the rim, without self-collision: on the GPU, as on the CPU,
/// the tip pass keeps them off its triangles, and no triangle meets the table after any
/// frame. The CPU steps it to frame 24, 25 cm above the top; the GPU from there to frame
/// 48. (Kept out by the particles and edges alone, 10 triangles met the table by frame
/// 42 on both.)
#[test]
fn a_coarse_tablecloth_on_the_gpu_never_meets_the_tables_corners() {
    drapes_over_the_rim(6, 24..48, 0.6);
}

/// `tablecloth` at 8 quads, the cloth 0.5 m across (it lands inside the table's top, away
/// from its rim), with the table thrown up through the falling cloth at 60 m/s (2 cm a
/// substep, twice the thickness) and stopped 1 m above its place, and no ground: the
/// table's `moves` (its keyframes, or an OBJ sequence) replacing `obj = "table.obj"`, its
/// files in `dir`.
fn thrown_table(moves: &str, dir: &std::path::Path) -> Scene {
    let text = include_str!("../assets/scenes/tablecloth.toml")
        .replace("quads = 40, size = 1.6", "quads = 8, size = 0.5")
        .replace("obj = \"table.obj\"\n", moves)
        .replace("[[effects]]\ntype = \"plane\"\nfriction = 0.4\n", "");
    let file = clothsim::scene::SceneFile::parse(&text, &dir.join("thrown.toml")).unwrap();
    Scene::from_file(file, None).expect("the table loads")
}

/// The table's OBJ.
fn table_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/meshes")
}

/// A table thrown up through the cloth sweeps it along, as on the CPU: each move is caught
/// in the table's frame where it was at the substep's start and where it is at its end, so
/// a particle the top passes in a substep is caught on the side it was on. Measured: 42 nm
/// apart after 5 frames, the whole cloth flung up past 2.7 m; with the table's pose at the
/// substep's end taken for its start too, 1.0 m apart (the top passes particles by).
#[test]
fn a_table_thrown_up_through_the_cloth_sweeps_it_along_as_on_the_cpu() {
    let moves = "obj = \"table.obj\"\nkeyframes = [ { time = 0.0, translate = [0.0, -3.0, 0.0] }, \
                 { time = 0.0666667, translate = [0.0, 1.0, 0.0] } ]\n";
    let (apart, cpu) = compare(thrown_table(moves, &table_dir()), 5);
    let lowest = lowest(&cpu);
    eprintln!("thrown table: {apart:e} m apart, lowest {lowest}");
    assert!(
        lowest > 2.5,
        "the table flings the whole cloth up: {lowest}"
    );
    assert!(apart < 1e-6, "GPU and CPU differ by {apart} m");
}

/// The table as an OBJ sequence of two frames, 3 m below its place and 1 m above it, a
/// fifteenth of a second apart (the thrown table's motion, its vertices moving in straight
/// lines), in a new folder.
fn thrown_frames() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let table = std::fs::read_to_string(table_dir().join("table.obj")).expect("the table");
    for (k, dy) in [-3.0f32, 1.0].into_iter().enumerate() {
        let moved: Vec<String> = (table.lines())
            .map(|line| match line.strip_prefix("v ") {
                Some(xyz) => {
                    let v: Vec<f32> = xyz.split_whitespace().map(|c| c.parse().unwrap()).collect();
                    format!("v {} {} {}", v[0], v[1] + dy, v[2])
                }
                None => line.to_string(),
            })
            .collect();
        let path = dir.path().join(format!("table_{k}.obj"));
        std::fs::write(path, moved.join("\n")).expect("a frame written");
    }
    dir
}

/// A deforming obstacle (an OBJ sequence) thrown up through the cloth sweeps it along as
/// on the CPU: its surface where each substep ends is written for the GPU, and a particle
/// near it at the substep's start is first carried by the surface's own move over the
/// substep (here 2 cm, twice the thickness). Measured: 0.48 µm apart after 6 frames, the
/// cloth flung up past 3.7 m; without the carry on the GPU, 2.0 m apart (the table passes
/// the cloth by); without the surface's velocity in the response, 2.0 m.
#[test]
fn a_table_thrown_up_as_an_obj_sequence_sweeps_the_cloth_along_as_on_the_cpu() {
    let dir = thrown_frames();
    let pattern = dir.path().join("table_%d.obj");
    let moves = format!("frames = '{}'\nfps = 15.0\n", pattern.display());
    let (apart, cpu) = compare(thrown_table(&moves, dir.path()), 6);
    let lowest = lowest(&cpu);
    eprintln!("thrown sequence: {apart:e} m apart, lowest {lowest}");
    assert!(
        lowest > 3.5,
        "the table flings the whole cloth up: {lowest}"
    );
    assert!(apart < 2e-6, "GPU and CPU differ by {apart} m");
}

/// `arm` at 7 quads: the napkin falls on the forearm as it bends up and down at the elbow
/// (an OBJ sequence of 16 frames) and hangs from it, kept off its creases by the edge pass
/// with the surface's velocity there, and off its tips by the tip pass beside the scene's
/// self-collision, as on the CPU; and on the GPU (from frame 3, the CPU stepping the fall
/// before) it never passes through the arm. Measured: 2.8 µm apart after 10 frames, the
/// napkin on the arm for six; with no surface velocity where the edge pass moves the
/// cloth, 8.7 mm (without self-collision); with every sweep of the edge pass run, 2.1 mm
/// (the same); with the obstacles acting again after every substep's pushes, not only
/// after pushes that moved something (as the CPU's solids do), 2.8 mm.
#[test]
fn a_napkin_on_a_bending_arm_moves_as_on_the_cpu() {
    let (apart, cpu) = compare_checking(scene("arm", 7), (3, 10), passes_through_nothing);
    let lowest = lowest(&cpu);
    eprintln!("arm: {apart:e} m apart, lowest {lowest}");
    // The arm's top is 0.85 m up: the napkin hangs from it, above the ground.
    assert!(
        lowest > 0.5 && lowest < 0.75,
        "the napkin hangs over the arm: {lowest}"
    );
    assert!(apart < 1e-5, "GPU and CPU differ by {apart} m");
}

/// A coarse cloth (6 × 6 quads of 17 cm, a 1 cm thickness, self-collision) dropped on a
/// pyramid's apex, a cube's corner, a rising apex (an OBJ sequence) and a 20 cm ball of
/// 3 072 triangles (1 508 of its 1 538 vertices smooth by their faces; the 30 in the
/// middles of the cube's faces, whose faces turn a little more, are tips), which rises
/// 1.7 cm under a cell: on the GPU, as on the CPU (`tests/obstacles.rs`), the tip pass
/// keeps the tips a thickness off the cloth's triangles (the ball's edges and vertices are
/// within this cloth's reach, and so kept off as creases and tips, as on the CPU), so none
/// meets the obstacle after any frame of the first second, and the cloth rests on the tip;
/// under semi-implicit Euler, and on the pyramid under implicit Euler, XPBD and VBD too
/// (whose substep's start the contacts read from a copy). Without the GPU's pass the
/// pyramid's apex came through at frame 15 (4 pairs). The GPU's
/// pass takes the triangles in colours, the CPU's patch by patch: where two triangles push
/// one particle in a substep the two part (at 6 quads by millimetres within a few frames
/// of meeting the apex; at 2 quads, 17–24 frames after), so a one-quad cloth on each is
/// compared with the CPU's, self-collision on: within 20 µm after 45 frames (measured
/// 0.6–2 µm; the pyramid's 0.57 m without the GPU's pass, the cloth fallen over the apex).
#[test]
fn tips_never_pierce_a_coarse_cloth_on_the_gpu() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let mut cases: Vec<_> = tipped_obstacles(dir.path()).into_iter().collect();
    cases.push(ball(dir.path(), 3072));
    let integrators = ["semi-implicit-euler", "implicit-euler", "xpbd", "vbd"];
    for obstacle in cases {
        let name = obstacle.name;
        let others = if name == "pyramid" { 4 } else { 1 };
        for integrator in &integrators[..others] {
            let scene = coarse_drop(dir.path(), &obstacle.effect, integrator, 6);
            let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend");
            let highest = drop_through_nothing(&mut gpu, 60, &format!("{name} {integrator}"));
            let tip = obstacle.tip_at(1.0);
            assert!(
                highest > tip,
                "{name} {integrator}: the cloth slid off, its highest point at {highest} m (the tip at {tip})"
            );
        }
        let scene = coarse_drop(dir.path(), &obstacle.effect, "semi-implicit-euler", 1);
        let (apart, _) = compare_checking(scene, (0, 45), |_, _| {});
        eprintln!("{name}, one quad: {apart:e} m apart");
        // Every vertex of the ball is a tip to a one-quad cloth: its two triangles push the
        // particles they share in the same substeps, in the GPU's order and the CPU's.
        let within = if name == "ball" { 1e-4 } else { 2e-5 };
        assert!(apart < within, "{name}: GPU and CPU differ by {apart} m");
    }
}

/// A rail of narrow faces, a roof with a low apex and the roof rising from flat
/// (`gentle_obstacles`), whose faces all meet at less than a crease, and a roof whose
/// ridges crease and apex comes to a tip only after frame 0 of its sequence
/// (`sprouting_roof`), under a coarse cloth: on the GPU, as on the CPU, each is fitted to
/// the cloth (its gentle edges and vertices within the cloth's reach, in any frame, kept
/// off as creases and tips are; a sequence's creases and tips in any frame kept off in
/// all), so no triangle of the cloth meets any after any frame of the first second under
/// semi-implicit Euler, and the cloth rests on top. (Not fitted, the rail came through at
/// frame 12, the roof's apex at frame 17; with a sequence's creases told by frame 0
/// alone, the sprouting roof at frame 25.)
#[test]
fn gentle_curves_and_later_creases_never_come_through_a_coarse_cloth_on_the_gpu() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let sprouting = (sprouting_roof(dir.path()), 4, [0.083, 0.167]);
    for (obstacle, quads, centre) in gentle_obstacles(dir.path()).into_iter().chain([sprouting]) {
        let (effect, sie) = (&obstacle.effect, "semi-implicit-euler");
        let scene = coarse_drop_at(dir.path(), effect, sie, quads, centre);
        let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend");
        let highest = drop_through_nothing(&mut gpu, 60, obstacle.name);
        assert!(
            highest > obstacle.tip_at(1.0),
            "{}: the cloth is not on top ({highest} m)",
            obstacle.name
        );
    }
}
