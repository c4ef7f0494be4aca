//! `clothsim accuracy`: what accuracy costs in time, written as CSV, Markdown and PNG.

use anyhow::{Context, Result};

use clothsim::mesh;
use clothsim::scene::Scene;

/// What to run beside the sweep.
#[derive(Clone, Copy, Debug, Default)]
pub struct Extras {
    pub map: bool,
    pub small_steps: bool,
}

/// A progress bar for `done` of `total` runs.
fn progress_bar(what: &'static str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(1);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} {msg} [{elapsed}]")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_message(what);
    bar
}

/// Sweeps `scene` (with the OBJ cloth `obj`, if given) as `config` says and writes the report
/// into `out`; with `extras`, the stability map and the small-steps grid too.
pub fn accuracy(
    scene: &str,
    obj: Option<&std::path::Path>,
    config: &clothsim::report::SweepConfig,
    extras: Extras,
    out: &std::path::Path,
) -> Result<()> {
    config.validate()?;
    let scene = Scene::open_with_obj(scene, obj, &mesh::ImportOptions::default())?;
    // Fail on an unusable output directory before a minute of work, not after it.
    std::fs::create_dir_all(out)
        .with_context(|| format!("{}: cannot create the output directory", out.display()))?;
    let bar = progress_bar("");
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
    if extras.map {
        let bar = progress_bar("stability map");
        let map = clothsim::report::stability_map(
            &scene,
            config,
            &clothsim::report::MAP_SCALES,
            &mut |done, total| {
                bar.set_length(total as u64);
                bar.set_position(done as u64);
                true
            },
        )?;
        bar.finish_and_clear();
        println!("stability map: {:.0} s", map.seconds_taken);
        for f in clothsim::report::write_map(&map, out)? {
            println!("wrote {}", f.display());
        }
    }
    if extras.small_steps {
        let bar = progress_bar("small steps");
        let grid = clothsim::report::small_steps(&scene, config, &mut |done, total| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
            true
        })?;
        bar.finish_and_clear();
        println!("small steps: {:.0} s", grid.seconds_taken);
        for line in grid.verdict() {
            println!("  {line}");
        }
        for f in clothsim::report::write_small_steps(&grid, out)? {
            println!("wrote {}", f.display());
        }
    }
    Ok(())
}

/// Measures the unit costs on `scene` on this machine and prints them beside the built-in
/// ones.
pub fn calibrate(scene: &str, obj: Option<&std::path::Path>) -> Result<()> {
    let scene = Scene::open_with_obj(scene, obj, &mesh::ImportOptions::default())?;
    eprintln!("timing each kind of work on `{}`…", scene.scenario);
    let measured = clothsim::report::calibrate(&scene);
    let built_in = clothsim::report::UnitCosts::default();
    println!("unit costs, in force evaluations of the cloth (one semi-implicit Euler substep):");
    println!("{:<34} {:>10} {:>10}", "", "measured", "built in");
    let rows = [
        (
            "implicit Euler's assembly",
            measured.assembly,
            built_in.assembly,
        ),
        (
            "a conjugate-gradient iteration",
            measured.linear_iteration,
            built_in.linear_iteration,
        ),
        ("an XPBD sweep", measured.xpbd_sweep, built_in.xpbd_sweep),
        ("a VBD sweep", measured.vbd_sweep, built_in.vbd_sweep),
    ];
    for (what, m, b) in rows {
        println!("{what:<34} {m:>10.2} {b:>10.2}");
    }
    println!("measured: {}", measured.source);
    println!("built in: {}", built_in.source);
    Ok(())
}
