//! Cloth that never passes through itself: the exact intersection check, the edge–edge
//! pairs, the continuous check's guarantee on the stress scenes under every integrator,
//! and friction between layers against Coulomb's law.

use clothsim::cloth::{ClothModel, ClothState};
use clothsim::mesh::{ImportOptions, build_mesh};
use clothsim::scene::{Scene, SceneFile, Simulation};
use clothsim::sim::intersections::{self_intersections, triangles_meet};
use clothsim::sim::{GuardAction, IntegratorKind, SelfContacts};
use glam::{DVec3, Vec3};

mod common;
use common::{
    WEDGE_RADIUS, edited_builtin, incline, parsed, slope_acceleration, slope_speed, wedge,
};

fn d(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

#[test]
fn the_check_tells_crossing_touching_and_apart_triangles() {
    let flat = [d(0.0, 0.0, 0.0), d(1.0, 0.0, 0.0), d(0.0, 0.0, 1.0)];
    // A vertical triangle through the middle of the flat one.
    let through = [d(0.2, -0.5, 0.2), d(0.2, 0.5, 0.2), d(0.3, 0.5, 0.3)];
    assert!(triangles_meet(flat, through));
    // The same, lifted clear of it.
    let above = through.map(|p| p + d(0.0, 0.6, 0.0));
    assert!(!triangles_meet(flat, above));
    // Touching at one point (a corner on the face) meets; a hair above does not.
    let touching = [d(0.2, 0.0, 0.2), d(0.2, 0.5, 0.2), d(0.3, 0.5, 0.3)];
    assert!(triangles_meet(flat, touching));
    let hair = touching.map(|p| p + d(0.0, 1e-12, 0.0));
    assert!(!triangles_meet(flat, hair));
    // Coplanar: overlapping meets, side by side does not.
    let overlapping = flat.map(|p| p + d(0.3, 0.0, 0.3));
    assert!(triangles_meet(flat, overlapping));
    let beside = flat.map(|p| p + d(2.0, 0.0, 0.0));
    assert!(!triangles_meet(flat, beside));
}

/// Two triangles sharing vertex 0: (0, 1, 2) flat and (0, 3, 4), whose far edge (3, 4)
/// is at height `y` and crosses over the first.
fn hinge(y: f32) -> Vec<Vec3> {
    vec![
        Vec3::ZERO,
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.6, y, -0.2),
        Vec3::new(-0.2, y, 0.6),
    ]
}

#[test]
fn triangles_sharing_a_vertex_meet_only_where_an_opposite_edge_passes_through() {
    let tris = [[0, 1, 2], [0, 3, 4]];
    // Far edge above: they touch only at the shared vertex.
    assert_eq!(self_intersections(&tris, &hinge(0.3)), 0);
    // Far edge pushed down through the first triangle.
    assert_eq!(
        self_intersections(&tris, &hinge(-0.3)),
        0,
        "not through: it starts beside"
    );
    let mut through = hinge(-0.3);
    through[3] = Vec3::new(0.3, 0.3, 0.3);
    through[4] = Vec3::new(0.3, -0.3, 0.3);
    assert_eq!(self_intersections(&tris, &through), 1);
    // Sharing an edge, even folded through one another, is never counted.
    let folded = [
        Vec3::ZERO,
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.5, -0.1, 0.5),
    ];
    assert_eq!(self_intersections(&[[0, 1, 2], [0, 1, 3]], &folded), 0);
}

/// Story: in plain f64 the check counted intersections in a flat cloth falling straight
/// down (coplanar neighbours whose volumes rounding gave signs); exact predicates count
/// none.
#[test]
fn a_flat_cloth_at_any_height_has_no_intersection() {
    let mut sim = builtin("layers", Some(12));
    for _ in 0..12 {
        sim.step_frame().expect("falls");
        assert_eq!(sim.intersections().self_pairs, 0);
    }
}

/// A strip along x pinned at height 0 and one along z `gap` above it, each one quad 1 m long
/// and 2 cm wide, crossing at their middles: no vertex of either is over the other's face,
/// so only their edges can meet.
fn crossed_strips(gap: f32, pinned: &[u32]) -> (ClothModel, ClothState) {
    let strip = |along_x: bool, y: f32| -> Vec<Vec3> {
        let (l, w) = (0.5, 0.01);
        let c = [(-l, -w), (l, -w), (l, w), (-l, w)];
        c.iter()
            .map(|&(a, b)| {
                if along_x {
                    Vec3::new(a, y, b)
                } else {
                    Vec3::new(b, y, a)
                }
            })
            .collect()
    };
    let mut positions = strip(true, 0.0);
    positions.extend(strip(false, gap));
    let soup = clothsim::mesh::PolygonSoup {
        positions,
        uvs: None,
        face_indices: vec![0, 1, 2, 3, 4, 5, 6, 7],
        face_arities: vec![4, 4],
    };
    let mesh = build_mesh(&soup, std::path::Path::new("strips"))
        .unwrap()
        .mesh;
    let model = ClothModel::new(&mesh, 0.2, pinned);
    let state = ClothState::at_rest(&model);
    (model, state)
}

#[test]
fn edges_that_cross_without_a_vertex_near_a_face_are_caught() {
    let (model, mut state) = crossed_strips(0.05, &[0, 1, 2, 3]);
    let start = state.pos.clone();
    // The upper strip moves 10 cm down in one substep: through the lower one.
    for p in &mut state.pos[4..] {
        p.y -= 0.1;
    }
    // Unresolved, it would end on the other side.
    assert!(state.pos[4..].iter().all(|p| p.y < 0.0));
    let mut solver = SelfContacts::default();
    solver
        .resolve([0.005, 0.0], &model, &start, &mut state)
        .unwrap();
    assert_eq!(self_intersections(&model.triangles, &state.pos), 0);
    // It stopped above the lower strip, not merely somewhere else.
    let lowest = clothsim::mesh::bounds(&state.pos[4..]).0.y;
    assert!(lowest > 0.0, "upper strip at {lowest} m");
}

/// The crossed strips (`pinned` held) with the upper one moved 10 cm down through the
/// lower in one resolved substep: the solver, the state and the substep's start.
fn driven_through(pinned: &[u32]) -> (SelfContacts, ClothState, Vec<Vec3>) {
    let (model, mut state) = crossed_strips(0.05, pinned);
    let start = state.pos.clone();
    for p in &mut state.pos[4..] {
        p.y -= 0.1;
    }
    let mut solver = SelfContacts::default();
    solver
        .resolve([0.005, 0.0], &model, &start, &mut state)
        .unwrap();
    (solver, state, start)
}

/// Where prescribed motion drives the cloth through itself, no cut can stop it: the pairs
/// are counted, not hidden.
#[test]
fn prescribed_motion_through_the_cloth_is_counted() {
    // Both strips pinned: the upper one is moved through the lower one as a handle would.
    let (solver, state, _) = driven_through(&[0, 1, 2, 3, 4, 5, 6, 7]);
    assert!(solver.work.forced > 0, "{:?}", solver.work);
    assert_eq!(solver.work.forced_total, solver.work.forced);
    // The pins' motion stands: the upper strip went through, below the lower one.
    assert!(state.pos[4..].iter().all(|p| p.y < 0.0));
}

/// A particle that prescribed motion drives through is held at its start, and the check
/// stops once its cuts move nothing more (it went on cutting it to where it was, for
/// ever); each forced pair is counted once, though the motion was checked again after the
/// cut: with one particle of the driven strip left free, the same pairs are forced as with
/// the strip pinned whole, and the free particle's pairs were cut first.
#[test]
fn a_forced_pair_is_counted_once_and_the_check_ends() {
    let forced = |pinned: &[u32]| {
        let (solver, state, start) = driven_through(pinned);
        let held = state.pos[7] == start[7];
        (solver.work.forced, solver.work.impacts, held)
    };
    let (all, _, _) = forced(&[0, 1, 2, 3, 4, 5, 6, 7]);
    let (some, impacts, held) = forced(&[0, 1, 2, 3, 4, 5, 6]);
    assert!(held, "the free particle is held at its start");
    assert!(all > 0);
    assert_eq!(some, all);
    assert!(
        impacts > some,
        "the free particle's pairs were cut: {impacts}"
    );
}

/// Story: a grab moved the held particle between frames, outside every substep, so a drag
/// through the cloth made it cross itself unseen: nothing cut, nothing counted. The move
/// now runs in the next frame's first substep, so self-contact sees it: every frame in which
/// a drag down through `layers` makes the cloth cross itself counts forced pairs, and a
/// drag along the top layer, through nothing, counts none; stepped a frame at a time (the
/// state read or not before it) or a substep at a time, on the CPU and on the GPU (the software adapter), where the state is
/// sent with the held particle where the move started and the first substep carries it on.
#[test]
fn a_grab_dragged_through_the_cloth_is_counted_not_hidden() {
    let by_frames = |sim: &mut Simulation| {
        sim.step_frame().expect("the drag is stepped");
    };
    // The state read between the grab and the step (on the GPU, sent to the device before
    // the move is handed over).
    let read_first = |sim: &mut Simulation| {
        sim.sync_state().expect("read back");
        sim.step_frame().expect("the drag is stepped");
    };
    let by_substeps = |sim: &mut Simulation| {
        for _ in 0..sim.substeps() {
            sim.substep().expect("the drag is stepped");
        }
    };
    let drag = |by: Vec3, step: &dyn Fn(&mut Simulation), (on_gpu, kind): (bool, _)| {
        let scene = Scene::open_resized("layers", None, &ImportOptions::default(), Some(8));
        let mut scene = scene.expect("layers");
        scene.params.step.integrator = kind;
        let mut sim = match on_gpu {
            true => common::gpu_simulation(scene, true).expect("GPU backend").0,
            false => Simulation::new(scene),
        };
        let forced = |sim: &Simulation| sim.forced_pairs().expect("self-collision");
        // The middle particle of the top layer (the last of the five).
        let n = sim.model().particle_count();
        let p = (4 * n / 5 + n / 10) as u32;
        let start = sim.state().pos[p as usize];
        let (mut crossings, mut counted) = (0, 0);
        for k in 1..=6 {
            let (before, was) = (forced(&sim), sim.intersections().self_pairs);
            sim.grab(p, start + by * k as f32);
            step(&mut sim);
            sim.sync_state().expect("read back");
            if sim.intersections().self_pairs > was {
                crossings += 1;
                counted += usize::from(forced(&sim) > before);
            }
        }
        (crossings, counted, forced(&sim))
    };
    let down = Vec3::new(0.0, -0.03, 0.0);
    let along = Vec3::new(0.01, 0.0, 0.0);
    for on_gpu in [false, true] {
        let at = (on_gpu, IntegratorKind::ImplicitEuler);
        for step in [
            &by_frames as &dyn Fn(&mut Simulation),
            &read_first,
            &by_substeps,
        ] {
            let (crossings, counted, total) = drag(down, step, at);
            assert!(crossings > 0, "the drag goes through the layers below");
            assert_eq!(counted, crossings, "{total} forced in all ({at:?})");
            assert_eq!(
                drag(along, step, at),
                (0, 0, 0),
                "along the top layer ({at:?})"
            );
        }
        // Under XPBD, whose contacts on the GPU read the substep's start from copies of
        // their own, and symplectic Euler: every crossing is counted (the GPU's XPBD
        // crosses nowhere, the free layers cut out of the way; with the move unseen it
        // crossed in 3 frames, none counted).
        for kind in [IntegratorKind::Xpbd, IntegratorKind::SemiImplicitEuler] {
            let at = (on_gpu, kind);
            let (crossings, counted, total) = drag(down, &by_frames, at);
            assert_eq!(counted, crossings, "{total} forced in all ({at:?})");
            assert_eq!(drag(along, &by_frames, at), (0, 0, 0), "along ({at:?})");
        }
    }
}

fn builtin(name: &str, quads: Option<u32>) -> Simulation {
    let scene = Scene::open_resized(name, None, &ImportOptions::default(), quads).unwrap();
    Simulation::new(scene)
}

/// Runs `name` (resized to `quads`) for `seconds` under `integrator` at `substeps`,
/// checking every frame: no intersection of the cloth with itself or a solid, finite, no
/// frame the guard gave up on, and no pair forced by prescribed motion.
fn never_passes_through(
    name: &str,
    quads: Option<u32>,
    integrator: IntegratorKind,
    substeps: u32,
    seconds: f64,
) {
    let mut scene = Scene::open_resized(name, None, &ImportOptions::default(), quads).unwrap();
    scene.params.step.integrator = integrator;
    scene.params.step.substeps = substeps;
    let mut sim = Simulation::new(scene);
    assert_eq!(sim.intersections().total(), 0, "{name} starts free");
    let frames = (seconds / sim.params().step.dt as f64).round() as usize;
    for frame in 1..=frames {
        sim.step_frame()
            .unwrap_or_else(|e| panic!("{name} {integrator:?} frame {frame}: {e}"));
        let found = sim.intersections();
        assert_eq!(
            found.self_pairs, 0,
            "{name} {integrator:?}: the cloth crosses itself after frame {frame}"
        );
        assert_eq!(
            found.total(),
            0,
            "{name} {integrator:?}: the cloth meets a solid after frame {frame}: {found:?}"
        );
        assert!(sim.state().is_finite());
        for e in sim.take_guard_events() {
            assert_ne!(e.action, GuardAction::GaveUp, "{name} {integrator:?}: {e}");
        }
    }
    let work = sim.self_collision_work().unwrap();
    assert_eq!(
        work.forced_total, 0,
        "{name} {integrator:?}: prescribed motion forced a pair"
    );
}

/// The integrators that step at a few substeps a frame, as a user runs them (3 here); the
/// explicit ones run at the scene's `explicit_substeps`, which their stability needs.
const FEW_SUBSTEPS: [IntegratorKind; 3] = [
    IntegratorKind::ImplicitEuler,
    IntegratorKind::Xpbd,
    IntegratorKind::Vbd,
];

/// [`never_passes_through`] under each of `integrators`: those of [`FEW_SUBSTEPS`] at 3
/// substeps a frame, the explicit ones at `explicit_substeps`.
fn never_passes_through_under(
    integrators: &[IntegratorKind],
    name: &str,
    quads: Option<u32>,
    explicit_substeps: u32,
    seconds: f64,
) {
    for &integrator in integrators {
        let substeps = if FEW_SUBSTEPS.contains(&integrator) {
            3
        } else {
            explicit_substeps
        };
        never_passes_through(name, quads, integrator, substeps, seconds);
    }
}

/// At its own 32² and for 2 s, where it lands on the sphere and folds onto the ground: at
/// 16² for 1.5 s it kept free of itself under every integrator even with the edge–edge pairs
/// left out; here five of the eight cross.
#[test]
fn crumple_never_passes_through_itself() {
    never_passes_through_under(&IntegratorKind::ALL, "crumple", Some(32), 24, 2.0);
}

#[test]
fn twist_never_passes_through_itself() {
    never_passes_through_under(&IntegratorKind::ALL, "twist", None, 64, 2.0);
}

#[test]
fn layers_never_pass_through_each_other() {
    let others: Vec<_> = (IntegratorKind::ALL.into_iter())
        .filter(|&k| k != IntegratorKind::ExplicitEuler)
        .collect();
    never_passes_through_under(&others, "layers", Some(8), 24, 1.2);
}

/// Explicit Euler on its own: its guard refines the stack to 384 substeps a frame, so this
/// is the longest of these runs (about half a minute), and runs beside the others.
#[test]
fn layers_never_pass_through_each_other_under_explicit_euler() {
    let explicit_euler = [IntegratorKind::ExplicitEuler];
    never_passes_through_under(&explicit_euler, "layers", Some(8), 24, 1.2);
}

/// Five 32 × 32 cloths stacked on a sphere at one implicit substep a frame: the sphere
/// presses the lowest layers into those above every substep, and pairs come within what
/// `f32` can tell apart (5·10⁻⁸ m); the cut positions, rounded to `f32`, are checked
/// again, so none crosses.
#[test]
fn layers_pressed_by_a_solid_never_pass_through_at_one_substep() {
    never_passes_through("layers", Some(32), IntegratorKind::ImplicitEuler, 1, 2.0);
}

/// Five 24 × 24 cloths at one implicit substep a frame, falling 4 cm a substep onto the
/// sphere: in frame 16 the stack pressed under the second layer held one of its particles
/// at its start, 4 cm above where the cloth's falling frame had gone on to. Its pairs with
/// the third layer, falling onto it, had been found for its motion before the cut, in
/// that frame, and the cut motion left the box they held for; searched again, the third
/// layer is cut too. (With the pairs kept, 56 pairs of triangles crossed there.)
#[test]
fn a_particle_held_back_by_a_cut_keeps_the_layer_falling_onto_it_out() {
    never_passes_through("layers", Some(24), IntegratorKind::ImplicitEuler, 1, 0.5);
}

/// The flung half lands on the pinned one in frame 26 at 16 quads; with the continuous
/// check left out, XPBD's cloth crossed itself there (13 pairs of triangles).
#[test]
fn fast_fold_never_passes_through_itself() {
    never_passes_through_under(&IntegratorKind::ALL, "fast-fold", Some(16), 24, 0.8);
}

/// Coulomb's law on an incline: the upper cloth slides with acceleration g (sin θ − μ cos
/// θ) when tan θ > μ, and stays when tan θ < μ: it does not freeze into the one below, and
/// friction is not lost.
#[test]
fn a_cloth_slides_off_another_as_coulomb_friction_says() {
    let mu = 0.3f32;
    for degrees in [30.0f32, 40.0] {
        let mut sim = Simulation::new(incline(degrees, mu, 8));
        let (a, expected) = slope_acceleration(&mut sim, (degrees, mu), (0.05, 0.2));
        assert!(
            (a - expected).abs() < 0.1 * expected,
            "{degrees}°: {a} m/s² against Coulomb's {expected}"
        );
    }
    // tan 10° = 0.18 < 0.3: it holds.
    let mut sim = Simulation::new(incline(10.0, mu, 8));
    sim.run(0.3);
    assert!(slope_speed(&sim).abs() < 0.01, "{} m/s", slope_speed(&sim));
}

/// A cloth draped over a sphere stays on it beside self-contact as it does without: the
/// sphere keeps the triangles' interiors out too (a face dips in between its corners),
/// and a face it holds up slides with the sphere's friction, as a particle does. Without
/// that friction the face pass lifted the draped cloth past the particles' offset, where
/// it slid off the sphere frictionless: `sphere-drop` at 12 quads with self-collision
/// ended 2 s with its particles 0.10 m high on average on the ground, against 0.69 m
/// draped over the sphere without self-collision.
#[test]
fn a_cloth_draped_on_a_sphere_stays_on_it_beside_self_contact() {
    let grid = ("quads = 24".to_string(), "quads = 12".to_string());
    let plane = "type = \"plane\"\nfriction = 0.4\n".to_string();
    let own = "\n[[effects]]\ntype = \"self-collision\"\nthickness = 0.01\nfriction = 0.3\n";
    let height = |edits: &[(&str, String)]| {
        let mut sim = Simulation::new(parsed(&edited_builtin("sphere-drop", edits)));
        sim.run(2.0);
        let pos = &sim.state().pos;
        pos.iter().map(|p| p.y).sum::<f32>() / pos.len() as f32
    };
    let alone = height(&[(&grid.0, grid.1.clone())]);
    let beside = height(&[(&grid.0, grid.1.clone()), (&plane, format!("{plane}{own}"))]);
    // The sphere's top is 0.85 m up: draped, the cloth's particles average about 0.69 m.
    assert!(
        alone > 0.6,
        "without self-collision the cloth lies {alone} m up"
    );
    assert!(
        (beside - alone).abs() < 0.02,
        "beside self-contact {beside} m up, without {alone} m"
    );
}

#[test]
fn quads_resizes_a_grid_and_its_thickness_with_it() {
    let sim = builtin("crumple", Some(64));
    assert_eq!(sim.model().particle_count(), 65 * 65);
    let thickness = |sim: &Simulation| {
        sim.effects()
            .iter()
            .find_map(|e| match e {
                clothsim::sim::Effect::SelfCollision(s) => Some(s.thickness),
                _ => None,
            })
            .unwrap()
    };
    assert!(
        (thickness(&sim) - 0.003).abs() < 1e-6,
        "{}",
        thickness(&sim)
    );
    // Coarser: the thickness stays.
    assert_eq!(thickness(&builtin("crumple", Some(16))), 0.006);
    // A strip keeps its proportions.
    assert_eq!(builtin("twist", Some(64)).model().particle_count(), 65 * 17);
    // An OBJ cloth cannot be resized.
    let err = Scene::open_resized(
        "hanging",
        Some(std::path::Path::new("assets/cloth.obj")),
        &ImportOptions::default(),
        Some(8),
    )
    .unwrap_err();
    assert!(err.to_string().contains("--quads"), "{err}");
    // Nor can a scene file's OBJ cloth, and 0 quads or more than 2048 are refused.
    let text = "name = \"o\"\n[cloth]\nobj = \"cloth.obj\"\n";
    let mut file = SceneFile::parse(text, std::path::Path::new("o.toml")).unwrap();
    let err = file.resize_grid(8).unwrap_err().to_string();
    assert!(err.contains("OBJ") && err.contains("--quads"), "{err}");
    for quads in [0, 2049] {
        let err = Scene::open_resized("crumple", None, &ImportOptions::default(), Some(quads))
            .unwrap_err()
            .to_string();
        assert!(err.contains("1..=2048"), "{quads}: {err}");
    }
}

/// The search for pairs is shared out between the team (from 2 048 triangles on), and so
/// are the refreshes, the picking of the pairs to push and the continuous checks (from
/// 16 384 pairs), and the pushes (from 4 096 pairs, in groups of slabs): the pieces are
/// read in their own order, the cuts keep their least and the groups pushed side by side
/// reach disjoint particles, so `layers` (five 24 × 24 cloths, 5 760 triangles, landing on a sphere and on each
/// other) ends its first second in the same bits on two threads as on one.
#[test]
fn self_contact_gives_the_same_bits_on_two_threads_as_on_one() {
    let run = |threads: usize| {
        let mut sim = builtin("layers", None);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        // The most pairs, and the most pushes, in any frame's last substep.
        let mut most = (0, 0);
        pool.install(|| {
            for _ in 0..60 {
                sim.step_frame().unwrap();
                let work = sim.self_collision_work().unwrap();
                most = (most.0.max(work.candidates), most.1.max(work.contacts));
            }
        });
        (sim.state().clone(), most)
    };
    let ((one, most), (two, _)) = (run(1), run(2));
    assert!(most.0 > 20_000 && most.1 > 1000, "{most:?}");
    assert!(one.pos == two.pos && one.vel == two.vel);
}

/// A cloth that starts through a solid, or through itself, is warned about with the count
/// the check finds; a mesh obstacle through it is counted too.
#[test]
fn a_cloth_that_starts_intersecting_is_warned_with_the_count() {
    // A ground tilted through the middle of a flat 8 × 8 cloth.
    let grid = "name = \"start\"\n[cloth]\ngrid = { quads = 8, size = 1.0 }\n";
    let sim = Simulation::new(parsed(&format!(
        "{grid}[[effects]]\ntype = \"plane\"\nnormal = [0.0, 1.0, 0.3]\n"
    )));
    let found = sim.intersections();
    let below = found.obstacles[0];
    assert!(
        below > 8 && below < 128,
        "{below} of 128 triangles below the ground"
    );
    let warned = sim.warnings().join("\n");
    assert!(
        warned.contains(&format!("{below} of its triangles")) && warned.contains("plane"),
        "{warned}"
    );
    // The back half folded over the front one, tilted so that it passes through it.
    let mut scene = parsed(grid);
    for p in &mut scene.initial.pos {
        if p.z < 0.0 {
            *p = Vec3::new(p.x, 0.3 * -p.z - 0.1, -p.z);
        }
    }
    let pos = scene.initial.pos.clone();
    let pairs = self_intersections(&scene.model.triangles, &pos);
    assert!(pairs > 0);
    let sim = Simulation::new(scene);
    let warned = sim.warnings().join("\n");
    assert!(
        warned.contains(&format!(
            "intersects itself at the start ({pairs} triangle pairs"
        )),
        "{warned}"
    );
    // A mesh sphere through the flat cloth meets it; lifted clear, it does not.
    // Moved by keyframes, it is counted where its motion has it at the time asked.
    let sim = Simulation::new(parsed(grid));
    let through = |lift: f32, moves: Option<Vec3>, time: f64| {
        let mut sphere = clothsim::sim::Obstacle::new("ball.obj");
        if let Some(by) = moves {
            let key = |time, translate| clothsim::sim::Keyframe {
                time,
                translate,
                rotate: None,
                ease: clothsim::sim::Ease::Linear,
            };
            sphere.keyframes = vec![key(0.0, None), key(1.0, Some(by))];
        }
        let mut soup = clothsim::bench_contact::cube_sphere(0.3, 1000);
        for p in &mut soup.positions {
            p.y += lift;
        }
        sphere.load_mesh(&soup).unwrap();
        let effects = [clothsim::sim::Effect::Obstacle(sphere)];
        let model = sim.model();
        let pos = &sim.state().pos;
        clothsim::sim::intersections(&effects, time, &model.triangles, pos).obstacles[0]
    };
    assert!(through(0.0, None, 0.0) > 0);
    assert_eq!(through(0.5, None, 0.0), 0);
    let down = Some(Vec3::new(0.0, -0.5, 0.0));
    assert_eq!(through(0.5, down, 0.0), 0);
    assert!(through(0.5, down, 1.0) > 0);
}

/// Two 8 × 8 cloths stacked on a ground, the upper one falling onto the lower: self-contact
/// moves the particles the ground placed only where nothing else can, so it pushes the
/// upper cloth up the whole thickness rather than the lower one into the ground, and
/// inside their borders the two stay a thickness apart after every frame. With the
/// ground's particles not held they came within 0.72 of it.
#[test]
fn a_cloth_resting_on_a_solid_is_not_pushed_into_it() {
    let (thickness, quads) = (0.01, 8);
    let text = format!(
        "name = \"stack\"\n[cloth]\ngrid = {{ quads = {quads}, size = 0.5, layers = 2, spacing = {} }}\n\
         [solver]\nintegrator = \"implicit-euler\"\nsubsteps = 2\n\
         [[effects]]\ntype = \"gravity\"\n\
         [[effects]]\ntype = \"plane\"\npoint = [0.0, -0.002, 0.0]\n\
         [[effects]]\ntype = \"self-collision\"\nthickness = {thickness}\nfriction = 0.0\n",
        1.5 * thickness,
    );
    let file = SceneFile::parse(&text, std::path::Path::new("stack.toml")).unwrap();
    let mut sim = Simulation::new(Scene::from_file(file, None).unwrap());
    let n = sim.model().particle_count() / 2;
    let mut least = f32::INFINITY;
    for _ in 0..30 {
        sim.step_frame().unwrap();
        let pos = &sim.state().pos;
        // Inside the borders, where the upper cloth lies over the lower one.
        let side = quads + 1;
        let inner = |k: usize| (1..quads).contains(&k);
        let inside = (0..n).filter(|i| inner(i % side) && inner(i / side));
        let gap = inside
            .map(|i| pos[n + i].y - pos[i].y)
            .fold(f32::INFINITY, f32::min);
        least = least.min(gap);
    }
    assert!(least >= 0.99 * thickness, "{least} apart");
}

/// A sphere smaller than the cloth's particle spacing holds a coarse cloth up by its
/// faces, with self-collision and without: `crumple` at 4 quads (25 cm apart) lands on its
/// sphere of 15 cm radius, which fits between four particles, and the exact check finds no
/// triangle through the sphere after any frame of 2 s. Without self-collision the solids
/// kept only the particles and edges out, and the cloth draped over the sphere with
/// triangles through it (a case once only warned about).
#[test]
fn a_sphere_between_a_coarse_cloths_particles_never_comes_through_it() {
    for own in [true, false] {
        let scene = Scene::open_resized("crumple", None, &ImportOptions::default(), Some(4));
        let mut scene = scene.expect("crumple");
        if !own {
            (scene.effects).retain(|e| !matches!(e, clothsim::sim::Effect::SelfCollision(_)));
        }
        let mut sim = Simulation::new(scene);
        // The sphere is the first solid.
        for frame in 0..120 {
            sim.step_frame().expect("a frame");
            let through = sim.intersections().obstacles[0];
            assert_eq!(
                through, 0,
                "self-collision {own}: {through} through the sphere after frame {frame}"
            );
        }
    }
}

/// The built-in scenes a user shrinks to a coarse cloth, without self-collision:
/// `tablecloth` at 6 quads (27 cm), whose table's corners poke up between the particles,
/// and `rotating-sphere` at 6 quads (17 cm), whose sphere of 40 cm rises 9 mm under a
/// cell's corners, about the offset the particles keep. Under every
/// integrator at the scene's substeps, the exact check finds no cloth triangle through a
/// solid after any frame of the first second. Kept out by their particles and edges
/// alone, 10 of the cloth's triangles met the table by 0.7 s, and 12–16 the sphere by
/// 0.5 s.
#[test]
fn coarse_built_in_cloths_never_meet_their_solids_without_self_collision() {
    for name in ["tablecloth", "rotating-sphere"] {
        for integrator in IntegratorKind::ALL {
            let mut scene =
                Scene::open_resized(name, None, &ImportOptions::default(), Some(6)).expect(name);
            scene.params.step.integrator = integrator;
            let mut sim = Simulation::new(scene);
            for frame in 0..60 {
                sim.step_frame().expect("a frame");
                let found = sim.intersections();
                assert_eq!(
                    found.total(),
                    0,
                    "{name} {integrator:?}: the cloth meets a solid after frame {frame}: {found:?}"
                );
            }
            assert!(sim.state().is_finite(), "{name} {integrator:?}");
        }
    }
}

/// A small cloth driven along the ground into the wedge under a sphere resting on it
/// ([`wedge`]). Near where the two touch, the sphere's collision offset and the ground's
/// overlap, and no place keeps a particle both offsets clear of both. Acting one after the
/// other, the ground's push came last and lifted the particle into the sphere. Now after
/// every substep every particle keeps both offsets, and after every frame no triangle
/// meets either, with and without self-collision (with it, nor itself).
#[test]
fn a_cloth_driven_into_the_wedge_under_a_sphere_on_the_ground_enters_neither() {
    let centre = Vec3::new(0.0, WEDGE_RADIUS, 0.0);
    for own in [
        "",
        "[[effects]]\ntype = \"self-collision\"\nthickness = 0.004\n",
    ] {
        let mut sim = Simulation::new(wedge(own));
        assert_eq!(sim.intersections().total(), 0, "the cloth starts clear");
        let (substeps, mut closest) = (sim.substeps() as usize, f32::INFINITY);
        for frame in 1..=30 {
            for substep in 0..substeps {
                sim.substep().unwrap();
                for (i, p) in sim.state().pos.iter().enumerate() {
                    let (r, y) = (p.distance(centre), p.y);
                    closest = closest.min(p.x.hypot(p.z));
                    // Both collision offsets (1 cm) kept, to their rounding.
                    assert!(
                        r >= WEDGE_RADIUS + 0.0099 && y >= 0.0099,
                        "frame {frame} substep {substep}: particle {i} at {p} is {} m \
                         from the sphere's surface, {y} m above the ground ({own:?})",
                        r - WEDGE_RADIUS
                    );
                }
            }
            // (Without self-collision the crumpled cloth may cross itself.)
            let found = sim.intersections();
            assert_eq!(found.obstacles, [0, 0], "frame {frame} ({own:?})");
            if !own.is_empty() {
                assert_eq!(found.self_pairs, 0, "frame {frame}: crosses itself");
            }
        }
        // It went in, as far as where the two offsets meet (0.1095 m from the axis).
        assert!(
            closest < 0.111,
            "the cloth kept {closest} m from the axis ({own:?})"
        );
    }
}
