//! Where a test finds the workspace's binaries: in the profile directory
//! above the test executable (`target/<profile>/deps/<test>` →
//! `target/<profile>/`), where `cargo test --workspace` builds them.

use std::path::{Path, PathBuf};

/// `target/<profile>/<name>` for the running test executable; panics if it
/// was not built (the end-to-end tests need the other packages' binaries:
/// `cargo test --workspace` builds them).
pub fn test_bin(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    let dir = exe.parent().and_then(Path::parent).expect("target dir");
    let p = dir.join(name);
    assert!(
        p.exists(),
        "{} not built: run the tests with `cargo test --workspace`",
        p.display()
    );
    p
}
