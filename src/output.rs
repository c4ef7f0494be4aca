//! Writing output files atomically: into a temporary file beside the target, then renamed,
//! so a failure never leaves a half-written file at the path or a temporary one beside it.

use std::io::Write;
use std::path::{Path, PathBuf};

/// Why an output file could not be written. Nothing was left behind.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The directory of the output file does not exist.
    #[error("{path}: the directory {dir} does not exist")]
    MissingDirectory { path: PathBuf, dir: PathBuf },
    /// Creating, writing or renaming failed.
    #[error("{path}: cannot write: {detail}")]
    Write { path: PathBuf, detail: String },
}

/// Writes `path` through `fill`, atomically.
///
/// # Errors
/// [`OutputError::MissingDirectory`], or [`OutputError::Write`] with what went wrong
/// (including an error `fill` returns).
pub fn write_atomically(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> Result<(), String>,
) -> Result<(), OutputError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.is_dir() {
        return Err(OutputError::MissingDirectory {
            path: path.to_path_buf(),
            dir,
        });
    }
    let write_err = |detail: String| OutputError::Write {
        path: path.to_path_buf(),
        detail,
    };
    let file_name = path
        .file_name()
        .ok_or_else(|| write_err("the path names no file".into()))?
        .to_string_lossy()
        .into_owned();
    let tmp = dir.join(format!(".{file_name}.{}.tmp", std::process::id()));
    let write = || -> Result<(), String> {
        let file = std::fs::File::create(&tmp).map_err(|e| e.to_string())?;
        let mut out = std::io::BufWriter::new(file);
        fill(&mut out)?;
        // Flush explicitly: a BufWriter dropped with an error would swallow it.
        out.flush().map_err(|e| e.to_string())?;
        out.get_ref().sync_all().map_err(|e| e.to_string())?;
        std::fs::rename(&tmp, path).map_err(|e| e.to_string())
    };
    let result = write().map_err(write_err);
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes `bytes` to `path` atomically.
///
/// # Errors
/// As [`write_atomically`].
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    write_atomically(path, |w| w.write_all(bytes).map_err(|e| e.to_string()))
}
