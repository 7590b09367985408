//! Atomic output: write to a temporary file in the destination folder, then rename over the
//! target. A run that fails midway leaves no file behind, and never a half-written one.
//!
//! The temporary is named after its target (`.NAME.latvox-XXXXXX`), so when a process is killed
//! outright (SIGKILL: no destructor runs) the leftover can be recognised and removed by whoever
//! next writes that target ([`remove_stale_temporaries`]), e.g. a resumed batch.

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
    // Named as `path`'s own temporaries are, so that a probe a killed run leaves behind is
    // removed with them (`remove_stale_temporaries`).
    tempfile::Builder::new()
        .prefix(&temp_prefix(path))
        .rand_bytes(RANDOM_LEN)
        .tempfile_in(dir)
        .map(drop)
        .map_err(|e| folder_error(path, e))
}

/// The error of creating a file in `path`'s folder, naming the user's path (not the temporary
/// file's) and the folder when it is missing.
fn folder_error(path: &Path, e: std::io::Error) -> Error {
    let dir = parent_dir(path);
    if !dir.is_dir() {
        return Error::invalid(format!(
            "{}: the folder {} does not exist",
            path.display(),
            dir.display()
        ));
    }
    // tempfile's message names the temporary file: keep only what went wrong.
    Error::io(path, std::io::Error::from(e.kind()))
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
/// `path` once complete (it is deleted if dropped instead; a killed run's is found by
/// [`remove_stale_temporaries`]).
pub fn temp_beside(path: &Path) -> Result<tempfile::NamedTempFile> {
    tempfile::Builder::new()
        .prefix(&temp_prefix(path))
        .rand_bytes(RANDOM_LEN)
        .permissions(file_mode())
        .tempfile_in(parent_dir(path))
        .map_err(|e| folder_error(path, e))
}

/// Length of the random part of a temporary's name (tempfile's default).
const RANDOM_LEN: usize = 6;

/// `.NAME.latvox-`: the start of every temporary written for `path` (the name is cut short so
/// that the temporary's own name stays within the usual 255-byte limit).
fn temp_prefix(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut end = name.len().min(200);
    while !name.is_char_boundary(end) {
        end -= 1;
    }
    format!(".{}.latvox-", &name[..end])
}

/// Removes temporaries left by writes of `path` that never finished (their process was killed).
/// Only call this when no other process can be writing `path` at the same moment; returns how
/// many were removed.
pub fn remove_stale_temporaries(path: &Path) -> Result<usize> {
    let dir = parent_dir(path);
    let prefix = temp_prefix(path);
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(0),
        Err(e) => return Err(Error::io(dir, e)),
    };
    let mut removed = 0;
    for entry in entries {
        let entry = entry.map_err(|e| Error::io(dir, e))?;
        let name = entry.file_name();
        let Some(rest) = name.to_str().and_then(|n| n.strip_prefix(&prefix)) else {
            continue;
        };
        if rest.len() == RANDOM_LEN && rest.bytes().all(|b| b.is_ascii_alphanumeric()) {
            match std::fs::remove_file(entry.path()) {
                Ok(()) => removed += 1,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => return Err(Error::io(entry.path(), e)),
            }
        }
    }
    Ok(removed)
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
    // On disk before the rename: after a crash of the machine, not only of the process, the
    // name holds the old file or the whole new one, never a new file with lost blocks.
    tmp.as_file().sync_data().map_err(|e| Error::io(path, e))?;
    tmp.persist(path).map_err(|e| Error::io(path, e.error))?;
    Ok(())
}

/// Writes `value` as pretty-printed JSON to `path`, atomically.
pub fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<()> {
    write_atomic(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value).map_err(std::io::Error::other)?;
        w.write_all(b"\n")
    })
}

/// A file written in pieces and put in place whole: a temporary beside the target until
/// [`AtomicFile::commit`]; dropped uncommitted, it leaves nothing.
pub struct AtomicFile {
    path: std::path::PathBuf,
    w: BufWriter<tempfile::NamedTempFile>,
}

impl AtomicFile {
    /// Starts writing `path`.
    pub fn create(path: &Path) -> Result<AtomicFile> {
        Ok(AtomicFile {
            path: path.to_path_buf(),
            w: BufWriter::with_capacity(1 << 20, temp_beside(path)?),
        })
    }

    /// The target's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes `bytes`.
    pub fn write(&mut self, bytes: &[u8]) -> Result<()> {
        self.w
            .write_all(bytes)
            .map_err(|e| Error::io(&self.path, e))
    }

    /// The writer, for formatted output; errors map with [`AtomicFile::error`].
    pub fn writer(&mut self) -> &mut dyn Write {
        &mut self.w
    }

    /// An I/O error of this file, naming the target.
    pub fn error(&self, e: std::io::Error) -> Error {
        Error::io(&self.path, e)
    }

    /// Flushes, syncs and renames over the target.
    pub fn commit(self) -> Result<()> {
        let path = self.path;
        let tmp = self
            .w
            .into_inner()
            .map_err(|e| Error::io(&path, e.into_error()))?;
        tmp.as_file().sync_data().map_err(|e| Error::io(&path, e))?;
        tmp.persist(&path).map_err(|e| Error::io(&path, e.error))?;
        Ok(())
    }
}

/// A folder filled file by file and put in place whole: a temporary folder beside the target
/// until [`AtomicDir::commit`], which replaces the target folder (and what it held). Only a
/// folder of the same kind is replaced — one holding the kind's mark file, as a previous write
/// left it — or an empty one: a folder of other files named by mistake (the part's own folder,
/// a home folder) is refused, never deleted.
pub struct AtomicDir {
    path: std::path::PathBuf,
    tmp: tempfile::TempDir,
}

impl AtomicDir {
    /// Starts filling the folder `path` (its parent must exist; `path` itself may exist, as an
    /// empty folder or one holding the file `mark` that every such folder holds, and is
    /// replaced on commit).
    pub fn create(path: &Path, mark: &str) -> Result<AtomicDir> {
        if path.exists() && !path.is_dir() {
            return Err(Error::invalid(format!(
                "{}: exists and is not a folder",
                path.display()
            )));
        }
        let empty = match std::fs::read_dir(path) {
            Ok(mut entries) => entries.next().is_none(),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => true,
            Err(e) => return Err(Error::io(path, e)),
        };
        if !empty && !path.join(mark).is_file() {
            return Err(Error::invalid(format!(
                "{}: the folder holds other files (no {mark}): name a new or empty folder",
                path.display()
            )));
        }
        let tmp = tempfile::Builder::new()
            .prefix(&temp_prefix(path))
            .rand_bytes(RANDOM_LEN)
            .tempdir_in(parent_dir(path))
            .map_err(|e| folder_error(path, e))?;
        Ok(AtomicDir {
            path: path.to_path_buf(),
            tmp,
        })
    }

    /// Where a file named `name` is written before the commit.
    pub fn file(&self, name: &str) -> std::path::PathBuf {
        self.tmp.path().join(name)
    }

    /// Puts the folder in place, replacing an existing one.
    pub fn commit(self) -> Result<()> {
        let err = |e| Error::io(&self.path, e);
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(self.tmp.path(), std::fs::Permissions::from_mode(0o755))
                .map_err(err)?;
        }
        let old = if self.path.exists() {
            let old = tempfile::Builder::new()
                .prefix(&temp_prefix(&self.path))
                .tempdir_in(parent_dir(&self.path))
                .map_err(err)?;
            let aside = old.path().join("old");
            std::fs::rename(&self.path, &aside).map_err(err)?;
            Some(old)
        } else {
            None
        };
        let tmp = self.tmp.keep();
        std::fs::rename(&tmp, &self.path).map_err(err)?;
        drop(old);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_of_other_files_is_refused_not_replaced() {
        let d = tempfile::tempdir().unwrap();
        let mine = d.path().join("mine");
        std::fs::create_dir(&mine).unwrap();
        std::fs::write(mine.join("notes.txt"), "keep").unwrap();
        let e = AtomicDir::create(&mine, "stack.json").err().unwrap();
        assert!(e.to_string().contains("holds other files"), "{e}");
        assert_eq!(
            std::fs::read_to_string(mine.join("notes.txt")).unwrap(),
            "keep"
        );

        // An empty folder, and a stack written before, are replaced whole.
        for (name, old) in [("empty", None), ("stack", Some("stack.json"))] {
            let p = d.path().join(name);
            std::fs::create_dir(&p).unwrap();
            if let Some(f) = old {
                std::fs::write(p.join(f), "{}").unwrap();
                std::fs::write(p.join("layer0.png"), "old").unwrap();
            }
            let dir = AtomicDir::create(&p, "stack.json").unwrap();
            std::fs::write(dir.file("stack.json"), "new").unwrap();
            dir.commit().unwrap();
            assert_eq!(
                std::fs::read_to_string(p.join("stack.json")).unwrap(),
                "new"
            );
            assert!(!p.join("layer0.png").exists());
        }
    }

    /// A link where an output goes is replaced by the output, never written through: what it
    /// pointed at is untouched.
    #[cfg(unix)]
    #[test]
    fn a_link_at_an_output_is_replaced_not_followed() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("theirs.txt");
        std::fs::write(&target, "theirs").unwrap();
        let out = d.path().join("out.stl");
        std::os::unix::fs::symlink(&target, &out).unwrap();
        write_atomic(&out, |w| w.write_all(b"mine")).unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "theirs");
        assert!(!std::fs::symlink_metadata(&out)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "mine");
    }
}
