//! `clothsim grid`: a rectangular grid cloth written as OBJ.

use anyhow::{Context, Result, bail};

use clothsim::mesh::{self, GridOrientation, GridSpec};

/// Writes a `quads` × `quads` grid of `size` metres to `out` (as triangles with `triangles`).
pub fn grid(quads: u32, size: f32, triangles: bool, out: &std::path::Path) -> Result<()> {
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
