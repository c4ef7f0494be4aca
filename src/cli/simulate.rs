//! `clothsim simulate`: a scene run headless, summarised.

use anyhow::{Result, bail};

use super::args::RunArgs;
use super::paths::check_directory;

/// Runs the scene and prints its summary (JSON with `json`); writes the cloth's end shape
/// to `export` if given.
pub fn simulate(args: &RunArgs, json: bool, export: Option<&std::path::Path>) -> Result<()> {
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
