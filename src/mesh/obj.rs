//! OBJ parsing (through `tobj`) and writing.
//!
//! Parsing validates once: a line scan ([`super::validate`]) finds unparsable, non-finite
//! or out-of-range numbers and face indices with their line numbers (tobj reports neither),
//! then tobj parses. Only the given text is read: `mtllib` statements are ignored.

use std::io::BufReader;
use std::path::Path;

use glam::{Vec2, Vec3};

use super::error::ObjError;
use super::polygons::PolygonSoup;
use super::validate::validate;

/// Parses OBJ text; `path` only names the source in error messages.
///
/// # Errors
/// [`ObjError::NotText`] (NUL bytes), [`ObjError::Parse`], [`ObjError::NonFinite`],
/// [`ObjError::CoordinateTooLarge`], [`ObjError::IndexOutOfRange`], [`ObjError::TooMany`],
/// [`ObjError::Empty`] (no faces), [`ObjError::Malformed`].
pub fn parse_obj(text: &str, path: &Path) -> Result<PolygonSoup, ObjError> {
    let corners = validate(text, path)?;
    let options = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = BufReader::new(text.as_bytes());
    // Never follow `mtllib`: the cloth needs no materials and import reads one file only.
    let (models, _materials) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Ok((Vec::new(), Default::default()))
    })
    .map_err(|e| ObjError::Malformed {
        path: path.to_path_buf(),
        detail: e.to_string(),
    })?;

    let mut soup = PolygonSoup::default();
    let mut uvs: Vec<Vec2> = Vec::new();
    let mut all_have_uvs = true;
    for model in &models {
        let mesh = &model.mesh;
        let base = soup.positions.len() as u32;
        let count = mesh.positions.len() / 3;
        soup.positions.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        // Per-corner texture coordinates: the first one seen for a position wins (seams weld).
        let mut model_uvs = vec![None; count];
        if !mesh.texcoord_indices.is_empty() && !mesh.texcoords.is_empty() {
            for (&vi, &ti) in mesh.indices.iter().zip(&mesh.texcoord_indices) {
                let t = ti as usize * 2;
                if let (Some(slot), Some(uv)) =
                    (model_uvs.get_mut(vi as usize), mesh.texcoords.get(t..t + 2))
                    && slot.is_none()
                {
                    *slot = Some(Vec2::new(uv[0], uv[1]));
                }
            }
        }
        all_have_uvs &= model_uvs.iter().all(Option::is_some);
        uvs.extend(model_uvs.into_iter().map(Option::unwrap_or_default));
        soup.face_indices
            .extend(mesh.indices.iter().map(|&i| i + base));
        if mesh.face_arities.is_empty() {
            soup.face_arities
                .extend(std::iter::repeat_n(3, mesh.indices.len() / 3));
        } else {
            soup.face_arities.extend_from_slice(&mesh.face_arities);
        }
    }
    if soup.face_arities.is_empty() {
        return Err(ObjError::Empty {
            path: path.to_path_buf(),
            detail: "the file has no faces (`f` lines)".into(),
        });
    }
    if all_have_uvs {
        soup.uvs = Some(uvs);
    }
    in_file_order(&mut soup, &models, &corners);
    Ok(soup)
}

/// Puts the soup's vertices back in the order of the file's `v` statements. tobj numbers
/// each object's vertices by first use in its faces, which for a grid written row by row
/// interleaves its first two rows; the file's order keeps neighbours' numbers a fixed step
/// apart (see `SpringRuns`), and an exported cloth comes back numbered as it was.
/// `corners` holds the file vertex of every face corner (from the validation scan); when
/// tobj's corners do not match them one for one, the order is left as it is.
fn in_file_order(soup: &mut PolygonSoup, models: &[tobj::Model], corners: &[u32]) {
    let mut file_vertex = vec![u32::MAX; soup.positions.len()];
    let (mut base, mut corner) = (0usize, 0usize);
    for model in models {
        for &i in &model.mesh.indices {
            match (file_vertex.get_mut(base + i as usize), corners.get(corner)) {
                (Some(slot), Some(&v)) if *slot == u32::MAX || *slot == v => *slot = v,
                _ => return,
            }
            corner += 1;
        }
        base += model.mesh.positions.len() / 3;
    }
    if corner != corners.len() || file_vertex.contains(&u32::MAX) {
        return;
    }
    // Stable: a vertex two objects share stays twice, its copies next to each other.
    let mut order: Vec<u32> = (0..soup.positions.len() as u32).collect();
    order.sort_by_key(|&i| file_vertex[i as usize]);
    let mut new_index = vec![0u32; order.len()];
    for (new, &old) in order.iter().enumerate() {
        new_index[old as usize] = new as u32;
    }
    soup.positions = order.iter().map(|&i| soup.positions[i as usize]).collect();
    if let Some(uvs) = &mut soup.uvs {
        *uvs = order.iter().map(|&i| uvs[i as usize]).collect();
    }
    for i in &mut soup.face_indices {
        *i = new_index[*i as usize];
    }
}

/// Writes a polygon soup as OBJ text (`v`, optional `vt`, and `f` lines).
pub fn write_obj(soup: &PolygonSoup) -> String {
    use std::fmt::Write;
    let mut out = String::with_capacity(soup.positions.len() * 40 + soup.face_indices.len() * 8);
    out.push_str("# written by clothsim\n");
    for p in &soup.positions {
        let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
    }
    if let Some(uvs) = &soup.uvs {
        for t in uvs {
            let _ = writeln!(out, "vt {} {}", t.x, t.y);
        }
    }
    for face in soup.faces() {
        out.push('f');
        for &i in face {
            if soup.uvs.is_some() {
                let _ = write!(out, " {}/{}", i + 1, i + 1);
            } else {
                let _ = write!(out, " {}", i + 1);
            }
        }
        out.push('\n');
    }
    out
}
