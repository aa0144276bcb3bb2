//! Output directories and files that are never half-written.
//!
//! The directory is checked before any work starts ([`OutDir::check`]),
//! but created only when the results are written ([`OutDir::write_all`]),
//! so a run that fails leaves nothing behind. Every file is written to a
//! temporary file in the same directory and renamed into place, so a file
//! is either complete or absent.

use crate::error::CliError;
use std::io::Write;
use std::path::{Path, PathBuf};

/// A checked output directory.
#[derive(Debug, Clone)]
pub struct OutDir {
    path: PathBuf,
}

impl OutDir {
    /// Checks that `path` is, or can be created as, a writable directory:
    /// an existing directory must accept a new file; otherwise its nearest
    /// existing ancestor must be a directory that accepts one. Nothing is
    /// created.
    pub fn check(path: &Path) -> Result<OutDir, CliError> {
        let fail = |why: String| {
            CliError::Usage(format!(
                "cannot write output directory {}: {why}",
                path.display()
            ))
        };
        let mut probe_dir = path.to_path_buf();
        loop {
            match std::fs::metadata(&probe_dir) {
                Ok(m) if m.is_dir() => break,
                Ok(_) => return Err(fail(format!("{} is not a directory", probe_dir.display()))),
                Err(_) => match probe_dir.parent() {
                    Some(p) if !p.as_os_str().is_empty() => probe_dir = p.to_path_buf(),
                    _ => {
                        probe_dir = PathBuf::from(".");
                        break;
                    }
                },
            }
        }
        tempfile::NamedTempFile::new_in(&probe_dir).map_err(|e| {
            fail(format!(
                "{} does not accept new files ({e})",
                probe_dir.display()
            ))
        })?;
        Ok(OutDir {
            path: path.to_path_buf(),
        })
    }

    /// The directory's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Creates the directory (and parents) and writes every `(name, bytes)`
    /// file atomically.
    pub fn write_all(&self, files: &[(String, Vec<u8>)]) -> anyhow::Result<()> {
        std::fs::create_dir_all(&self.path)
            .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", self.path.display()))?;
        for (name, bytes) in files {
            write_atomic(&self.path.join(name), bytes)?;
        }
        Ok(())
    }
}

/// Writes `bytes` to `path` through a temporary file in the same directory
/// and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut tmp = tempfile::NamedTempFile::new_in(dir)
        .map_err(|e| anyhow::anyhow!("cannot write in {}: {e}", dir.display()))?;
    tmp.write_all(bytes)
        .and_then(|_| tmp.flush())
        .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
    tmp.persist(path)
        .map_err(|e| anyhow::anyhow!("cannot write {}: {}", path.display(), e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_creates_nothing_and_write_all_creates_everything() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("a/b");
        let out = OutDir::check(&target).unwrap();
        assert!(!target.exists(), "check must not create the directory");
        out.write_all(&[
            ("x.txt".into(), b"hello".to_vec()),
            ("y.txt".into(), b"world".to_vec()),
        ])
        .unwrap();
        assert_eq!(std::fs::read(target.join("x.txt")).unwrap(), b"hello");
        // Only the two files: no temporary left.
        assert_eq!(std::fs::read_dir(&target).unwrap().count(), 2);
    }

    #[test]
    fn a_file_in_the_way_is_refused() {
        let root = tempfile::tempdir().unwrap();
        let file = root.path().join("f");
        std::fs::write(&file, b"").unwrap();
        let e = OutDir::check(&file.join("sub")).unwrap_err();
        assert!(e.to_string().contains("is not a directory"), "{e}");
    }
}
