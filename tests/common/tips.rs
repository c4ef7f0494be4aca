//! Obstacles whose tips or gentle curves reach up into a coarse cloth's triangles, where
//! every particle and edge of it keeps clear of the faces and the sharp edges (the CPU's
//! tests and the GPU's drop cloth on them alike).
#![allow(dead_code)] // Not every test file drops cloth on tips.

use std::path::Path;

use glam::Vec3;

use clothsim::scene::{Scene, Simulation};

/// Writes an OBJ of `vertices` and triangles (0-based) to `path`.
pub fn write_obj(path: &Path, vertices: &[Vec3], triangles: &[[u32; 3]]) {
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
pub fn scene_in(dir: &Path, toml: &str) -> Scene {
    let path = dir.join("scene.toml");
    std::fs::write(&path, toml).unwrap();
    Scene::open(&path.display().to_string()).unwrap_or_else(|e| panic!("{e}"))
}

/// A scene of a coarse cloth (1 m square of `quads` × `quads` quads, 6: 17 cm, far wider
/// than the obstacle's tip) dropped under `integrator` onto the obstacle `obstacle` (a TOML
/// effect), with the ground and self-collision (whose guarantee covers the cloth's
/// surface, not only its particles).
pub fn coarse_drop(dir: &Path, obstacle: &str, integrator: &str, quads: u32) -> Scene {
    coarse_drop_at(dir, obstacle, integrator, quads, [0.03, 0.02])
}

/// As [`coarse_drop`], the cloth's centre over `[x, z]`.
pub fn coarse_drop_at(
    dir: &Path,
    obstacle: &str,
    integrator: &str,
    quads: u32,
    [x, z]: [f32; 2],
) -> Scene {
    scene_in(
        dir,
        &format!(
            "name = \"tip\"\n[cloth]\ngrid = {{ quads = {quads}, size = 1.0 }}\n\
             orientation = \"horizontal\"\ncenter = [{x}, 0.8, {z}]\n\
             [solver]\nintegrator = \"{integrator}\"\nsubsteps = 16\n\
             [[effects]]\ntype = \"gravity\"\n{obstacle}\n\
             [[effects]]\ntype = \"plane\"\nfriction = 0.4\n\
             [[effects]]\ntype = \"self-collision\"\nthickness = 0.01\n"
        ),
    )
}

/// An obstacle with a tip that points up.
pub struct Tipped {
    pub name: &'static str,
    /// Its TOML effect.
    pub effect: String,
    /// How high its tip is at the start (m), and how fast it rises (m/s).
    pub tip: f32,
    pub rise: f32,
}

impl Tipped {
    /// How high its tip is `seconds` in (up to two seconds).
    pub fn tip_at(&self, seconds: f32) -> f32 {
        self.tip + self.rise * seconds
    }
}

/// Writes into `dir` a pyramid (its apex 0.5 m up), a 30 cm cube standing on a corner
/// (0.56 m up) and a pyramid whose apex rises from 0.3 to 0.6 m over two seconds (an OBJ
/// sequence: its tips move with the surface), and returns them.
pub fn tipped_obstacles(dir: &Path) -> [Tipped; 3] {
    let pyramid = [
        Vec3::new(-0.2, 0.0, -0.2),
        Vec3::new(0.2, 0.0, -0.2),
        Vec3::new(0.2, 0.0, 0.2),
        Vec3::new(-0.2, 0.0, 0.2),
        Vec3::new(0.0, 0.5, 0.0),
    ];
    let faces = [
        [0, 1, 4],
        [1, 2, 4],
        [2, 3, 4],
        [3, 0, 4],
        [0, 3, 2],
        [0, 2, 1],
    ];
    write_obj(&dir.join("pyramid.obj"), &pyramid, &faces);
    // About its centre, its faces quads as the file gives them.
    let cube = "v -0.15 -0.15 -0.15\nv 0.15 -0.15 -0.15\nv -0.15 0.15 -0.15\n\
                v 0.15 0.15 -0.15\nv -0.15 -0.15 0.15\nv 0.15 -0.15 0.15\n\
                v -0.15 0.15 0.15\nv 0.15 0.15 0.15\n\
                f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4\n";
    std::fs::write(dir.join("cube.obj"), cube).unwrap();
    for (k, height) in [0.3, 0.45, 0.6].into_iter().enumerate() {
        let mut rising = pyramid;
        rising[4].y = height;
        write_obj(&dir.join(format!("rising_{k}.obj")), &rising, &faces);
    }
    let tipped = |name, rest: &str, tip, rise| Tipped {
        name,
        effect: format!("[[effects]]\ntype = \"obstacle\"\n{rest}"),
        tip,
        rise,
    };
    [
        tipped("pyramid", "obj = \"pyramid.obj\"\n", 0.5, 0.0),
        // Its diagonal turned upright: the corner at 0.3 + 0.26 m.
        tipped(
            "cube",
            "obj = \"cube.obj\"\nrotate = { axis = [1.0, 0.0, -1.0], degrees = 54.7356 }\n\
             translate = [0.0, 0.3, 0.0]\n",
            0.3 + 0.15 * 3f32.sqrt(),
            0.0,
        ),
        tipped(
            "rising",
            "frames = \"rising_%d.obj\"\nfps = 1.0\n",
            0.3,
            0.15,
        ),
    ]
}

/// Obstacles whose faces all meet at less than a crease, yet whose surface falls away under
/// a coarse cloth's edge or triangle by more than its thickness, written into `dir`, with
/// where the cloth's centre goes ([`coarse_drop_at`]) and how many quads it has:
///
/// - `rail`: a prism of 72 narrow faces (each turning 5° from the next) along the x axis,
///   30 cm in radius, its top 0.6 m up, under a cloth of 6 quads: a cloth edge across it
///   (a 24 cm diagonal) sinks some 2.5 cm below its particles' offset;
/// - `roof`: a 1.6 m square block 30 cm high whose top rises 4.7° to an apex 6.6 cm
///   higher in the middle, under a cloth of 4 quads whose centre is placed so that the
///   apex lies inside a triangle (its circumradius 18 cm), which it rises 1.5 cm into;
/// - `rising roof`: the same as an OBJ sequence whose frame 0 is flat, the apex rising to
///   its height over the first second (under the cloth, which lands at 0.3 s).
pub fn gentle_obstacles(dir: &Path) -> [(Tipped, u32, [f32; 2]); 3] {
    write_prism(&dir.join("rail.obj"), 72, 0.3, 0.3);
    let apex = ROOF_BASE + ROOF_HALF * 4.7f32.to_radians().tan();
    write_obj(&dir.join("roof.obj"), &roof(apex), &ROOF_FACES);
    // The same roof flat at first, its apex rising over a second: frame 0 has no gentle
    // part at all.
    write_obj(&dir.join("roof_1.obj"), &roof(apex), &ROOF_FACES);
    write_obj(&dir.join("roof_0.obj"), &roof(ROOF_BASE), &ROOF_FACES);
    let obstacle = |name, source: &str, tip| Tipped {
        name,
        effect: format!("[[effects]]\ntype = \"obstacle\"\n{source}\n"),
        tip,
        rise: 0.0,
    };
    [
        (obstacle("rail", "obj = \"rail.obj\"", 0.6), 6, [0.03, 0.02]),
        (
            obstacle("roof", "obj = \"roof.obj\"", apex),
            4,
            [0.083, 0.167],
        ),
        (
            obstacle("rising roof", "frames = \"roof_%d.obj\"\nfps = 1.0", apex),
            4,
            [0.083, 0.167],
        ),
    ]
}

/// Half the width of the roof's block (m), and its height under the roof.
const ROOF_HALF: f32 = 0.8;
const ROOF_BASE: f32 = 0.3;

/// The roof's faces: the block's bottom and sides, then the roof's four, which meet at
/// its apex.
const ROOF_FACES: [[u32; 3]; 14] = [
    [0, 1, 2],
    [0, 2, 3],
    [4, 5, 1],
    [4, 1, 0],
    [5, 6, 2],
    [5, 2, 1],
    [6, 7, 3],
    [6, 3, 2],
    [7, 4, 0],
    [7, 0, 3],
    [4, 8, 5],
    [5, 8, 6],
    [6, 8, 7],
    [7, 8, 4],
];

/// The roof's vertices, its apex `apex` m up over the middle of the block's top.
fn roof(apex: f32) -> Vec<Vec3> {
    let mut roof = Vec::new();
    for y in [0.0, ROOF_BASE] {
        roof.extend(
            [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
                .map(|[x, z]| Vec3::new(ROOF_HALF * x, y, ROOF_HALF * z)),
        );
    }
    roof.push(Vec3::new(0.0, apex, 0.0));
    roof
}

/// The roof's block with a top flat in frame 0 that rises to a steep apex over two seconds
/// (an OBJ sequence of three frames, one a second, written into `dir`: the apex 0.3, 0.45
/// and 0.6 m up), as an obstacle: its four ridges creases and its apex a tip from frame 1
/// (the faces turn 15° across a ridge there, 29° in frame 2), though frame 0 has neither.
pub fn sprouting_roof(dir: &Path) -> Tipped {
    for (k, apex) in [ROOF_BASE, 0.45, 0.6].into_iter().enumerate() {
        write_obj(
            &dir.join(format!("sprouting_{k}.obj")),
            &roof(apex),
            &ROOF_FACES,
        );
    }
    Tipped {
        name: "sprouting roof",
        effect: "[[effects]]\ntype = \"obstacle\"\nframes = \"sprouting_%d.obj\"\nfps = 1.0\n"
            .to_string(),
        tip: ROOF_BASE,
        rise: 0.15,
    }
}

/// Writes to `path` a closed prism of `sides` narrow faces along the x axis, 2 m long, its
/// corners `radius` from the line `y = axis`, `z = 0`.
fn write_prism(path: &Path, sides: u32, radius: f32, axis: f32) {
    let (corners, faces) = clothsim::sim::obstacle::prism(sides, radius);
    let raised: Vec<Vec3> = corners.iter().map(|&c| c + Vec3::Y * axis).collect();
    write_obj(path, &raised, &faces);
}

/// A 20 cm ball of about `triangles` triangles on the ground (its top 0.4 m up), written
/// into `dir` as `ball.obj`.
pub fn ball(dir: &Path, triangles: usize) -> Tipped {
    write_ball(&dir.join("ball.obj"), 0.2, triangles);
    Tipped {
        name: "ball",
        effect: "[[effects]]\ntype = \"obstacle\"\nobj = \"ball.obj\"\n".to_string(),
        tip: 0.4,
        rise: 0.0,
    }
}

/// Steps `sim` `frames` frames, after each of which no cloth triangle meets the obstacle
/// (the exact check), and returns how high the cloth's highest point then is (m), every
/// particle finite; `case` names it in a failure.
pub fn drop_through_nothing(sim: &mut Simulation, frames: usize, case: &str) -> f32 {
    for frame in 0..frames {
        sim.step_frame().unwrap_or_else(|e| panic!("{case}: {e}"));
        let met = sim.intersections().obstacles[0];
        assert_eq!(met, 0, "{case}: frame {frame}");
    }
    let pos = &sim.state().pos;
    assert!(pos.iter().all(|p| p.is_finite()), "{case}");
    pos.iter().map(|p| p.y).fold(f32::MIN, f32::max)
}

/// A ball of radius `radius` and about `triangles` triangles resting on the ground (the
/// benchmark's cube-sphere: a cube's faces cut into even squares pushed out onto it).
pub fn write_ball(path: &Path, radius: f32, triangles: usize) {
    let soup = clothsim::bench_contact::cube_sphere(radius, triangles);
    let up = |p: &Vec3| *p + Vec3::Y * radius;
    let faces: Vec<[u32; 3]> = (soup.face_indices.chunks_exact(3))
        .map(|f| [f[0], f[1], f[2]])
        .collect();
    write_obj(
        path,
        &soup.positions.iter().map(up).collect::<Vec<_>>(),
        &faces,
    );
}
