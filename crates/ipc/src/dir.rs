//! The runtime directory: iceoryx2's root and the session file's home. It
//! must be a real directory owned by this user and writable by nobody else;
//! one another user created first is never used (see [`crate::domain`]).

use std::fs::DirBuilder;
use std::os::unix::fs::{DirBuilderExt, MetadataExt};
use std::path::{Path, PathBuf};

use motion_config::args::RUNTIME_DIR_MAX;

use crate::error::IpcError;

/// This process's effective user id: the owner every file of the domain must have.
pub(crate) fn euid() -> u32 {
    nix::unistd::geteuid().as_raw()
}

/// The system runtime directory: the package's tmpfiles entry creates it at
/// boot, owned by the daemon's user `motion`.
const SYSTEM_RUNTIME_DIR: &str = "/run/motion";

/// The default runtime directory: `/run/motion` for root, and for the user
/// that owns it (the packaged daemon's user `motion`: so that
/// `sudo -u motion motionctl status` finds the daemon the units started
/// without a `--runtime-dir`); else `/tmp/motion-<uid>`.
pub fn default_runtime_dir() -> PathBuf {
    match euid() {
        0 => PathBuf::from(SYSTEM_RUNTIME_DIR),
        uid if owned_by(Path::new(SYSTEM_RUNTIME_DIR), uid) => PathBuf::from(SYSTEM_RUNTIME_DIR),
        uid => PathBuf::from(format!("/tmp/motion-{uid}")),
    }
}

/// `dir` is a real directory (not a symlink) owned by `uid`. Whether it is
/// private enough is [`check_private_dir`]'s judgement, made before use.
fn owned_by(dir: &Path, uid: u32) -> bool {
    std::fs::symlink_metadata(dir).is_ok_and(|m| m.is_dir() && m.uid() == uid)
}

/// `dir`, or the default.
pub fn runtime_dir_or_default(dir: Option<&Path>) -> PathBuf {
    dir.map_or_else(default_runtime_dir, Path::to_path_buf)
}

/// Creates the runtime directory (0700) if missing, then insists it is a
/// real directory (not a symlink), owned by this user and writable by nobody
/// else.
pub fn ensure_private_dir(dir: &Path) -> Result<(), IpcError> {
    let shown = dir.display();
    if dir.as_os_str().len() > RUNTIME_DIR_MAX {
        return Err(IpcError::Unsafe(format!(
            "runtime directory {shown} is longer than {RUNTIME_DIR_MAX} characters (iceoryx2's \
             socket paths below it are limited): choose a shorter runtime_dir"
        )));
    }
    match DirBuilder::new().mode(0o700).create(dir) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
        Err(e) => {
            return Err(IpcError::Unsafe(format!(
                "cannot create the runtime directory {shown}: {e}"
            )))
        }
    }
    check_private_dir(dir)
}

/// The checks of [`ensure_private_dir`] on an existing directory.
pub fn check_private_dir(dir: &Path) -> Result<(), IpcError> {
    let shown = dir.display();
    let m = std::fs::symlink_metadata(dir)
        .map_err(|e| IpcError::Unsafe(format!("runtime directory {shown}: {e}")))?;
    if m.file_type().is_symlink() || !m.is_dir() {
        return Err(IpcError::Unsafe(format!(
            "runtime directory {shown} is not a directory (a symlink or a file): refusing it"
        )));
    }
    if m.uid() != euid() {
        return Err(IpcError::Unsafe(format!(
            "runtime directory {shown} belongs to uid {}, not to this user ({}): another user \
             created it first; remove it or choose another runtime_dir",
            m.uid(),
            euid()
        )));
    }
    if m.mode() & 0o022 != 0 {
        return Err(IpcError::Unsafe(format!(
            "runtime directory {shown} is writable by group or others (mode {:o}); it must be \
             0700 or 0750",
            m.mode() & 0o7777
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::os::unix::fs::PermissionsExt;

    use super::*;
    use crate::test_dir as dir;

    #[test]
    fn a_runtime_dir_someone_else_could_write_is_refused() {
        let d = dir("a");
        let _ = std::fs::remove_dir_all(&d);
        ensure_private_dir(&d).unwrap();
        assert_eq!(std::fs::metadata(&d).unwrap().mode() & 0o777, 0o700);
        std::fs::set_permissions(&d, std::fs::Permissions::from_mode(0o777)).unwrap();
        assert!(ensure_private_dir(&d)
            .unwrap_err()
            .to_string()
            .contains("writable by group or others"));
        std::fs::remove_dir_all(&d).unwrap();
        let target = dir("t");
        std::fs::create_dir_all(&target).unwrap();
        std::os::unix::fs::symlink(&target, &d).unwrap();
        assert!(ensure_private_dir(&d)
            .unwrap_err()
            .to_string()
            .contains("not a directory"));
        std::fs::remove_file(&d).unwrap();
        std::fs::remove_dir_all(&target).unwrap();
        assert!(
            ensure_private_dir(Path::new("/tmp/a-runtime-dir-name-too-long"))
                .unwrap_err()
                .to_string()
                .contains("longer than")
        );
    }
}
