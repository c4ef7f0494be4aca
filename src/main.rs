//! The `clothsim` command: the GUI by default, plus headless subcommands.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};

use clothsim::mesh::{self, GridOrientation, GridSpec, SpringKind};
use clothsim::scene::{SCENARIOS, Scene, Simulation};
use clothsim::sim::IntegratorKind;
use clothsim::view;

#[derive(Parser)]
#[command(
    name = "clothsim",
    version,
    about = "Cloth simulator and viewer",
    args_conflicts_with_subcommands = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Open the GUI with this OBJ file as the cloth (no subcommand: the GUI).
    obj: Option<PathBuf>,
}

#[derive(Subcommand)]
enum Command {
    /// Topology of an OBJ cloth: particles, triangles, edges, springs by kind.
    Info {
        file: PathBuf,
        /// Print one JSON object.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        import: ImportArgs,
    },
    /// List the built-in scenarios.
    Scenes,
    /// Run a scenario headless and print a summary.
    Simulate {
        #[command(flatten)]
        run: RunArgs,
        /// Print one JSON object.
        #[arg(long)]
        json: bool,
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
        #[arg(long, required_unless_present = "out_dir", conflicts_with_all = ["out_dir", "every"])]
        out: Option<PathBuf>,
        /// Write a frame every K simulation frames (with --out-dir).
        #[arg(long, requires = "out_dir")]
        every: Option<u32>,
        /// Directory for the frame sequence (frame_00000.png, …); must exist.
        #[arg(long)]
        out_dir: Option<PathBuf>,
    },
    /// What accuracy costs in time: every integrator × step size against a reference;
    /// writes accuracy.csv, accuracy.md and accuracy.png.
    Accuracy {
        /// Scenario name (see `clothsim scenes`).
        #[arg(long, default_value = "hanging")]
        scene: String,
        /// Use this OBJ cloth instead of the scenario's default.
        #[arg(long)]
        obj: Option<PathBuf>,
        /// Comma-separated integrators (default: all seven).
        #[arg(long, value_delimiter = ',')]
        integrators: Option<Vec<IntegratorKind>>,
        /// Comma-separated step sizes in seconds (default: 1/60 s over 3, 6, … 384 substeps).
        #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
        dts: Option<Vec<f64>>,
        /// Simulated seconds of each run.
        #[arg(long, default_value_t = 0.25, allow_negative_numbers = true)]
        seconds: f64,
        /// Largest acceptable max position error, as a fraction of the cloth's size.
        #[arg(long, default_value_t = clothsim::report::DEFAULT_TOLERANCE, allow_negative_numbers = true)]
        tolerance: f64,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
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
struct ImportArgs {
    /// Weld corners closer than this fraction of the cloth's size (0: only identical ones).
    #[arg(long, default_value_t = mesh::ImportOptions::default().weld_tolerance, allow_negative_numbers = true)]
    weld_tolerance: f32,
}

impl ImportArgs {
    fn options(&self) -> Result<mesh::ImportOptions> {
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
struct RunArgs {
    /// Scenario name (see `clothsim scenes`).
    #[arg(long, default_value = "hanging")]
    scene: String,
    /// Use this OBJ cloth instead of the scenario's default.
    #[arg(long)]
    obj: Option<PathBuf>,
    /// Integrator: explicit-euler, semi-implicit-euler, verlet, rk2, rk4, implicit-euler, xpbd.
    #[arg(long)]
    integrator: Option<IntegratorKind>,
    /// Simulated seconds.
    #[arg(long, default_value_t = 3.0, allow_negative_numbers = true)]
    seconds: f64,
    /// Frame time step, seconds.
    #[arg(long, allow_negative_numbers = true)]
    dt: Option<f32>,
    /// Substeps per frame.
    #[arg(long)]
    substeps: Option<u32>,
    #[command(flatten)]
    import: ImportArgs,
}

impl RunArgs {
    fn simulation(&self) -> Result<Simulation> {
        let mut scene = match &self.obj {
            Some(path) => Scene::with_obj_options(&self.scene, path, &self.import.options()?)?,
            None => Scene::builtin(&self.scene)?,
        };
        if let Some(k) = self.integrator {
            scene.params.integrator = k;
        }
        if let Some(dt) = self.dt {
            scene.params.dt = dt;
        }
        if let Some(s) = self.substeps {
            scene.params.substeps = s;
        }
        scene.params.validate().map_err(anyhow::Error::msg)?;
        if !(self.seconds.is_finite() && self.seconds >= 0.0) {
            bail!(
                "--seconds must be a finite number ≥ 0, got {}",
                self.seconds
            );
        }
        for w in &scene.warnings {
            eprintln!("warning: {}: {w}", scene.cloth_name);
        }
        Ok(Simulation::new(scene))
    }
}

fn main() {
    env_logger::Builder::from_env(
        env_logger::Env::default().default_filter_or("warn,wgpu_hal=off"),
    )
    .init();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => e.exit(), // --help, --version
        Err(e) => {
            // One line, like every other error: clap's first line names the argument.
            let text = e.render().to_string();
            eprintln!("{}", text.lines().next().unwrap_or("error: bad arguments"));
            std::process::exit(2);
        }
    };
    if let Err(e) = run(cli) {
        // `{:#}` joins the causes on one line; a message spanning lines is folded.
        eprintln!("error: {}", format!("{e:#}").replace('\n', " "));
        std::process::exit(1);
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        None => clothsim::app::run(cli.obj).map_err(|e| {
            anyhow::anyhow!(
                "cannot open the window: {e}. Headless use: `clothsim --help` lists the subcommands"
            )
        }),
        Some(Command::Info { file, json, import }) => info(&file, json, &import.options()?),
        Some(Command::Scenes) => {
            for s in SCENARIOS {
                println!("{:<16} {}", s.name, s.summary);
            }
            Ok(())
        }
        Some(Command::Simulate { run, json }) => simulate(&run, json),
        Some(Command::Render {
            run,
            size,
            overlay,
            out,
            every,
            out_dir,
        }) => render(
            &run,
            &size,
            &overlay,
            out.as_deref(),
            every,
            out_dir.as_deref(),
        ),
        Some(Command::Accuracy {
            scene,
            obj,
            integrators,
            dts,
            seconds,
            tolerance,
            out,
        }) => {
            let mut config = clothsim::report::SweepConfig {
                seconds,
                tolerance,
                ..Default::default()
            };
            if let Some(list) = integrators {
                config.integrators = list;
            }
            if let Some(list) = dts {
                config.dts = list;
            }
            accuracy(&scene, obj.as_deref(), &config, &out)
        }
        Some(Command::Grid {
            quads,
            size,
            triangles,
            out,
        }) => grid(quads, size, triangles, &out),
    }
}

fn info(file: &std::path::Path, json: bool, options: &mesh::ImportOptions) -> Result<()> {
    let build = mesh::load_obj_with(file, options)?;
    let m = &build.mesh;
    let [structural, shear, bend] = SpringKind::ALL.map(|k| m.spring_count(k));
    if json {
        let v = serde_json::json!({
            "file": file.display().to_string(),
            "particles": m.positions.len(),
            "triangles": m.triangles.len(),
            "edges": m.edges.len(),
            "springs": structural + shear + bend,
            "structural": structural,
            "shear": shear,
            "bend": bend,
            "warnings": build.warnings,
        });
        println!("{v}");
    } else {
        for w in &build.warnings {
            eprintln!("warning: {}: {w}", file.display());
        }
        println!("{}", file.display());
        println!("  particles   {}", m.positions.len());
        println!("  triangles   {}", m.triangles.len());
        println!("  edges       {}", m.edges.len());
        println!(
            "  springs     {} (structural {structural}, shear {shear}, bend {bend})",
            structural + shear + bend
        );
    }
    Ok(())
}

fn simulate(args: &RunArgs, json: bool) -> Result<()> {
    let mut sim = args.simulation()?;
    let summary = sim.run(args.seconds);
    if json {
        println!("{}", serde_json::to_string(&summary)?);
    } else {
        println!(
            "scene {} with {} ({})",
            summary.scene, summary.cloth, summary.integrator
        );
        println!(
            "  {} particles, {} springs ({} structural, {} shear, {} bend)",
            summary.particles, summary.springs, summary.structural, summary.shear, summary.bend
        );
        println!(
            "  simulated {:.3} s in {} frames of {:.5} s × {} substeps (requested {}), wall {:.3} s",
            summary.simulated_seconds,
            summary.frames,
            summary.dt,
            summary.substeps,
            summary.requested_substeps,
            summary.wall_seconds
        );
        println!(
            "  finite {}, max speed {:.4} m/s, kinetic energy {:.6} J",
            summary.finite, summary.max_speed, summary.kinetic_energy
        );
        match summary.min_collider_distance {
            Some(d) => println!("  closest particle to a collider surface: {d:.5} m"),
            None => println!("  no colliders"),
        }
        for event in &summary.guard_events {
            println!("  stability guard: {event}");
        }
    }
    if let Some(e) = summary.error {
        bail!(e);
    }
    Ok(())
}

fn accuracy(
    scene: &str,
    obj: Option<&std::path::Path>,
    config: &clothsim::report::SweepConfig,
    out: &std::path::Path,
) -> Result<()> {
    config.validate()?;
    let scene = match obj {
        Some(path) => Scene::with_obj(scene, path)?,
        None => Scene::builtin(scene)?,
    };
    // Fail on an unusable output directory before a minute of work, not after it.
    std::fs::create_dir_all(out)
        .with_context(|| format!("{}: cannot create the output directory", out.display()))?;
    let bar = indicatif::ProgressBar::new(1);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} {msg} [{elapsed}]")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let report = clothsim::report::sweep(&scene, config, &mut |p| {
        bar.set_length(p.total as u64);
        bar.set_position(p.done as u64);
        bar.set_message(p.what.clone());
        true
    })?;
    bar.finish_and_clear();
    let files = clothsim::report::write_report(&report, out)?;
    println!(
        "for a tolerance of {} of the cloth's size: {}",
        config.tolerance,
        clothsim::report::choice_sentence(&report)
    );
    for f in files {
        println!("wrote {}", f.display());
    }
    Ok(())
}

fn grid(quads: u32, size: f32, triangles: bool, out: &std::path::Path) -> Result<()> {
    if quads == 0 || !(size.is_finite() && size > 0.0) {
        bail!("--quads must be ≥ 1 and --size a positive number of metres");
    }
    let mut soup =
        GridSpec::square(quads, size, GridOrientation::Horizontal, glam::Vec3::ZERO).polygons();
    if triangles {
        soup = soup.triangulated();
    }
    std::fs::write(out, mesh::write_obj(&soup))
        .with_context(|| format!("cannot write {}", out.display()))?;
    println!("wrote {}", out.display());
    Ok(())
}

fn parse_size(size: &str) -> Result<(u32, u32)> {
    let parsed = size
        .split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.trim().parse::<u32>().ok()?, h.trim().parse::<u32>().ok()?)));
    match parsed {
        Some((w, h)) if w > 0 && h > 0 => Ok((w, h)),
        _ => bail!("--size must look like 1280x720, got `{size}`"),
    }
}

fn render(
    args: &RunArgs,
    size: &str,
    overlay: &str,
    out: Option<&std::path::Path>,
    every: Option<u32>,
    out_dir: Option<&std::path::Path>,
) -> Result<()> {
    use clothsim::render::{AdapterPreference, Offscreen, RenderOptions, save_png};
    let (width, height) = parse_size(size)?;
    let options = RenderOptions::default()
        .with_overlays(overlay)
        .map_err(anyhow::Error::msg)?;
    if let Some(dir) = out_dir
        && !dir.is_dir()
    {
        bail!("--out-dir {}: not an existing directory", dir.display());
    }
    // Fail before a long simulation, not after it.
    if let Some(path) = out
        && let Some(parent) = path.parent()
        && !parent.as_os_str().is_empty()
        && !parent.is_dir()
    {
        bail!(
            "{}: the directory {} does not exist",
            path.display(),
            parent.display()
        );
    }
    let mut sim = args.simulation()?;
    let camera = view::default_camera(&sim, width as f32 / height as f32);
    let mut offscreen = Offscreen::new(width, height, AdapterPreference::Any)?;
    let frames = (args.seconds / sim.params().dt as f64).round() as u64;
    match (out, out_dir) {
        (Some(path), _) => {
            for _ in 0..frames {
                sim.step_frame()?;
            }
            let image = offscreen.render(&view::frame(&sim), &camera, &options)?;
            save_png(&image, path)?;
            println!(
                "wrote {} ({}x{}, t = {:.3} s)",
                path.display(),
                width,
                height,
                sim.state().time
            );
        }
        (None, Some(dir)) => {
            let every = every.unwrap_or(1).max(1) as u64;
            let bar = indicatif::ProgressBar::new(frames / every + 1);
            bar.set_style(
                indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} frames {msg}")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            let mut written = 0u64;
            for f in 0..=frames {
                if f > 0 {
                    sim.step_frame()?;
                }
                if f % every == 0 {
                    let image = offscreen.render(&view::frame(&sim), &camera, &options)?;
                    save_png(&image, &dir.join(format!("frame_{written:05}.png")))?;
                    written += 1;
                    bar.inc(1);
                }
            }
            bar.finish_with_message(format!("written to {}", dir.display()));
        }
        (None, None) => bail!("give --out FILE.png or --out-dir DIR"),
    }
    Ok(())
}
