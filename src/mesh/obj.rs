//! OBJ reading (through `tobj`) and writing.
//!
//! Reading validates once: a line scan finds unparsable or non-finite numbers and face
//! indices out of range with their line numbers (tobj reports neither), then tobj parses.
//! Only the given file is read: `mtllib` statements are ignored.

use std::io::BufReader;
use std::path::Path;

use glam::{Vec2, Vec3};

use super::error::ObjError;
use super::polygons::PolygonSoup;

/// Reads an OBJ file into a polygon soup.
///
/// # Errors
/// [`ObjError::NotFound`], [`ObjError::Io`], [`ObjError::NotText`] for file problems, and the
/// content errors of [`parse_obj`].
pub fn read_obj(path: &Path) -> Result<PolygonSoup, ObjError> {
    let bytes = std::fs::read(path).map_err(|source| match source.kind() {
        std::io::ErrorKind::NotFound => ObjError::NotFound {
            path: path.to_path_buf(),
        },
        _ => ObjError::Io {
            path: path.to_path_buf(),
            cause: source,
        },
    })?;
    let text = match std::str::from_utf8(&bytes) {
        Ok(text) => text,
        Err(e) => {
            return Err(ObjError::NotText {
                path: path.to_path_buf(),
                offset: e.valid_up_to(),
            });
        }
    };
    parse_obj(text, path)
}

/// Parses OBJ text; `path` only names the source in error messages.
///
/// # Errors
/// [`ObjError::NotText`] (NUL bytes), [`ObjError::Parse`], [`ObjError::NonFinite`],
/// [`ObjError::IndexOutOfRange`], [`ObjError::Empty`] (no faces), [`ObjError::Malformed`].
pub fn parse_obj(text: &str, path: &Path) -> Result<PolygonSoup, ObjError> {
    validate(text, path)?;
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
    Ok(soup)
}

/// The validation scan: checks every `v`, `vt`, `vn` and `f` statement and reports the
/// first problem with its 1-based line number.
fn validate(text: &str, path: &Path) -> Result<(), ObjError> {
    if let Some(offset) = text.bytes().position(|b| b == 0) {
        return Err(ObjError::NotText {
            path: path.to_path_buf(),
            offset,
        });
    }
    let total_positions = text
        .lines()
        .filter(|l| l.split_whitespace().next() == Some("v"))
        .count();
    let mut positions_so_far = 0usize;
    for (n, line) in text.lines().enumerate() {
        let line_no = n + 1;
        let mut words = line.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let (what, needed) = match keyword {
            "v" => ("vertex position", 3),
            "vt" => ("texture coordinate", 2),
            "vn" => ("normal", 3),
            "f" => {
                let corners: Vec<&str> = words.collect();
                if corners.len() < 3 {
                    return Err(ObjError::Parse {
                        path: path.to_path_buf(),
                        line: line_no,
                        what: "face (needs at least 3 corners)",
                        text: line.trim().to_string(),
                    });
                }
                for corner in corners {
                    let first = corner.split('/').next().unwrap_or("");
                    let index: i64 = first.parse().map_err(|_| ObjError::Parse {
                        path: path.to_path_buf(),
                        line: line_no,
                        what: "face vertex index",
                        text: corner.to_string(),
                    })?;
                    // OBJ indices are 1-based; negative ones count back from the last vertex.
                    let resolved = if index < 0 {
                        positions_so_far as i64 + index
                    } else {
                        index - 1
                    };
                    if index == 0 || resolved < 0 || resolved >= total_positions as i64 {
                        return Err(ObjError::IndexOutOfRange {
                            path: path.to_path_buf(),
                            line: line_no,
                            index,
                            count: total_positions,
                        });
                    }
                }
                continue;
            }
            _ => continue,
        };
        let values: Vec<&str> = words.collect();
        if values.len() < needed {
            return Err(ObjError::Parse {
                path: path.to_path_buf(),
                line: line_no,
                what,
                text: line.trim().to_string(),
            });
        }
        for word in &values[..needed] {
            let value: f32 = word.parse().map_err(|_| ObjError::Parse {
                path: path.to_path_buf(),
                line: line_no,
                what,
                text: word.to_string(),
            })?;
            if keyword == "v" && !value.is_finite() {
                return Err(ObjError::NonFinite {
                    path: path.to_path_buf(),
                    line: line_no,
                    text: word.to_string(),
                });
            }
        }
        if keyword == "v" {
            positions_so_far += 1;
        }
    }
    Ok(())
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
