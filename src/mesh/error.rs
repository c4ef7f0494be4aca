//! Errors of OBJ import: one variant per kind of bad input.

use std::path::PathBuf;

/// Why an OBJ file could not become a cloth. Every message names the file, the line
/// where known, and the problem.
#[derive(Debug, thiserror::Error)]
pub enum ObjError {
    /// The file does not exist.
    #[error("{path}: file not found")]
    NotFound { path: PathBuf },
    /// The path is a directory, a device, a pipe or a socket: nothing was read.
    #[error("{path}: is {what}, not a file; an OBJ must be a regular file")]
    NotAFile { path: PathBuf, what: &'static str },
    /// The file is larger than import reads; nothing was read.
    #[error(
        "{path}: the file has {bytes} bytes, more than the {limit} bytes import reads; is this really a cloth?"
    )]
    TooLarge {
        path: PathBuf,
        bytes: u64,
        limit: u64,
    },
    /// More vertices or triangles than import builds; nothing was parsed.
    #[error("{path}: {count} {what}, more than the {limit} import builds")]
    TooMany {
        path: PathBuf,
        what: &'static str,
        count: usize,
        limit: usize,
    },
    /// A coordinate too large to simulate.
    #[error(
        "{path}:{line}: coordinate `{text}` is too large; positions must be within ±1e6 m (larger values lose all precision and overflow when squared)"
    )]
    CoordinateTooLarge {
        path: PathBuf,
        line: usize,
        text: String,
    },
    /// The file exists but could not be read (permissions, I/O failure).
    #[error("{path}: cannot read file: {cause}")]
    Io {
        path: PathBuf,
        cause: std::io::Error,
    },
    /// The file is not UTF-8 text (for example a binary file).
    #[error(
        "{path}: not a text file (byte {offset} is not valid UTF-8 or is NUL); is this really an OBJ?"
    )]
    NotText { path: PathBuf, offset: usize },
    /// A number or statement could not be parsed.
    #[error("{path}:{line}: cannot parse {what}: `{text}`")]
    Parse {
        path: PathBuf,
        line: usize,
        what: &'static str,
        text: String,
    },
    /// A number parsed but is NaN or infinite.
    #[error(
        "{path}:{line}: non-finite number `{text}` in a vertex position; positions must be finite metres"
    )]
    NonFinite {
        path: PathBuf,
        line: usize,
        text: String,
    },
    /// A face refers to a vertex that does not exist.
    #[error(
        "{path}:{line}: face refers to vertex {index}, but the file defines {count} vertices (indices are 1-based)"
    )]
    IndexOutOfRange {
        path: PathBuf,
        line: usize,
        index: i64,
        count: usize,
    },
    /// Nothing to simulate: no faces, or every face was degenerate.
    #[error("{path}: no usable triangles ({detail})")]
    Empty { path: PathBuf, detail: String },
    /// The parser rejected the file for a reason the validation pass did not find.
    #[error("{path}: malformed OBJ: {detail}")]
    Malformed { path: PathBuf, detail: String },
}
