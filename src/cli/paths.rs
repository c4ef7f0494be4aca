//! Checks of where the command line writes.

use anyhow::{Result, bail};

/// Fails before a long run, not after it, when a file's directory does not exist.
pub fn check_directory(path: &std::path::Path) -> Result<()> {
    if let Some(parent) = path.parent()
        && !parent.as_os_str().is_empty()
        && !parent.is_dir()
    {
        bail!(
            "{}: the directory {} does not exist",
            path.display(),
            parent.display()
        );
    }
    Ok(())
}
