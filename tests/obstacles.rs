//! Mesh obstacles: a cloth does not pass one, however thin and however fast it comes; it
//! rests on a mesh as on the shape the mesh approximates; a turning one carries it by
//! friction. Bad obstacle input gets one error naming where.

use std::path::Path;

use glam::Vec3;

use clothsim::scene::{Scene, SceneFile, Simulation};
use clothsim::sim::{Effect, IntegratorKind};

/// Writes an OBJ of `vertices` and triangles (0-based) to `path`.
fn write_obj(path: &Path, vertices: &[Vec3], triangles: &[[u32; 3]]) {
    let mut text = String::new();
    for v in vertices {
        text += &format!("v {} {} {}\n", v.x, v.y, v.z);
    }
    for t in triangles {
        text += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(path, text).unwrap();
}

/// A scene from `toml` in `dir` (relative paths start there).
fn scene(dir: &Path, toml: &str) -> Scene {
    let path = dir.join("scene.toml");
    std::fs::write(&path, toml).unwrap();
    Scene::open(&path.display().to_string()).unwrap_or_else(|e| panic!("{e}"))
}

/// Substeps per frame that keep each method stable on a 0.8 m, 16-quad cloth of the
/// default material (the guard stays out: every substep is the integrator's own). The
/// unconditionally stable methods take 4, so that a particle at 10 m/s moves 4 cm a
/// substep, four times the collision offset: only its path, not where it ends, shows
/// that it crossed.
fn stable_substeps(kind: IntegratorKind) -> u32 {
    match kind {
        IntegratorKind::ExplicitEuler => 1500,
        IntegratorKind::Rk2 => 200,
        IntegratorKind::ImplicitEuler | IntegratorKind::Xpbd => 4,
        _ => 64,
    }
}

/// A 0.8 m cloth thrown at 10 m/s onto a single 1 m square of two triangles (no thickness
/// of its own, a 1 cm collision offset): after every substep, under every integrator, each
/// particle over the square is still on its side of it, at least the offset above it.
#[test]
fn a_cloth_thrown_at_a_thin_square_at_10_m_s_never_passes_it() {
    let dir = tempfile::tempdir().unwrap();
    let corners = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)];
    let square: Vec<Vec3> = corners.iter().map(|&(x, z)| Vec3::new(x, 0.0, z)).collect();
    write_obj(
        &dir.path().join("square.obj"),
        &square,
        &[[0, 2, 1], [0, 3, 2]],
    );
    // Three heights, so that some substep of the fast methods ends past the square, not
    // within the offset above it.
    let kinds = IntegratorKind::ALL.into_iter();
    for (kind, height) in kinds.flat_map(|k| [0.3, 0.317, 0.334].map(|h| (k, h))) {
        let mut scene = scene(
            dir.path(),
            &format!(
                r#"
name = "thrown"
[cloth]
grid = {{ quads = 16, size = 0.8 }}
center = [0.0, {height}, 0.0]
[[effects]]
type = "gravity"
[[effects]]
type = "obstacle"
obj = "square.obj"
"#
            ),
        );
        scene.params.step.integrator = kind;
        scene.params.step.substeps = stable_substeps(kind);
        let offset = scene.params.contact.offset;
        let mut sim = Simulation::new(scene);
        sim.modify_state(|s| s.vel.fill(Vec3::new(0.0, -10.0, 0.0)));
        let (mut lowest, mut substeps) = (f32::INFINITY, 0);
        while sim.state().time < 0.1 {
            sim.substep().unwrap();
            substeps += 1;
            for p in &sim.state().pos {
                let over = p.x.abs() < 0.5 && p.z.abs() < 0.5;
                if over {
                    lowest = lowest.min(p.y);
                    assert!(
                        p.y >= offset * 0.999,
                        "{kind:?} from {height} m: a particle at {p} after substep {substeps}"
                    );
                }
            }
        }
        // It did reach the square (and stayed on it).
        assert!(lowest < offset * 1.01, "{kind:?}: lowest {lowest}");
    }
}

/// A missing obstacle OBJ is an error that names that file; a scale of zero names the
/// scene file's line and column and the key.
#[test]
fn bad_obstacle_input_names_where() {
    let dir = tempfile::tempdir().unwrap();
    let base = r#"
name = "bad"
[cloth]
grid = { quads = 4, size = 1.0 }
[[effects]]
type = "obstacle"
"#;
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, format!("{base}obj = \"missing.obj\"\n")).unwrap();
    let err = Scene::open(&path.display().to_string())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("missing.obj") && err.contains("not found"),
        "{err}"
    );

    let text = format!("{base}obj = \"missing.obj\"\nscale = 0.0\n");
    let err = SceneFile::parse(&text, &path).unwrap_err().to_string();
    assert!(
        err.contains("scene.toml:8:") && err.contains("`scale`"),
        "{err}"
    );

    // An obstacle built in code and never read is refused by a running simulation.
    let mut sim = Simulation::new(Scene::builtin("hanging").unwrap());
    let mut effects = sim.effects().to_vec();
    effects.push(Effect::Obstacle(clothsim::sim::Obstacle::new("table.obj")));
    let err = sim.set_effects(effects).unwrap_err().to_string();
    assert!(
        err.contains("table.obj") && err.contains("not read"),
        "{err}"
    );
}
