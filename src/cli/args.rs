//! The command line: the subcommands and the arguments they share.

use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::{Parser, Subcommand};

use clothsim::gpu::{Backend, gpu_simulation};
use clothsim::mesh;
use clothsim::scene::{Scene, Simulation};
use clothsim::sim::{IntegratorKind, Precision};

#[derive(Parser)]
#[command(
    name = "clothsim",
    version,
    about = "Cloth simulator and viewer",
    args_conflicts_with_subcommands = true
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Open the GUI with this OBJ file as the cloth (no subcommand: the GUI).
    pub obj: Option<PathBuf>,
}

#[derive(Subcommand)]
pub enum Command {
    /// Topology of an OBJ cloth: particles, triangles, edges, springs by kind.
    Info {
        file: PathBuf,
        /// Print one JSON object.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        import: ImportArgs,
    },
    /// List the built-in scenes, or check scene files and list what they hold.
    Scenes {
        /// Scene files (.toml) to check; none lists the built-in scenes.
        files: Vec<PathBuf>,
    },
    /// Run a scene headless and print a summary.
    Simulate {
        #[command(flatten)]
        run: RunArgs,
        /// Print one JSON object.
        #[arg(long)]
        json: bool,
        /// Write the cloth as it is at the end as an OBJ file.
        #[arg(long)]
        export_obj: Option<PathBuf>,
        /// Write the cloth, and each obstacle as placed, every K frames (with --out-dir).
        #[arg(long, requires = "out_dir")]
        every: Option<u32>,
        /// Directory for the frames as OBJ files (cloth_00000.obj, obstacle-1_00000.obj, …,
        /// numbered as `render --every` numbers its PNGs); must exist.
        #[arg(long)]
        out_dir: Option<PathBuf>,
        /// After every frame, count the triangle pairs that intersect (the cloth's own, and
        /// the cloth's against each solid) and report the largest counts.
        #[arg(long)]
        check_intersections: bool,
    },
    /// Render the state after --seconds to a PNG, or every K frames to a numbered sequence.
    Render {
        #[command(flatten)]
        run: RunArgs,
        /// Image size WIDTHxHEIGHT in pixels.
        #[arg(long, default_value = "1280x720")]
        size: String,
        /// Comma-separated overlays: springs, strain, bend, particles, wireframe, no-mesh, no-checker.
        #[arg(long, default_value = "")]
        overlay: String,
        /// Output PNG (single image).
        #[arg(long, required_unless_present_any = ["out_dir", "gif"], conflicts_with_all = ["out_dir", "every", "gif"])]
        out: Option<PathBuf>,
        /// Write a frame every K simulation frames (with --out-dir or --gif).
        #[arg(long)]
        every: Option<u32>,
        /// Directory for the frame sequence (frame_00000.png, …); must exist.
        #[arg(long)]
        out_dir: Option<PathBuf>,
        /// An animated GIF of the run (every K-th frame with --every).
        #[arg(long)]
        gif: Option<PathBuf>,
    },
    /// What accuracy costs in time: every integrator × step size against a reference;
    /// writes accuracy.csv, accuracy.md and accuracy.png.
    Accuracy {
        /// A built-in scene (see `clothsim scenes`) or a scene file (.toml); `orders`, where
        /// every method's order of accuracy shows, unless told another.
        #[arg(long, default_value = clothsim::report::ORDERS_SCENE)]
        scene: String,
        /// Use this OBJ cloth instead of the scene's own.
        #[arg(long)]
        obj: Option<PathBuf>,
        /// Comma-separated integrators (default: all eight).
        #[arg(long, value_delimiter = ',')]
        integrators: Option<Vec<IntegratorKind>>,
        /// Comma-separated step sizes in seconds (default: on `orders` 1/60 s over 1, √2, 2,
        /// 2√2, 4, 8, … 1 024 substeps; on any other scene over 3, 6, … 384).
        #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
        dts: Option<Vec<f64>>,
        /// Simulated seconds of each run (default: 1 on `orders`, 0.25 on any other scene).
        #[arg(long, allow_negative_numbers = true)]
        seconds: Option<f64>,
        /// Largest acceptable max position error, as a fraction of the cloth's size.
        #[arg(long, default_value_t = clothsim::report::DEFAULT_TOLERANCE, allow_negative_numbers = true)]
        tolerance: f64,
        /// What every run of the sweep and its reference computes in: f64 (rounding far below
        /// the errors measured) or f32 (to see where f32's rounding floors the errors).
        #[arg(long, default_value_t = Precision::F64)]
        precision: Precision,
        /// Output directory (created if missing).
        #[arg(long, required_unless_present = "calibrate")]
        out: Option<PathBuf>,
        /// Instead: measure on this machine what each kind of work costs on the scene (the
        /// unit costs the choice weighs counted work by) and print them beside the built-in
        /// ones the report uses.
        #[arg(long)]
        calibrate: bool,
        /// Also: each integrator's largest stable step against the springs' stiffness, a
        /// tenth to a hundred times the scene's (stability-map.csv, .md, .png).
        #[arg(long)]
        map: bool,
        /// Also: XPBD and VBD over substeps × sweeps per substep, and n substeps of one
        /// sweep against one substep of n sweeps (small-steps.csv, .md).
        #[arg(long)]
        small_steps: bool,
    },
    /// Speed on the `hanging-bench` scene: µs per substep and the sag after 2 s for each
    /// size × integrator × thread count (the scene the peer frameworks run too). µs per
    /// substep over the whole run, in its median frame and in its fastest frame.
    Bench {
        /// Comma-separated particles per side.
        #[arg(long, value_delimiter = ',', default_value = "32,64,128,256")]
        sizes: Vec<u32>,
        /// Comma-separated integrators [default: semi-implicit-euler,implicit-euler,xpbd,vbd].
        #[arg(long, value_delimiter = ',')]
        integrators: Option<Vec<IntegratorKind>>,
        /// Comma-separated thread counts.
        #[arg(long, value_delimiter = ',', default_value = "1,2")]
        threads: Vec<usize>,
        /// Print one JSON object per row.
        #[arg(long)]
        json: bool,
        /// cpu, or gpu (wgpu compute: semi-implicit and implicit Euler, XPBD, VBD; --threads
        /// does not apply).
        #[arg(long, value_enum, default_value_t = Backend::Cpu)]
        backend: Backend,
        /// What the CPU computes in: f32 or f64 (the GPU refuses f64).
        #[arg(long, default_value_t = Precision::F32)]
        precision: Precision,
        /// Simulated seconds of each row (the sag is held against its reference only at
        /// 2, the time the reference is for).
        #[arg(long, default_value_t = clothsim::bench::BENCH_SECONDS, allow_negative_numbers = true)]
        seconds: f64,
        /// Instead: a 64 × 64 cloth resting on a mesh sphere of about 1 000 and 100 000
        /// triangles, the obstacle phase against the springs' (per --threads).
        #[arg(long, conflicts_with_all = ["sizes", "integrators", "backend", "seconds"])]
        obstacles: bool,
        /// Instead: the `crumple` scene's first simulated second at --quads (its own
        /// integrator, or each of --integrators), the contact phases per substep
        /// against the springs', self-contact's alone, and the pairs per particle (per
        /// --threads).
        #[arg(long, conflicts_with_all = ["sizes", "backend", "obstacles", "seconds"])]
        crumple: bool,
        /// Comma-separated grid sizes (quads a side) for --crumple.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "64",
            requires = "crumple"
        )]
        quads: Vec<u32>,
        /// Runs of each --crumple row, taken in turn across the thread counts; the row
        /// prints each time's median (a shared machine's load swings one run's).
        #[arg(long, default_value_t = 3, requires = "crumple")]
        repeat: u32,
    },
    /// Write a rectangular grid cloth as an OBJ file (quads: diagonals become shear springs).
    Grid {
        /// Quads along each side.
        #[arg(long, default_value_t = 24)]
        quads: u32,
        /// Side length, metres.
        #[arg(long, default_value_t = 1.0)]
        size: f32,
        /// Write triangles instead of quads.
        #[arg(long)]
        triangles: bool,
        #[arg(long)]
        out: PathBuf,
    },
}

/// How an OBJ cloth is imported.
#[derive(clap::Args)]
pub struct ImportArgs {
    /// Weld corners closer than this fraction of the cloth's size (0: only identical ones).
    #[arg(long, default_value_t = mesh::ImportOptions::default().weld_tolerance, allow_negative_numbers = true)]
    pub weld_tolerance: f32,
}

impl ImportArgs {
    /// The import options, checked.
    pub fn options(&self) -> Result<mesh::ImportOptions> {
        if !(self.weld_tolerance.is_finite() && (0.0..0.1).contains(&self.weld_tolerance)) {
            bail!(
                "--weld-tolerance must be a fraction of the cloth's size in 0..0.1, got {}",
                self.weld_tolerance
            );
        }
        Ok(mesh::ImportOptions {
            weld_tolerance: self.weld_tolerance,
        })
    }
}

/// What every simulating subcommand takes.
#[derive(clap::Args)]
pub struct RunArgs {
    /// A built-in scene (see `clothsim scenes`) or a scene file (.toml).
    #[arg(long, default_value = "hanging")]
    pub scene: String,
    /// Use this OBJ cloth instead of the scene's own.
    #[arg(long)]
    pub obj: Option<PathBuf>,
    /// Integrator: explicit-euler, semi-implicit-euler, verlet, rk2, rk4, implicit-euler, xpbd,
    /// vbd.
    #[arg(long)]
    pub integrator: Option<IntegratorKind>,
    /// Simulated seconds.
    #[arg(long, default_value_t = 3.0, allow_negative_numbers = true)]
    pub seconds: f64,
    /// Frame time step, seconds.
    #[arg(long, allow_negative_numbers = true)]
    pub dt: Option<f32>,
    /// Substeps per frame.
    #[arg(long)]
    pub substeps: Option<u32>,
    /// What the state, forces and integrators compute in: f32 (the scene file's unless it
    /// says otherwise) or f64 (the CPU backend only; about twice the time).
    #[arg(long)]
    pub precision: Option<Precision>,
    /// Sweeps per substep of XPBD (constraint projections) and VBD (descent sweeps).
    #[arg(long)]
    pub iterations: Option<u32>,
    /// Resize the scene's grid cloth to N quads along its longer side (its self-collision
    /// thickness shrinks with the spacing).
    #[arg(long)]
    pub quads: Option<u32>,
    /// What steps the cloth: cpu (every integrator and effect) or gpu (wgpu compute:
    /// semi-implicit and implicit Euler, XPBD and VBD; springs, gravity, air damping, wind, dihedral
    /// bending, pins, handles, spheres, planes; mesh obstacles, rigid or OBJ sequences;
    /// self-collision).
    #[arg(long, value_enum, default_value_t = Backend::Cpu)]
    pub backend: Backend,
    #[command(flatten)]
    pub import: ImportArgs,
}

impl RunArgs {
    /// The simulation the arguments describe, on the backend they ask for.
    pub fn simulation(&self) -> Result<Simulation> {
        let options = self.import.options()?;
        let mut scene =
            Scene::open_resized(&self.scene, self.obj.as_deref(), &options, self.quads)?;
        if let Some(k) = self.integrator {
            scene.params.step.integrator = k;
        }
        if let Some(dt) = self.dt {
            scene.params.step.dt = dt;
        }
        if let Some(s) = self.substeps {
            scene.params.step.substeps = s;
        }
        if let Some(p) = self.precision {
            scene.params.solver.precision = p;
        }
        if let Some(n) = self.iterations {
            if !(1..=10_000).contains(&n) {
                bail!("--iterations must be in 1..=10000, got {n}");
            }
            scene.params.solver.xpbd_iterations = n;
            scene.params.solver.vbd_iterations = n;
        }
        scene.params.validate().map_err(anyhow::Error::msg)?;
        if !(self.seconds.is_finite() && self.seconds >= 0.0) {
            bail!(
                "--seconds must be a finite number ≥ 0, got {}",
                self.seconds
            );
        }
        // The import's warnings before anything can fail, then those the simulation adds
        // about the start (a cloth that meets itself or a solid), which follow them in its
        // list.
        let imported = scene.warnings.len();
        for w in &scene.warnings {
            eprintln!("warning: {}: {w}", scene.cloth_name);
        }
        let sim = match self.backend {
            Backend::Cpu => Simulation::new(scene),
            Backend::Gpu => {
                let (sim, adapter) = gpu_simulation(scene, true)?;
                eprintln!("note: stepping on the GPU: {adapter}");
                sim
            }
        };
        for w in sim.warnings().iter().skip(imported) {
            eprintln!("warning: {}: {w}", sim.cloth_name());
        }
        Ok(sim)
    }
}
