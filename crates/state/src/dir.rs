//! The state directory: created private (0700) if missing, refused when it
//! is not ours or others can write to it — a reference planted there by
//! another user would home a machine at the wrong place.

use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum StateError {
    #[error("state_dir {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("state_dir {path}: {why}")]
    Unsafe { path: PathBuf, why: String },
}

/// A checked state directory.
#[derive(Clone, Debug)]
pub struct StateDir {
    path: PathBuf,
}

impl StateDir {
    /// Creates `path` (and missing parents, 0700) and checks it: a real
    /// directory (not a symlink), owned by this user, not writable by group
    /// or others.
    pub fn open(path: &Path) -> Result<Self, StateError> {
        let io = |source| StateError::Io {
            path: path.to_path_buf(),
            source,
        };
        if !path.exists() {
            std::fs::DirBuilder::new()
                .recursive(true)
                .mode(0o700)
                .create(path)
                .map_err(io)?;
        }
        let m = std::fs::symlink_metadata(path).map_err(io)?;
        let unsafe_ = |why: String| StateError::Unsafe {
            path: path.to_path_buf(),
            why,
        };
        if m.file_type().is_symlink() {
            return Err(unsafe_("is a symbolic link".into()));
        }
        if !m.is_dir() {
            return Err(unsafe_("is not a directory".into()));
        }
        let me = nix::unistd::geteuid().as_raw();
        if m.uid() != me {
            return Err(unsafe_(format!(
                "is owned by uid {}, not by this process's uid {me}",
                m.uid()
            )));
        }
        let mode = m.permissions().mode() & 0o7777;
        if mode & 0o022 != 0 {
            return Err(unsafe_(format!(
                "mode {mode:o}: group or others may write to it (chmod go-w)"
            )));
        }
        Ok(Self {
            path: path.to_path_buf(),
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// A file inside the directory.
    pub fn file(&self, name: &str) -> PathBuf {
        self.path.join(name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn creates_a_private_directory() {
        let t = tempfile::tempdir().unwrap();
        let p = t.path().join("a/b");
        let d = StateDir::open(&p).unwrap();
        let mode = std::fs::metadata(d.path()).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o700);
    }

    #[test]
    fn refuses_a_directory_others_can_write() {
        let t = tempfile::tempdir().unwrap();
        std::fs::set_permissions(t.path(), std::fs::Permissions::from_mode(0o777)).unwrap();
        let e = StateDir::open(t.path()).unwrap_err().to_string();
        assert!(e.contains("group or others may write"), "{e}");
    }

    #[test]
    fn refuses_a_symlink_and_a_file() {
        let t = tempfile::tempdir().unwrap();
        let real = t.path().join("real");
        std::fs::create_dir(&real).unwrap();
        let link = t.path().join("link");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        assert!(StateDir::open(&link)
            .unwrap_err()
            .to_string()
            .contains("symbolic link"));
        let file = t.path().join("file");
        std::fs::write(&file, "x").unwrap();
        assert!(StateDir::open(&file)
            .unwrap_err()
            .to_string()
            .contains("not a directory"));
    }
}
