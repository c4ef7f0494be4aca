//! Scene files: the built-in scenes are files read by the same code as the user's; every
//! problem is reported with file, line, column and key; a saved setup reloads as it was.

use std::path::Path;

use clothsim::mesh::load_obj;
use clothsim::scene::{BUILTIN_SCENES, Scene, SceneError, SceneFile, Simulation, scenarios};
use clothsim::sim::{BendingModel, ClothSprings, Effect, Gravity, IntegratorKind, Sphere, Wind};
use glam::Vec3;

/// A minimal valid scene with `extra` appended.
fn scene_text(extra: &str) -> String {
    format!(
        "name = \"test\"\n\
         [cloth]\n\
         grid = {{ quads = 4, size = 1.0 }}\n\
         orientation = \"vertical\"\n\
         {extra}"
    )
}

fn parse_error(text: &str) -> (usize, usize, String) {
    match SceneFile::parse(text, Path::new("dir/my.toml")) {
        Err(SceneError::File {
            path,
            line,
            column,
            message,
        }) => {
            assert_eq!(path, Path::new("dir/my.toml"));
            (line, column, message)
        }
        other => panic!("expected a file error, got {other:?}"),
    }
}

#[test]
fn every_builtin_scene_file_parses_builds_and_round_trips() {
    assert_eq!(BUILTIN_SCENES.len(), 14);
    for file in scenarios() {
        let scene = Scene::builtin(&file.name).expect("builds");
        // The smallest, `orders`, is 7 × 7.
        assert!(scene.model.particle_count() >= 49, "{}", file.name);
        // Written out and read back, the file is the same file.
        let again = SceneFile::parse(&file.to_toml(), Path::new("again.toml")).expect("reparses");
        assert_eq!(&again, file, "{}", file.name);
    }
    let names: Vec<&str> = scenarios().iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "hanging",
            "sphere-drop",
            "rotating-sphere",
            "flag",
            "self-fold",
            "tablecloth",
            "carousel",
            "twist",
            "arm",
            "crumple",
            "layers",
            "fast-fold",
            "hanging-bench",
            "orders",
        ]
    );
}

#[test]
fn a_syntax_error_names_file_line_and_column() {
    let text = scene_text("[solver]\ndt = = 0.01\n");
    let (line, column, message) = parse_error(&text);
    assert_eq!((line, column), (6, 6), "{message}");
    let shown = SceneFile::parse(&text, Path::new("dir/my.toml"))
        .unwrap_err()
        .to_string();
    assert!(shown.starts_with("dir/my.toml:6:6: "), "{shown}");
}

#[test]
fn an_unknown_key_is_an_error_that_names_it() {
    let (line, column, message) = parse_error(&scene_text("[solver]\nsubstep = 4\n"));
    assert_eq!((line, column), (6, 1));
    assert!(message.contains("unknown field `substep`"), "{message}");
    assert!(
        message.contains("`substeps`"),
        "the valid keys are listed: {message}"
    );
    // Inside an effect too.
    let (line, _, message) = parse_error(&scene_text(
        "[[effects]]\ntype = \"wind\"\nvelocity = [1.0, 0.0, 0.0]\nspeed = 3.0\n",
    ));
    assert_eq!(line, 8);
    assert!(message.contains("`speed`"), "{message}");
    // An unknown effect type names the known ones.
    let (line, _, message) = parse_error(&scene_text("[[effects]]\ntype = \"magnetism\"\n"));
    assert_eq!(line, 6, "at the `type` key");
    assert!(
        message.contains("magnetism") && message.contains("self-collision"),
        "{message}"
    );
}

#[test]
fn a_value_of_the_wrong_type_names_line_and_key() {
    let (line, _, message) = parse_error(&scene_text("[solver]\nsubsteps = \"many\"\n"));
    assert_eq!(line, 6);
    assert!(
        message.contains("string") || message.contains("integer"),
        "{message}"
    );
}

#[test]
fn out_of_range_values_name_the_key_and_its_line() {
    let cases = [
        ("[solver]\ndt = -0.01\n", 6, "`dt`"),
        ("[solver]\nsubsteps = 0\n", 6, "`substeps`"),
        ("[material]\ndensity = 0.0\n", 6, "`density`"),
        ("[material]\ndensity = 1e-38\n", 6, "`density`"),
        ("[material]\ndensity = 1e6\n", 6, "`density`"),
        (
            "[material]\nstiffness = { structural = -5.0, shear = 1.0, bend = 1.0 }\n",
            6,
            "`stiffness`",
        ),
        (
            "[[effects]]\ntype = \"gravity\"\n\n[[effects]]\ntype = \"air-damping\"\nrate = -1.0\n",
            10,
            "`rate`",
        ),
        (
            "[[effects]]\ntype = \"gravity\"\n\n[[effects]]\ntype = \"air-damping\"\nrate = 1e30\n",
            10,
            "`rate`",
        ),
        (
            "[[effects]]\ntype = \"gravity\"\nacceleration = [0.0, -1e30, 0.0]\n",
            7,
            "`acceleration`",
        ),
        (
            "[[effects]]\ntype = \"wind\"\nvelocity = [1e30, 0.0, 0.0]\n",
            7,
            "`velocity`",
        ),
        (
            "[[effects]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 0.0\n",
            8,
            "`radius`",
        ),
        (
            "[[effects]]\ntype = \"plane\"\nnormal = [0.0, 0.0, 0.0]\n",
            7,
            "`normal`",
        ),
        (
            "[[effects]]\ntype = \"self-collision\"\nthickness = -0.01\n",
            7,
            "`thickness`",
        ),
        (
            "[[effects]]\ntype = \"bending\"\nmodel = \"dihedral\"\nstiffness = -1.0\n",
            8,
            "`stiffness`",
        ),
    ];
    for (extra, want_line, key) in cases {
        let (line, _, message) = parse_error(&scene_text(extra));
        assert!(message.contains(key), "{extra}: {message}");
        assert_eq!(line, want_line, "{extra}: {message}");
    }
    // The cloth needs exactly one source.
    let (_, _, message) = parse_error("name = \"x\"\n[cloth]\norientation = \"vertical\"\n");
    assert!(message.contains("`obj` or `grid`"), "{message}");
    // Stacked grids: 1 to 64 layers, a positive spacing, the stack lower than the grid is
    // wide (the key named on the grid's line).
    for (grid, key) in [
        ("layers = 0", "`layers`"),
        ("layers = 65", "`layers`"),
        ("layers = 2, spacing = 0.0", "`spacing`"),
        ("layers = 2, spacing = -0.1", "`spacing`"),
        ("layers = 5, spacing = 0.25", "`spacing`"),
    ] {
        let text = format!("name = \"x\"\n[cloth]\ngrid = {{ quads = 4, size = 1.0, {grid} }}\n");
        let (line, _, message) = parse_error(&text);
        assert!(message.contains(key), "{grid}: {message}");
        assert_eq!(line, 3, "{grid}: {message}");
    }
    let text =
        "name = \"x\"\n[cloth]\ngrid = { quads = 4, size = 1.0, layers = 5, spacing = 0.2 }\n";
    SceneFile::parse(text, Path::new("t.toml")).expect("a stack of 0.8 m under a 1 m grid");
}

#[test]
fn a_scene_file_builds_its_cloth_pins_solver_material_and_effects() {
    let text = scene_text(
        "center = [0.0, 2.0, 0.0]\n\
         [pins]\ncorners = [\"top-left\", \"top-right\"]\nindices = [12]\n\
         [solver]\nintegrator = \"rk4\"\ndt = 0.01\nsubsteps = 30\n\
         [material]\ndensity = 0.3\nstiffness = { structural = 300.0, shear = 100.0, bend = 5.0 }\n\
         [[effects]]\ntype = \"gravity\"\nacceleration = [0.0, -3.0, 0.0]\n\
         [[effects]]\ntype = \"bending\"\nmodel = \"dihedral\"\nstiffness = 0.01\n\
         [[effects]]\ntype = \"wind\"\nvelocity = [0.0, 0.0, 5.0]\ngust = 0.0\n\
         [[effects]]\ntype = \"sphere\"\ncenter = [0.0, 1.0, 0.0]\nradius = 0.25\nspin = [0.0, 2.0, 0.0]\n",
    );
    let file = SceneFile::parse(&text, Path::new("t.toml")).expect("valid");
    let scene = Scene::from_file(file, None).expect("builds");
    assert_eq!(scene.model.particle_count(), 25);
    let p = &scene.params;
    assert_eq!(
        (p.step.integrator, p.step.dt, p.step.substeps),
        (IntegratorKind::Rk4, 0.01, 30)
    );
    assert_eq!(
        (p.material.density, p.material.stiffness),
        (0.3, [300.0, 100.0, 5.0])
    );
    // The top corners of a vertical 4×4-quad cloth centred at y = 2, and particle 12.
    let pinned: Vec<Vec3> = scene
        .pins
        .iter()
        .map(|&i| scene.initial.pos[i as usize])
        .collect();
    assert_eq!(scene.pins.len(), 3);
    assert!(scene.pins.contains(&12));
    assert_eq!(
        pinned
            .iter()
            .filter(|x| (x.y - 2.5).abs() < 1e-6 && (x.x.abs() - 0.5).abs() < 1e-6)
            .count(),
        2,
        "{pinned:?}"
    );
    assert_eq!(
        scene.effects,
        vec![
            Effect::Springs(ClothSprings),
            Effect::Gravity(Gravity {
                acceleration: Vec3::new(0.0, -3.0, 0.0),
            }),
            Effect::Bending(BendingModel::Dihedral { stiffness: 0.01 }),
            Effect::Wind(Wind {
                velocity: Vec3::new(0.0, 0.0, 5.0),
                gust: 0.0,
                ..Wind::default()
            }),
            Effect::Sphere(Sphere {
                center: Vec3::new(0.0, 1.0, 0.0),
                radius: 0.25,
                spin: Vec3::new(0.0, 2.0, 0.0),
                friction: 0.5,
            }),
        ]
    );
}

#[test]
fn pins_by_region_and_bad_pins_are_reported() {
    let scene = |pins: &str| {
        let file = SceneFile::parse(&scene_text(pins), Path::new("t.toml")).expect("parses");
        Scene::from_file(file, None)
    };
    // The vertical cloth spans y ∈ [−0.5, 0.5]: the top row is the 5 particles at y = 0.5.
    let top = scene("[pins]\nregion = { min = [-9.0, 0.4, -9.0], max = [9.0, 9.0, 9.0] }\n")
        .expect("builds");
    assert_eq!(top.pins.len(), 5);
    assert!(
        top.pins
            .iter()
            .all(|&p| top.initial.pos[p as usize].y > 0.49)
    );
    let edge = scene("[pins]\nedges = [\"left\"]\n").expect("builds");
    assert!(
        edge.pins
            .iter()
            .all(|&p| edge.initial.pos[p as usize].x < -0.49)
    );
    assert_eq!(edge.pins.len(), 5);
    let err = scene("[pins]\nindices = [25]\n").expect_err("only 25 particles");
    assert!(err.to_string().contains("25"), "{err}");
    let err = scene("[pins]\nregion = { min = [5.0, 5.0, 5.0], max = [6.0, 6.0, 6.0] }\n")
        .expect_err("an empty region is a mistake");
    assert!(err.to_string().contains("region"), "{err}");
}

#[test]
fn an_obj_path_is_relative_to_the_scene_file() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("cloths");
    std::fs::create_dir(&sub).unwrap();
    std::fs::copy("assets/cloth.obj", sub.join("c.obj")).unwrap();
    let path = dir.path().join("s.toml");
    std::fs::write(
        &path,
        "name = \"mine\"\n[cloth]\nobj = \"cloths/c.obj\"\n[[effects]]\ntype = \"gravity\"\n",
    )
    .unwrap();
    // Not relative to the working directory: it is the project root here.
    let scene = Scene::open(path.to_str().unwrap()).expect("found beside the file");
    assert_eq!(scene.scenario, "mine");
    assert_eq!(
        scene.model.particle_count(),
        load_obj(Path::new("assets/cloth.obj"))
            .unwrap()
            .mesh
            .positions
            .len()
    );
    // A missing cloth is named with the path it was looked for at.
    std::fs::remove_file(sub.join("c.obj")).unwrap();
    let err = Scene::open(path.to_str().unwrap()).unwrap_err().to_string();
    assert!(err.contains("cloths/c.obj"), "{err}");
}

#[test]
fn unreadable_scene_files_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    let err = Scene::open(dir.path().join("none.toml").to_str().unwrap()).unwrap_err();
    assert!(err.to_string().contains("none.toml"), "{err}");
    let err = Scene::open(dir.path().to_str().unwrap().to_owned().as_str()).unwrap_err();
    assert!(!err.to_string().is_empty());
    let folder = dir.path().join("folder.toml");
    std::fs::create_dir(&folder).unwrap();
    let err = Scene::open(folder.to_str().unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("folder.toml") && err.contains("regular file"),
        "{err}"
    );
}

#[test]
fn a_saved_setup_reloads_as_it_was_running() {
    let dir = tempfile::tempdir().unwrap();
    let mut sim = Simulation::new(Scene::builtin("sphere-drop").unwrap());
    // Change everything a user can change live.
    let mut params = sim.params().clone();
    params.step.integrator = IntegratorKind::ImplicitEuler;
    params.step.substeps = 7;
    params.material.stiffness = [321.0, 123.0, 12.0];
    sim.set_params(params.clone()).unwrap();
    let mut effects = sim.effects().to_vec();
    for e in &mut effects {
        match e {
            Effect::AirDamping(a) => a.rate = 0.25,
            Effect::Gravity(g) => g.acceleration = Vec3::new(0.0, -5.0, 0.0),
            _ => {}
        }
    }
    effects.retain(|e| !matches!(e, Effect::Plane(_)));
    effects.push(Effect::Wind(Wind::default()));
    effects.push(Effect::Bending(BendingModel::Dihedral { stiffness: 0.004 }));
    effects.retain(|e| *e != Effect::Bending(BendingModel::Springs));
    sim.set_effects(effects.clone()).unwrap();
    sim.toggle_pin(3);
    let path = dir.path().join("saved.toml");
    std::fs::write(&path, sim.scene_file().to_toml()).unwrap();

    let again = Scene::open(path.to_str().unwrap()).expect("the saved file loads");
    assert_eq!(again.params, params);
    assert_eq!(again.effects, effects);
    assert_eq!(again.model.particle_count(), sim.model().particle_count());
    assert_eq!(again.pins, vec![3]);
    assert_eq!(
        again.initial.pos,
        sim.initial().pos,
        "the cloth is placed as before"
    );
}

#[test]
fn an_exported_obj_reimports_with_the_same_counts_and_positions() {
    let dir = tempfile::tempdir().unwrap();
    let mut sim = Simulation::new(Scene::builtin("sphere-drop").unwrap());
    sim.run(0.5);
    let path = dir.path().join("out.obj");
    std::fs::write(&path, sim.export_obj()).unwrap();
    let back = load_obj(&path).expect("the export is a valid OBJ");
    assert_eq!(back.mesh.positions.len(), sim.model().particle_count());
    assert_eq!(back.mesh.triangles.len(), sim.model().triangles.len());
    // Welding keeps the order of first appearance, which the export follows: positions
    // come back bit for bit (Rust prints the shortest decimal that reads back the same).
    assert_eq!(back.mesh.positions, sim.state().pos);
    assert_eq!(back.mesh.triangles, sim.model().triangles);
}

/// Story: a 20 × 20 cloth of 1 m with a self-collision thickness of 0.2 m (four times its
/// spacing) aborted under symplectic Euler, and under implicit Euler the guard gave up at
/// t = 0 advising a lower stiffness: every particle started inside its neighbours'
/// triangles. A thickness at or above the shortest rest edge is refused, naming both.
#[test]
fn a_self_collision_thicker_than_the_cloths_edges_is_refused_naming_both_lengths() {
    let grid = |thickness: f32| {
        format!(
            "name = \"t\"\n[cloth]\ngrid = {{ quads = 20, size = 1.0 }}\n\
             [[effects]]\ntype = \"gravity\"\n\
             [[effects]]\ntype = \"self-collision\"\nthickness = {thickness}\n"
        )
    };
    let (line, column, message) = parse_error(&grid(0.2));
    assert_eq!((line, column), (8, 1));
    assert!(
        message.starts_with("`thickness` = 0.2 m") && message.contains("0.05 m"),
        "{message}"
    );
    // Just below the edge is the user's call; at the edge it is refused.
    SceneFile::parse(&grid(0.049), Path::new("t.toml")).expect("below the edge");
    parse_error(&grid(0.05));

    // An OBJ cloth's edges are known once it is imported: the error names the cloth.
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy("assets/cloth.obj", dir.path().join("c.obj")).unwrap();
    let path = dir.path().join("s.toml");
    std::fs::write(
        &path,
        "name = \"s\"\n[cloth]\nobj = \"c.obj\"\n\
         [[effects]]\ntype = \"self-collision\"\nthickness = 0.05\n",
    )
    .unwrap();
    let err = Scene::open(path.to_str().unwrap()).unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, SceneError::Thickness { .. }), "{err:?}");
    assert!(
        text.contains("c.obj") && text.contains("0.05 m") && text.contains("0.0417 m"),
        "{text}"
    );

    // A running simulation refuses it too, and keeps its effects.
    let mut sim = Simulation::new(Scene::builtin("self-fold").unwrap());
    let before = sim.effects().to_vec();
    let mut effects = before.clone();
    for e in &mut effects {
        if let Effect::SelfCollision(s) = e {
            s.thickness = 0.2;
        }
    }
    let err = sim.set_effects(effects).unwrap_err().to_string();
    assert!(err.contains("0.2 m") && err.contains("0.0417 m"), "{err}");
    assert_eq!(sim.effects(), before);
}

/// Story: `Scene::from_file` panicked ("unreachable") on a `SceneFile` built in code with
/// neither `obj` nor `grid`; `SceneFile::parse` refuses such a file, code could still make
/// one. It is an error naming the scene now.
#[test]
fn a_scene_file_built_in_code_without_a_cloth_is_an_error_not_a_panic() {
    let mut file = clothsim::scene::scenario("hanging").unwrap().clone();
    file.cloth.grid = None;
    file.cloth.obj = None;
    let err = Scene::from_file(file, None).unwrap_err();
    assert!(matches!(err, SceneError::NoCloth { .. }), "{err:?}");
    assert!(err.to_string().contains("`hanging` has no cloth"), "{err}");
}

/// An effect a scene has at most one of (gravity, air damping, the bending model, a
/// ground plane, wind, self-collision) listed twice is refused at its second `type`, naming
/// the first: the CPU's forces would sum two gravities where everything that reads one
/// number (the GPU's uniform, the guard's limits) takes the first. Two spheres are two
/// obstacles. A running simulation refuses a second one too, and keeps its effects.
#[test]
fn an_effect_a_scene_has_once_listed_twice_is_refused_naming_both() {
    let twice = "[[effects]]\ntype = \"gravity\"\n\n[[effects]]\ntype = \"air-damping\"\n\
                 rate = 0.1\n\n[[effects]]\ntype = \"gravity\"\n";
    let (line, _, message) = parse_error(&scene_text(twice));
    assert_eq!(line, 13, "{message}");
    assert!(
        message.contains("`gravity` is already effect 1"),
        "{message}"
    );
    let sphere = |x: f32| {
        format!("[[effects]]\ntype = \"sphere\"\ncenter = [{x:?}, 0.0, 0.0]\nradius = 0.2\n")
    };
    let spheres = sphere(0.0) + &sphere(1.0);
    SceneFile::parse(&scene_text(&spheres), Path::new("t.toml")).expect("two spheres");

    let mut sim = Simulation::new(Scene::builtin("hanging").unwrap());
    let before = sim.effects().to_vec();
    let mut effects = before.clone();
    let damping = (before.iter())
        .find(|e| matches!(e, Effect::AirDamping(_)))
        .expect("the hanging cloth has air damping")
        .clone();
    effects.push(damping);
    let err = sim.set_effects(effects).unwrap_err().to_string();
    assert!(
        err.contains("air-damping") && err.contains("is already effect"),
        "{err}"
    );
    assert_eq!(sim.effects(), before);
}
