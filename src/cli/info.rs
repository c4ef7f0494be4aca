//! `clothsim info`: an OBJ cloth's topology.

use anyhow::Result;

use clothsim::mesh::{self, SpringKind};

/// Prints `file`'s particles, triangles, edges and springs by kind (JSON with `json`).
pub fn info(file: &std::path::Path, json: bool, options: &mesh::ImportOptions) -> Result<()> {
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
