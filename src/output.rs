//! Atomic output: write to a temporary file in the destination folder, then rename over the
//! target. A run that fails midway leaves no file behind, and never a half-written one.

use crate::error::{Error, Result};
use std::io::{BufWriter, Write};
use std::path::Path;

/// Checks up front that `path` can be created (its folder exists and is writable), so a long
/// job fails before doing its work rather than after.
pub fn check_writable(path: &Path) -> Result<()> {
    let dir = parent_dir(path);
    if path.is_dir() {
        return Err(Error::invalid(format!(
            "{}: is a directory",
            path.display()
        )));
    }
    tempfile::Builder::new()
        .prefix(".latvox-probe-")
        .tempfile_in(dir)
        .map(drop)
        .map_err(|e| Error::io(path, e))
}

/// Ordinary file permissions (0666 less the umask), not the temporary file's private 0600.
fn file_mode() -> std::fs::Permissions {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::Permissions::from_mode(0o666)
    }
    #[cfg(not(unix))]
    {
        std::fs::metadata(".")
            .map(|m| m.permissions())
            .unwrap_or_else(|_| unreachable!())
    }
}

fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// A new temporary file in `path`'s folder, with ordinary permissions, to be renamed over
/// `path` once complete (it is deleted if dropped instead).
pub fn temp_beside(path: &Path) -> Result<tempfile::NamedTempFile> {
    tempfile::Builder::new()
        .prefix(".latvox-")
        .permissions(file_mode())
        .tempfile_in(parent_dir(path))
        .map_err(|e| Error::io(path, e))
}

/// Writes `path` atomically through `body`.
pub fn write_atomic(
    path: &Path,
    body: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let tmp = temp_beside(path)?;
    {
        let mut w = BufWriter::with_capacity(1 << 20, tmp.as_file());
        body(&mut w).map_err(|e| Error::io(path, e))?;
        w.flush().map_err(|e| Error::io(path, e))?;
    }
    tmp.persist(path).map_err(|e| Error::io(path, e.error))?;
    Ok(())
}
