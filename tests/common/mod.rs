//! What the test files share (the GPU's, and the contact tests).

pub mod tips;

/// [`clothsim::gpu::gpu_simulation`] on the software adapter (Mesa's llvmpipe through GL
/// where there is one), as the golden images: the tests' bounds are its rounding.
#[allow(dead_code)] // Not every test file steps on the GPU.
pub fn gpu_simulation(
    scene: clothsim::scene::Scene,
    read_every_frame: bool,
) -> Result<(clothsim::scene::Simulation, String), clothsim::gpu::GpuError> {
    let software = clothsim::device::AdapterPreference::Software;
    clothsim::gpu::gpu_simulation_on(scene, read_every_frame, software)
}

/// A scene from TOML `text` (a file of no directory).
#[allow(dead_code)] // Not every test file writes scenes out.
pub fn parsed(text: &str) -> clothsim::scene::Scene {
    let path = std::path::Path::new("test.toml");
    let file =
        clothsim::scene::SceneFile::parse(text, path).unwrap_or_else(|e| panic!("{e}\n{text}"));
    clothsim::scene::Scene::from_file(file, None).unwrap_or_else(|e| panic!("{e}"))
}

/// The text of the built-in scene `name` with each edit's first string replaced by its
/// second. Each must be there: a scene whose text changed under a test would otherwise
/// keep the setting the test means to change.
#[allow(dead_code)]
pub fn edited_builtin(name: &str, edits: &[(&str, String)]) -> String {
    let (_, text) = (clothsim::scene::BUILTIN_SCENES.iter())
        .find(|(n, _)| *n == name)
        .unwrap_or_else(|| panic!("no built-in `{name}`"));
    edits.iter().fold(text.to_string(), |text, (from, to)| {
        assert!(text.contains(from), "no `{from}` in `{name}`");
        text.replace(from, to)
    })
}

/// The largest distance between the same particle in `a` and `b`, metres.
pub fn farthest(a: &[glam::Vec3], b: &[glam::Vec3]) -> f32 {
    (a.iter().zip(b))
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f32::max)
}

/// `scene` on the CPU and on the GPU (the software adapter): `frames` frames, then every
/// particle pushed sideways at 0.5 m/s (an outside change), then one frame more; how far
/// apart the two cloths end, metres.
#[allow(dead_code)] // Not every GPU test file pushes.
pub fn apart_after_a_push(scene: clothsim::scene::Scene, frames: usize) -> f32 {
    let mut cpu = clothsim::scene::Simulation::new(scene.clone());
    let (mut gpu, _) = gpu_simulation(scene, true).expect("GPU backend");
    for sim in [&mut cpu, &mut gpu] {
        for _ in 0..frames {
            sim.step_frame().expect("frame");
        }
        sim.sync_state().expect("read back");
        sim.modify_state(|s| s.vel.iter_mut().for_each(|v| v.z += 0.5));
        sim.step_frame().expect("frame");
    }
    farthest(&cpu.state().pos, &gpu.state().pos)
}

/// Two `quads` × `quads` cloths of 0.5 m, one 1.05 thickness (10 mm) above the other, the
/// lower pinned, under semi-implicit Euler at 16 substeps; gravity tilted by `degrees` from
/// the normal (an incline); friction `mu` between them.
#[allow(dead_code)] // Not every test file has one.
pub fn incline(degrees: f32, mu: f32, quads: u32) -> clothsim::scene::Scene {
    let thickness = 0.01;
    let text = format!(
        "name = \"incline\"\n[cloth]\ngrid = {{ quads = {quads}, size = 0.5, layers = 2, spacing = {} }}\n\
         [solver]\nintegrator = \"semi-implicit-euler\"\nsubsteps = 16\n\
         [material]\nstiffness = {{ structural = 400.0, shear = 150.0, bend = 20.0 }}\n\
         [pins]\nregion = {{ min = [-1.0, -1.0, -1.0], max = [1.0, 0.001, 1.0] }}\n\
         [[effects]]\ntype = \"gravity\"\nacceleration = [0.0, {}, {}]\n\
         [[effects]]\ntype = \"self-collision\"\nthickness = {thickness}\nfriction = {mu}\n",
        1.05 * thickness,
        -9.81 * degrees.to_radians().cos(),
        9.81 * degrees.to_radians().sin(),
    );
    let path = std::path::Path::new("incline.toml");
    let file = clothsim::scene::SceneFile::parse(&text, path).expect("parses");
    clothsim::scene::Scene::from_file(file, None).expect("loads")
}

/// The upper cloth's mean velocity along the slope (+z) of an [`incline`].
#[allow(dead_code)]
pub fn slope_speed(sim: &clothsim::scene::Simulation) -> f32 {
    let n = sim.model().particle_count() / 2;
    sim.state().vel[n..].iter().map(|v| v.z).sum::<f32>() / n as f32
}

/// How the upper cloth of [`incline`]`(degrees, mu, …)`, stepped by `sim`, accelerates
/// along the slope from `settle` seconds on over `over` seconds (m/s²), against Coulomb's
/// g (sin θ − μ cos θ).
#[allow(dead_code)]
pub fn slope_acceleration(
    sim: &mut clothsim::scene::Simulation,
    (degrees, mu): (f32, f32),
    (settle, over): (f64, f64),
) -> (f32, f32) {
    sim.run(settle);
    sim.sync_state().expect("read back");
    let (t0, v0) = (sim.state().time, slope_speed(sim));
    sim.run(over);
    sim.sync_state().expect("read back");
    let a = (slope_speed(sim) - v0) / (sim.state().time - t0) as f32;
    let th = degrees.to_radians();
    (a, 9.81 * (th.sin() - mu * th.cos()))
}

/// Three stacked 4 × 4 squares of 20 cm, 3 cm apart, with gravity and self-collision: the
/// lowest free but for a corner, its springs `stiffness` N/m (symplectic Euler at the
/// scene's 4 substeps blows up as it sags from 400 on), the middle one pinned, the top one
/// a handle that jumps 4.5 cm down through the middle one and back up, once a frame. Each
/// jump takes 0.1 ms from 0.2 ms into its frame, inside the frame's first substep at any
/// count the guard tries (up to 32), so it forces the same pairs of the two prescribed
/// squares however the frame is stepped, and before a blow-up stops a try; the free square
/// swings down, clear of them.
#[allow(dead_code)]
pub fn driven_through(integrator: &str, stiffness: f32) -> clothsim::scene::Scene {
    let keyframes: Vec<String> = (0..12)
        .flat_map(|frame| {
            let t = frame as f32 / 60.0 + 2e-4;
            let [from, to] = if frame % 2 == 0 {
                [0.0, -0.045]
            } else {
                [-0.045, 0.0]
            };
            [(t, from), (t + 1e-4, to)]
        })
        .map(|(t, y)| format!("{{ time = {t}, translate = [0.0, {y}, 0.0] }}"))
        .collect();
    let toml = format!(
        r#"
name = "driven"
[cloth]
grid = {{ quads = 4, size = 0.2, layers = 3, spacing = 0.03 }}
orientation = "horizontal"
center = [0.0, 1.0, 0.0]
[solver]
integrator = "{integrator}"
dt = 0.016666668
substeps = 4
[material]
stiffness = {{ structural = {stiffness}, shear = {stiffness}, bend = {stiffness} }}
[pins]
region = {{ min = [-1.0, 0.99, -1.0], max = [1.0, 1.01, 1.0] }}
indices = [0]
[[effects]]
type = "gravity"
[[effects]]
type = "self-collision"
thickness = 0.005
[[handles]]
region = {{ min = [-1.0, 1.02, -1.0], max = [1.0, 1.04, 1.0] }}
keyframes = [ {} ]
"#,
        keyframes.join(", ")
    );
    let path = std::path::Path::new("driven.toml");
    let file = clothsim::scene::SceneFile::parse(&toml, path).unwrap_or_else(|e| panic!("{e}"));
    clothsim::scene::Scene::from_file(file, None).unwrap_or_else(|e| panic!("{e}"))
}

/// [`driven_through`] under implicit Euler at 2 000 N/m, the guard with one refinement and
/// no fallback.
#[allow(dead_code)]
pub fn driven_to_give_up() -> clothsim::scene::Scene {
    let mut scene = driven_through("implicit-euler", 2000.0);
    scene.params.guard = clothsim::sim::GuardPolicy {
        max_refinements: 1,
        fallback: None,
        ..Default::default()
    };
    scene
}

/// Steps `sim` (of [`driven_to_give_up`], on either backend) two frames, then under
/// symplectic Euler, which blows up: the frame given up leaves the count of forced pairs
/// where the frame found it.
#[allow(dead_code)]
pub fn a_frame_given_up_keeps_its_count(mut sim: clothsim::scene::Simulation) {
    use clothsim::sim::{GuardAction, IntegratorKind};
    let forced = |sim: &clothsim::scene::Simulation| sim.forced_pairs().expect("self-collision");
    for _ in 0..2 {
        sim.step_frame().expect("implicit Euler holds");
    }
    let mut params = sim.params().clone();
    params.step.integrator = IntegratorKind::SemiImplicitEuler;
    sim.set_params(params).expect("symplectic Euler runs");
    let mut before = forced(&sim);
    for _ in 0..8 {
        before = forced(&sim);
        if sim.step_frame().is_err() {
            break;
        }
    }
    let events = sim.take_guard_events();
    assert_eq!(events.last().map(|e| &e.action), Some(&GuardAction::GaveUp));
    assert!(before > 0, "the jumps forced pairs before");
    assert_eq!(forced(&sim), before);
}

/// The sphere's radius in [`wedge`], m; it rests on the ground with its centre this high.
#[allow(dead_code)]
pub const WEDGE_RADIUS: f32 = 0.3;

/// A small cloth (4 × 4 quads, 6 cm) lying 1.5 cm above the ground beside a sphere that
/// rests on it, 13 cm from where they touch, set moving at 3 m/s towards that point and a
/// little down (implicit Euler, 8 substeps, no friction); `own` is added to its effects.
#[allow(dead_code)]
pub fn wedge(own: &str) -> clothsim::scene::Scene {
    let r = WEDGE_RADIUS;
    let mut scene = parsed(&format!(
        "name = \"wedge\"\n\
         [cloth]\ngrid = {{ quads = 4, size = 0.06 }}\norientation = \"horizontal\"\n\
         center = [0.16, 0.015, 0.0]\n\
         [solver]\nintegrator = \"implicit-euler\"\nsubsteps = 8\n\
         [[effects]]\ntype = \"sphere\"\ncenter = [0.0, {r}, 0.0]\nradius = {r}\nfriction = 0.0\n\
         [[effects]]\ntype = \"plane\"\nfriction = 0.0\n{own}"
    ));
    (scene.initial.vel.iter_mut()).for_each(|v| *v = glam::Vec3::new(-3.0, -0.3, 0.0));
    scene
}
