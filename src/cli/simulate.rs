//! `clothsim simulate`: a scene run headless, summarised.

use std::path::Path;

use anyhow::{Result, bail};
use clothsim::mesh::{PolygonSoup, write_obj};
use clothsim::scene::Simulation;
use clothsim::sim::Intersections;
use clothsim::view;

use super::args::RunArgs;
use super::paths::check_directory;

/// Runs the scene and prints its summary (JSON with `json`); writes the cloth's end shape
/// to `export` if given, and with `frames` = `(dir, k)` the cloth and each obstacle every
/// k frames into `dir`.
pub fn simulate(
    args: &RunArgs,
    json: bool,
    export: Option<&Path>,
    frames: Option<(&Path, u32)>,
    check_intersections: bool,
) -> Result<()> {
    if let Some(path) = export {
        check_directory(path)?;
    }
    if let Some((dir, _)) = frames
        && !dir.is_dir()
    {
        bail!("--out-dir {}: not an existing directory", dir.display());
    }
    let mut sim = args.simulation()?;
    let mut written = 0u64;
    let mut worst: Option<Intersections> = None;
    let mut summary = sim.run_observed(args.seconds, |sim, frame| {
        if check_intersections {
            let now = sim.intersections();
            worst = Some(worst.as_ref().map_or_else(|| now.clone(), |w| w.max(&now)));
        }
        match frames {
            Some((dir, every)) if frame % every.max(1) as u64 == 0 => {
                write_frame(sim, dir, written)?;
                written += 1;
                anyhow::Ok(())
            }
            _ => Ok(()),
        }
    })?;
    summary.intersections = worst;
    if let Some((dir, _)) = frames
        && !json
    {
        println!("wrote {written} frames as OBJ files to {}", dir.display());
    }
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
        if let Some(found) = &summary.intersections {
            let solids: Vec<String> = found.obstacles.iter().map(ToString::to_string).collect();
            println!(
                "  intersections (most after any frame): self {}, solids [{}]",
                found.self_pairs,
                solids.join(", ")
            );
        }
        if let Some(forced) = summary.forced_pairs.filter(|&n| n > 0) {
            println!(
                "  self-contact: prescribed motion (pins, handles) forced {forced} pairs of the \
                 cloth together"
            );
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

/// Writes the cloth as it is now as `cloth_NNNNN.obj` and each mesh obstacle, where its
/// motion has it now, as `obstacle-K_NNNNN.obj` (K from 1, in the scene's order).
fn write_frame(sim: &Simulation, dir: &Path, number: u64) -> Result<()> {
    let cloth = dir.join(format!("cloth_{number:05}.obj"));
    clothsim::output::write_bytes(&cloth, sim.export_obj().as_bytes())?;
    for (k, mesh) in view::meshes(sim.effects(), sim.state().time)
        .iter()
        .enumerate()
    {
        let soup = PolygonSoup {
            positions: (mesh.vertices.iter())
                .map(|&v| mesh.transform.transform_point3(v))
                .collect(),
            uvs: None,
            face_indices: mesh.triangles.iter().flatten().copied().collect(),
            face_arities: vec![3; mesh.triangles.len()],
        };
        let path = dir.join(format!("obstacle-{}_{number:05}.obj", k + 1));
        clothsim::output::write_bytes(&path, write_obj(&soup).as_bytes())?;
    }
    Ok(())
}
