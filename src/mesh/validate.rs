//! The validation scan of OBJ text: every `v`, `vt`, `vn` and `f` statement is checked and
//! the first problem is reported with its 1-based line number, before tobj parses.

use std::path::Path;

use super::error::ObjError;
use super::limits::{MAX_COORDINATE, MAX_TRIANGLES, MAX_VERTICES};

/// Checks `text`; `path` names it in errors. Returns the vertex (0-based, in the order of
/// the `v` statements) of every face corner, in order.
///
/// # Errors
/// The first problem: [`ObjError::NotText`] (a NUL byte), [`ObjError::TooMany`],
/// [`ObjError::Parse`], [`ObjError::NonFinite`], [`ObjError::CoordinateTooLarge`],
/// [`ObjError::IndexOutOfRange`].
pub fn validate(text: &str, path: &Path) -> Result<Vec<u32>, ObjError> {
    if let Some(offset) = text.bytes().position(|b| b == 0) {
        return Err(ObjError::NotText {
            path: path.to_path_buf(),
            offset,
        });
    }
    let total_positions = count_statements(text, path)?;
    let mut positions_so_far = 0usize;
    let mut corners = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let at = Line {
            path,
            number: n + 1,
            text: line,
        };
        match words.next() {
            Some("f") => at.face(words, positions_so_far, total_positions, &mut corners)?,
            Some("v") => {
                at.numbers(words, "vertex position", 3, true)?;
                positions_so_far += 1;
            }
            Some("vt") => at.numbers(words, "texture coordinate", 2, false)?,
            Some("vn") => at.numbers(words, "normal", 3, false)?,
            _ => {}
        }
    }
    Ok(corners)
}

/// Counts `v` statements and the triangles faces will make, refusing a file over the limits
/// before anything is parsed; returns the number of positions.
fn count_statements(text: &str, path: &Path) -> Result<usize, ObjError> {
    let (mut positions, mut triangles) = (0usize, 0usize);
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => positions += 1,
            Some("f") => triangles += words.count().saturating_sub(2),
            _ => {}
        }
    }
    let too_many = |what, count, limit| ObjError::TooMany {
        path: path.to_path_buf(),
        what,
        count,
        limit,
    };
    if positions > MAX_VERTICES {
        return Err(too_many("vertices", positions, MAX_VERTICES));
    }
    if triangles > MAX_TRIANGLES {
        return Err(too_many("triangles", triangles, MAX_TRIANGLES));
    }
    Ok(positions)
}

/// One line of the file, for checking and for error messages.
struct Line<'a> {
    path: &'a Path,
    number: usize,
    text: &'a str,
}

impl Line<'_> {
    fn parse_error(&self, what: &'static str, text: &str) -> ObjError {
        ObjError::Parse {
            path: self.path.to_path_buf(),
            line: self.number,
            what,
            text: text.to_string(),
        }
    }

    /// A face: at least 3 corners, each a vertex index that exists (1-based, or negative
    /// counting back from the last vertex so far), pushed to `out` 0-based.
    fn face<'w>(
        &self,
        words: impl Iterator<Item = &'w str>,
        positions_so_far: usize,
        total: usize,
        out: &mut Vec<u32>,
    ) -> Result<(), ObjError> {
        let corners: Vec<&str> = words.collect();
        if corners.len() < 3 {
            return Err(self.parse_error("face (needs at least 3 corners)", self.text.trim()));
        }
        for corner in corners {
            let first = corner.split('/').next().unwrap_or("");
            let index: i64 = first
                .parse()
                .map_err(|_| self.parse_error("face vertex index", corner))?;
            let resolved = if index < 0 {
                positions_so_far as i64 + index
            } else {
                index - 1
            };
            if index == 0 || resolved < 0 || resolved >= total as i64 {
                return Err(ObjError::IndexOutOfRange {
                    path: self.path.to_path_buf(),
                    line: self.number,
                    index,
                    count: total,
                });
            }
            out.push(resolved as u32);
        }
        Ok(())
    }

    /// At least `needed` numbers; for positions (`finite_metres`) finite and within
    /// [`MAX_COORDINATE`].
    fn numbers<'w>(
        &self,
        words: impl Iterator<Item = &'w str>,
        what: &'static str,
        needed: usize,
        finite_metres: bool,
    ) -> Result<(), ObjError> {
        let values: Vec<&str> = words.collect();
        if values.len() < needed {
            return Err(self.parse_error(what, self.text.trim()));
        }
        for word in &values[..needed] {
            let value: f32 = word.parse().map_err(|_| self.parse_error(what, word))?;
            if !finite_metres {
                continue;
            }
            if !value.is_finite() {
                return Err(ObjError::NonFinite {
                    path: self.path.to_path_buf(),
                    line: self.number,
                    text: word.to_string(),
                });
            }
            if value.abs() > MAX_COORDINATE {
                return Err(ObjError::CoordinateTooLarge {
                    path: self.path.to_path_buf(),
                    line: self.number,
                    text: word.to_string(),
                });
            }
        }
        Ok(())
    }
}
