//! Runs the command line's subcommand (or the GUI without one).

use anyhow::Result;

use clothsim::gpu::{Backend, GPU_INTEGRATORS};

use super::accuracy::accuracy;
use super::args::{Cli, Command};
use super::bench::{BenchRuns, bench, contact_bench, crumple_bench};
use super::grid::grid;
use super::info::info;
use super::render::{Output, render};
use super::scenes::scenes;
use super::simulate::simulate;

/// Runs what `cli` asks for.
///
/// # Errors
/// Whatever the subcommand met, as one message.
pub fn run(cli: Cli) -> Result<()> {
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
            every,
            out_dir,
            check_intersections,
        }) => simulate(
            &run,
            json,
            export_obj.as_deref(),
            out_dir.as_deref().map(|dir| (dir, every.unwrap_or(1))),
            check_intersections,
        ),
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
            precision,
            out,
            calibrate,
            map,
            small_steps,
        }) => {
            if calibrate {
                return super::accuracy::calibrate(&scene, obj.as_deref());
            }
            let Some(out) = out else {
                anyhow::bail!("--out is needed (or --calibrate)");
            };
            let mut config = clothsim::report::SweepConfig {
                tolerance,
                precision,
                ..clothsim::report::SweepConfig::for_scene(&scene)
            };
            if let Some(seconds) = seconds {
                config.seconds = seconds;
            }
            if let Some(list) = integrators {
                config.integrators = list;
            }
            if let Some(list) = dts {
                config.dts = list;
            }
            let extras = super::accuracy::Extras { map, small_steps };
            accuracy(&scene, obj.as_deref(), &config, extras, &out)
        }
        Some(Command::Grid {
            quads,
            size,
            triangles,
            out,
        }) => grid(quads, size, triangles, &out),
        Some(Command::Bench {
            threads,
            json,
            obstacles: true,
            ..
        }) => contact_bench(&threads, json),
        Some(Command::Bench {
            threads,
            json,
            crumple: true,
            quads,
            integrators,
            repeat,
            ..
        }) => crumple_bench(&quads, integrators.as_deref(), &threads, repeat, json),
        Some(Command::Bench {
            sizes,
            integrators,
            threads,
            json,
            backend,
            precision,
            seconds,
            obstacles: false,
            crumple: false,
            ..
        }) => {
            let integrators = integrators.unwrap_or_else(|| match backend {
                Backend::Cpu => clothsim::bench::BENCH_INTEGRATORS.to_vec(),
                Backend::Gpu => GPU_INTEGRATORS.to_vec(),
            });
            let runs = BenchRuns {
                sizes: &sizes,
                integrators: &integrators,
                threads: &threads,
                seconds,
            };
            bench(&runs, json, backend, precision)
        }
    }
}
