//! Where a bench finds the binaries it runs: the workspace's next to its
//! own executable (`target/release/`), or as given; other tools
//! (cyclictest, stress-ng) in `$PATH`.

use std::path::{Path, PathBuf};

/// `motion-supervisor`, `motion-io` and `motionctl`.
#[derive(Clone, Debug)]
pub struct Binaries {
    pub supervisor: PathBuf,
    pub io: PathBuf,
    pub motionctl: PathBuf,
}

impl Binaries {
    /// `motion-supervisor` as given or next to this binary, `motion-io`
    /// (`$MOTION_IO_BIN`, else beside the supervisor) and `motionctl`
    /// beside it; every one must be an executable file.
    pub fn find(supervisor: Option<&Path>) -> Result<Self, String> {
        let supervisor = match supervisor {
            Some(p) => p.to_path_buf(),
            None => beside_this_exe("motion-supervisor").ok_or_else(|| {
                "motion-supervisor not found next to this binary; build it first: \
                 `cargo build --release --workspace --bins` (with the same CARGO_TARGET_DIR), \
                 or pass --supervisor PATH"
                    .to_string()
            })?,
        };
        let io = std::env::var_os("MOTION_IO_BIN")
            .map(PathBuf::from)
            .unwrap_or_else(|| supervisor.with_file_name("motion-io"));
        let motionctl = supervisor.with_file_name("motionctl");
        for p in [&supervisor, &io, &motionctl] {
            if !is_executable(p) {
                return Err(format!(
                    "{} is not an executable file (build the workspace's binaries: \
                     `cargo build --release --workspace --bins`)",
                    p.display()
                ));
            }
        }
        Ok(Self {
            supervisor,
            io,
            motionctl,
        })
    }
}

/// A regular file with an execute bit.
pub fn is_executable(p: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    std::fs::metadata(p).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}

/// `name` in a directory of `$PATH`.
pub fn find_in_path(name: &str) -> Option<PathBuf> {
    let dirs = std::env::var_os("PATH")?;
    std::env::split_paths(&dirs).find_map(|d| {
        let p = d.join(name);
        is_executable(&p).then_some(p)
    })
}

/// `name` next to the running executable, if it is an executable file.
pub fn beside_this_exe(name: &str) -> Option<PathBuf> {
    let p = std::env::current_exe().ok()?.with_file_name(name);
    is_executable(&p).then_some(p)
}
