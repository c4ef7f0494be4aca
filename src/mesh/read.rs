//! Reading an OBJ file from disk: only regular files, only up to a size limit.

use std::io::Read;
use std::path::Path;

use super::error::ObjError;
use super::limits::MAX_FILE_BYTES;
use super::obj::parse_obj;
use super::polygons::PolygonSoup;

/// Reads an OBJ file into a polygon soup. Directories, devices, pipes and sockets are
/// refused before anything is read, and so is a file above [`MAX_FILE_BYTES`] (checked on
/// its size and again while reading, in case it grows).
///
/// # Errors
/// [`ObjError::NotFound`], [`ObjError::NotAFile`], [`ObjError::TooLarge`], [`ObjError::Io`],
/// [`ObjError::NotText`] for file problems, and the content errors of [`parse_obj`].
pub fn read_obj(path: &Path) -> Result<PolygonSoup, ObjError> {
    let io = |cause: std::io::Error| match cause.kind() {
        std::io::ErrorKind::NotFound => ObjError::NotFound {
            path: path.to_path_buf(),
        },
        _ => ObjError::Io {
            path: path.to_path_buf(),
            cause,
        },
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(ObjError::NotAFile {
            path: path.to_path_buf(),
            what: kind_of(&meta.file_type()),
        });
    }
    let too_large = |bytes: u64| ObjError::TooLarge {
        path: path.to_path_buf(),
        bytes,
        limit: MAX_FILE_BYTES,
    };
    if meta.len() > MAX_FILE_BYTES {
        return Err(too_large(meta.len()));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    std::fs::File::open(path)
        .map_err(io)?
        .take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(too_large(bytes.len() as u64));
    }
    let text = std::str::from_utf8(&bytes).map_err(|e| ObjError::NotText {
        path: path.to_path_buf(),
        offset: e.valid_up_to(),
    })?;
    parse_obj(text, path)
}

/// What a non-regular file is, in words.
fn kind_of(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_fifo() {
            return "a pipe";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}
