//! The `clothsim` command: the GUI by default, plus headless subcommands.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};

use clothsim::gpu::{Backend, GPU_INTEGRATOR, gpu_simulation};
use clothsim::mesh::{self, GridOrientation, GridSpec, SpringKind};
use clothsim::scene::{Scene, Simulation};
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
        /// A built-in scene (see `clothsim scenes`) or a scene file (.toml).
        #[arg(long, default_value = "hanging")]
        scene: String,
        /// Use this OBJ cloth instead of the scene's own.
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
    /// Speed on the `hanging-bench` scene: µs per substep and the sag after 2 s for each
    /// size × integrator × thread count (the scene the peer frameworks run too). µs per
    /// substep over the whole run, in its median frame and in its fastest frame.
    Bench {
        /// Comma-separated particles per side.
        #[arg(long, value_delimiter = ',', default_value = "32,64,128,256")]
        sizes: Vec<u32>,
        /// Comma-separated integrators [default: semi-implicit-euler,implicit-euler,xpbd;
        /// with --backend gpu, semi-implicit-euler, the one it runs].
        #[arg(long, value_delimiter = ',')]
        integrators: Option<Vec<IntegratorKind>>,
        /// Comma-separated thread counts.
        #[arg(long, value_delimiter = ',', default_value = "1,2")]
        threads: Vec<usize>,
        /// Print one JSON object per row.
        #[arg(long)]
        json: bool,
        /// cpu, or gpu (semi-implicit Euler on wgpu compute; --threads does not apply).
        #[arg(long, value_enum, default_value_t = Backend::Cpu)]
        backend: Backend,
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
    /// A built-in scene (see `clothsim scenes`) or a scene file (.toml).
    #[arg(long, default_value = "hanging")]
    scene: String,
    /// Use this OBJ cloth instead of the scene's own.
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
    /// What steps the cloth: cpu (every integrator and effect) or gpu (wgpu compute:
    /// semi-implicit Euler, springs, gravity, air damping, pins, spheres, planes).
    #[arg(long, value_enum, default_value_t = Backend::Cpu)]
    backend: Backend,
    #[command(flatten)]
    import: ImportArgs,
}

impl RunArgs {
    fn simulation(&self) -> Result<Simulation> {
        let mut scene =
            Scene::open_with_obj(&self.scene, self.obj.as_deref(), &self.import.options()?)?;
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
        match self.backend {
            Backend::Cpu => Ok(Simulation::new(scene)),
            Backend::Gpu => {
                let (sim, adapter) = gpu_simulation(scene, true)?;
                eprintln!("note: stepping on the GPU: {adapter}");
                Ok(sim)
            }
        }
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
        Some(Command::Scenes { files }) => scenes(&files),
        Some(Command::Simulate {
            run,
            json,
            export_obj,
        }) => simulate(&run, json, export_obj.as_deref()),
        Some(Command::Render {
            run,
            size,
            overlay,
            out,
            every,
            out_dir,
            gif,
        }) => render(
            &run,
            &size,
            &overlay,
            Output {
                png: out.as_deref(),
                every,
                dir: out_dir.as_deref(),
                gif: gif.as_deref(),
            },
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
        Some(Command::Bench {
            sizes,
            integrators,
            threads,
            json,
            backend,
        }) => {
            let integrators = integrators.unwrap_or_else(|| match backend {
                Backend::Cpu => clothsim::bench::BENCH_INTEGRATORS.to_vec(),
                Backend::Gpu => vec![GPU_INTEGRATOR],
            });
            bench(&sizes, &integrators, &threads, json, backend)
        }
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

/// The effects of a scene file, in words.
fn describe(file: &clothsim::scene::SceneFile) -> String {
    let effects: Vec<&str> = file.effects().iter().map(|e| e.phase()).collect();
    format!("{} [{}]", file.summary, effects.join(", "))
}

fn scenes(files: &[PathBuf]) -> Result<()> {
    if files.is_empty() {
        for s in clothsim::scene::scenarios() {
            println!("{:<16} {}", s.name, describe(s));
        }
        return Ok(());
    }
    for path in files {
        let loaded = clothsim::scene::SceneFile::load(path)?;
        // Building it checks the cloth and the pins too.
        let scene = Scene::from_loaded(&loaded)?;
        println!(
            "{}: {} — {} particles, {}",
            path.display(),
            loaded.file.name,
            scene.model.particle_count(),
            describe(&loaded.file)
        );
    }
    Ok(())
}

fn simulate(args: &RunArgs, json: bool, export: Option<&std::path::Path>) -> Result<()> {
    if let Some(path) = export {
        check_directory(path)?;
    }
    let mut sim = args.simulation()?;
    let summary = sim.run(args.seconds);
    if let Some(path) = export {
        clothsim::output::write_bytes(path, sim.export_obj().as_bytes())?;
        if !json {
            println!("wrote {}", path.display());
        }
    }
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
        if summary.solver_iterations_per_step > 0.0 {
            println!(
                "  linear solver: {:.1} conjugate-gradient iterations per step",
                summary.solver_iterations_per_step
            );
        }
        let phases: Vec<String> = summary
            .phases
            .iter()
            .map(|(name, p)| format!("{name} {:.3} s ({} calls)", p.seconds, p.calls))
            .collect();
        println!("  phases: {}", phases.join(", "));
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
    let scene = Scene::open_with_obj(scene, obj, &mesh::ImportOptions::default())?;
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

/// Where `render` writes.
struct Output<'a> {
    png: Option<&'a std::path::Path>,
    every: Option<u32>,
    dir: Option<&'a std::path::Path>,
    gif: Option<&'a std::path::Path>,
}

/// Fails before a long run, not after it, when a file's directory does not exist.
fn check_directory(path: &std::path::Path) -> Result<()> {
    if let Some(parent) = path.parent()
        && !parent.as_os_str().is_empty()
        && !parent.is_dir()
    {
        bail!(
            "{}: the directory {} does not exist",
            path.display(),
            parent.display()
        );
    }
    Ok(())
}

fn render(args: &RunArgs, size: &str, overlay: &str, output: Output<'_>) -> Result<()> {
    use clothsim::render::{AdapterPreference, GifWriter, Offscreen, RenderOptions, save_png};
    let (width, height) = parse_size(size)?;
    let options = RenderOptions::default()
        .with_overlays(overlay)
        .map_err(anyhow::Error::msg)?;
    if let Some(dir) = output.dir
        && !dir.is_dir()
    {
        bail!("--out-dir {}: not an existing directory", dir.display());
    }
    for path in [output.png, output.gif].into_iter().flatten() {
        check_directory(path)?;
    }
    if output.png.is_none() && output.dir.is_none() && output.gif.is_none() {
        bail!("give --out FILE.png, --out-dir DIR or --gif FILE.gif");
    }
    let mut sim = args.simulation()?;
    let camera = view::default_camera(&sim, width as f32 / height as f32);
    let mut offscreen = Offscreen::new(width, height, AdapterPreference::Any)?;
    let frames = (args.seconds / sim.params().dt as f64).round() as u64;
    if let Some(path) = output.png {
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
        return Ok(());
    }
    let every = output.every.unwrap_or(1).max(1) as u64;
    let mut gif = match output.gif {
        Some(path) => Some(GifWriter::create(
            path,
            every as f64 * sim.params().dt as f64,
        )?),
        None => None,
    };
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
            if let Some(dir) = output.dir {
                save_png(&image, &dir.join(format!("frame_{written:05}.png")))?;
            }
            if let Some(g) = gif.as_mut() {
                g.add(&image)?;
            }
            written += 1;
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    if let Some(g) = gif {
        g.finish()?;
    }
    for (what, place) in [("", output.dir), (" as a GIF", output.gif)] {
        if let Some(p) = place {
            println!("wrote {written} frames{what} to {}", p.display());
        }
    }
    Ok(())
}

fn bench(
    sizes: &[u32],
    integrators: &[IntegratorKind],
    threads: &[usize],
    json: bool,
    backend: Backend,
) -> Result<()> {
    if let Some(&n) = sizes.iter().find(|&&n| !(3..=2048).contains(&n)) {
        bail!("--sizes: {n} particles per side is outside 3..=2048");
    }
    if let Some(&t) = threads.iter().find(|&&t| !(1..=256).contains(&t)) {
        bail!("--threads: {t} is outside 1..=256");
    }
    if backend == Backend::Gpu
        && let Some(k) = integrators.iter().find(|&&k| k != GPU_INTEGRATOR)
    {
        bail!(
            "--backend gpu runs {} only, not {}",
            GPU_INTEGRATOR.name(),
            k.name()
        );
    }
    if !json {
        println!(
            "{:>5} {:<20} {:>7} {:>9} {:>12} {:>9} {:>9} {:>12} {:>10} {:>10}  sag",
            "N",
            "integrator",
            "threads",
            "substeps",
            "µs/substep",
            "median fr",
            "best fr",
            "substeps/s",
            "sag m",
            "reference",
        );
    }
    // The GPU rows do not depend on the CPU threads: once.
    let threads = if backend == Backend::Gpu {
        &threads[..threads.len().min(1)]
    } else {
        threads
    };
    for &t in threads {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .with_context(|| format!("cannot start {t} threads"))?;
        for &n in sizes {
            for &k in integrators {
                let row = match backend {
                    Backend::Cpu => pool.install(|| clothsim::bench::bench_one(n, k))?,
                    // On this thread, not the pool's: a GL device (llvmpipe through EGL) is
                    // current on the thread that made it, and a pool's thread still tearing
                    // that down while the process exits corrupts the heap (a crash at exit
                    // in a few runs in a hundred).
                    Backend::Gpu => clothsim::bench::bench_gpu(n, k)?,
                };
                if json {
                    println!("{}", serde_json::to_string(&row)?);
                } else {
                    let verdict = match (row.finite, row.sag_ok, row.sag_error) {
                        (false, _, _) => "diverged".to_string(),
                        (true, Some(ok), Some(e)) => {
                            format!(
                                "{:.2} % off{}",
                                100.0 * e,
                                if ok {
                                    ""
                                } else {
                                    " (too far: the speed does not count)"
                                }
                            )
                        }
                        _ => "no reference".to_string(),
                    };
                    let frame = |us: Option<f64>| us.map_or("—".into(), |us| format!("{us:.1}"));
                    println!(
                        "{:>5} {:<20} {:>7} {:>9} {:>12.1} {:>9} {:>9} {:>12.0} {:>10.5} {:>10}  {}",
                        row.n,
                        row.integrator,
                        row.threads,
                        row.substeps_per_frame,
                        row.us_per_substep,
                        frame(row.median_frame_us),
                        frame(row.best_frame_us),
                        row.substeps_per_second,
                        row.sag_m,
                        row.reference_sag_m
                            .map_or("—".into(), |r| format!("{r:.5}")),
                        verdict
                    );
                }
            }
        }
    }
    Ok(())
}
