//! Saving the current setup as a scene file anywhere: every path in it (the cloth's OBJ,
//! each obstacle's OBJ or frames) is made relative to the saved file, and the program's own
//! meshes that a built-in scene names are written beside it, so the file opens as saved.

use std::path::{Path, PathBuf};

use crate::output::{OutputError, write_bytes};
use crate::sim::{Effect, frame_path};

use super::file::SceneFile;
use super::registry::builtin_mesh;
use super::scene::{DEFAULT_CLOTH_NAME, DEFAULT_CLOTH_OBJ};

/// What saving wrote: the scene file and the built-in meshes beside it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Saved {
    pub scene: PathBuf,
    pub meshes: Vec<PathBuf>,
}

/// A scene file that could not be saved; nothing of it was written.
#[derive(Debug, thiserror::Error)]
pub enum SaveError {
    #[error(
        "{path} exists and is not the built-in mesh `{name}` the scene needs beside it: \
         save the scene in another folder"
    )]
    Clash { path: PathBuf, name: String },
    #[error("{path}: cannot make the folder: {detail}")]
    Folder { path: PathBuf, detail: String },
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// The text of a file the program carries, by the name a built-in scene gives it.
fn builtin_file(name: &Path) -> Option<&'static str> {
    builtin_mesh(name)
        .or_else(|| (name == Path::new(DEFAULT_CLOTH_NAME)).then_some(DEFAULT_CLOTH_OBJ))
}

/// Paths rewritten for a scene file in `dir`, and the built-in files to write there.
struct Relocation {
    dir: PathBuf,
    writes: Vec<(PathBuf, &'static str)>,
}

impl Relocation {
    /// `path` as the saved file should name it: a built-in file (one that is no file on
    /// disk) keeps its name and is written beside; any other path is made relative to the
    /// folder (absolute where it cannot be, as on another drive).
    fn path(&mut self, path: &Path) -> PathBuf {
        if !path.is_file()
            && let Some(text) = builtin_file(path)
        {
            self.writes.push((path.to_path_buf(), text));
            return path.to_path_buf();
        }
        let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
        pathdiff::diff_paths(&absolute, &self.dir).unwrap_or(absolute)
    }

    /// A sequence's pattern as the saved file should name it: built-in frames keep it and
    /// are all written beside.
    fn pattern(&mut self, pattern: &str) -> String {
        let frame = |k| frame_path(pattern, k).map(PathBuf::from);
        if frame(0).is_some_and(|f| !f.is_file() && builtin_file(&f).is_some()) {
            for k in 0.. {
                match frame(k).and_then(|f| builtin_file(&f).map(|text| (f, text))) {
                    Some(write) => self.writes.push(write),
                    None => break,
                }
            }
            return pattern.to_string();
        }
        self.path(Path::new(pattern)).display().to_string()
    }
}

/// Writes `file` to `path` with its paths made relative to it and the built-in meshes it
/// names beside it. A built-in mesh already there is left as it is; a different file in
/// its place refuses the whole save.
///
/// # Errors
/// [`SaveError::Clash`], [`SaveError::Folder`], or the writing's [`OutputError`].
pub fn save(file: &SceneFile, path: &Path) -> Result<Saved, SaveError> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
    let dir = dir.unwrap_or(Path::new("."));
    let mut relocation = Relocation {
        dir: std::path::absolute(dir).unwrap_or_else(|_| dir.to_path_buf()),
        writes: Vec::new(),
    };
    let mut file = file.clone();
    if let Some(obj) = &file.cloth.obj {
        file.cloth.obj = Some(relocation.path(obj));
    }
    for effect in &mut file.effects {
        if let Effect::Obstacle(obstacle) = effect {
            match &obstacle.frames {
                Some(pattern) => obstacle.frames = Some(relocation.pattern(pattern)),
                None => obstacle.obj = relocation.path(&obstacle.obj),
            }
        }
    }
    // Every clash is found before anything is written.
    let mut meshes = Vec::new();
    for (name, text) in &relocation.writes {
        let target = dir.join(name);
        match std::fs::read(&target) {
            Ok(there) if there == text.as_bytes() => {}
            Ok(_) => {
                return Err(SaveError::Clash {
                    path: target,
                    name: name.display().to_string(),
                });
            }
            Err(_) => meshes.push((target, *text)),
        }
    }
    for (target, text) in &meshes {
        if let Some(folder) = target.parent() {
            std::fs::create_dir_all(folder).map_err(|e| SaveError::Folder {
                path: folder.to_path_buf(),
                detail: e.to_string(),
            })?;
        }
        write_bytes(target, text.as_bytes())?;
    }
    write_bytes(path, file.to_toml().as_bytes())?;
    Ok(Saved {
        scene: path.to_path_buf(),
        meshes: meshes.into_iter().map(|(p, _)| p).collect(),
    })
}
