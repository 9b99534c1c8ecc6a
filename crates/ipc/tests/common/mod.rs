//! Helpers shared by the integration tests: a private domain per test (unique
//! service prefix AND runtime directory) and leftover checks.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};

use motion_ipc::{cleanup_domain, Domain};

static COUNTER: AtomicU32 = AtomicU32::new(0);

pub struct TestEnv {
    pub domain: Domain,
    pub root: PathBuf,
}

impl TestEnv {
    /// Fresh domain: prefix `mf{tag}{pid}x{n}`, runtime dir `/tmp/mf{pid}_{n}`
    /// (short: iceoryx2's socket paths below it are limited).
    pub fn new(tag: &str) -> Self {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let pid = std::process::id();
        let root = PathBuf::from(format!("/tmp/mf{}_{n}", pid % 1_000_000));
        let _ = std::fs::remove_dir_all(&root);
        let domain = Domain::establish(&format!("mf{tag}{pid}x{n}"), Some(&root)).unwrap();
        Self { domain, root }
    }

    /// Same domain as another process announced through the environment.
    pub fn from_parts(prefix: String, root: PathBuf) -> Self {
        Self {
            domain: Domain::read_session(&root, &prefix).unwrap(),
            root,
        }
    }

    /// Files in /dev/shm that belong to this domain.
    pub fn shm_files(&self) -> Vec<String> {
        self.domain.shm_files()
    }

    /// Regular files (not directories) under the runtime directory, except
    /// the session file.
    pub fn root_files(&self) -> Vec<PathBuf> {
        let mut out = Vec::new();
        collect_files(&self.root, &mut out);
        out.retain(|p| p.extension().is_none_or(|e| e != "session"));
        out
    }

    /// Checks that dropping every port and node left nothing behind except
    /// iceoryx2's persistent per-domain node counter (`*.global_mgmt`), then
    /// removes that one with `cleanup_domain` (which must leave nothing).
    ///
    /// Must only be called when no process uses the domain any more.
    pub fn assert_clean_and_remove(&self) {
        let shm = self.shm_files();
        let unexpected: Vec<_> = shm
            .iter()
            .filter(|f| !f.ends_with(".global_mgmt"))
            .collect();
        assert!(
            unexpected.is_empty(),
            "iceoryx2 left shared memory behind: {unexpected:?}"
        );
        let files = self.root_files();
        assert!(
            files.is_empty(),
            "iceoryx2 left files under {}: {files:?}",
            self.root.display()
        );
        let report = cleanup_domain(&self.domain);
        assert!(report.domain_gone(), "{report}");
        let left = self.shm_files();
        assert!(left.is_empty(), "still in /dev/shm: {left:?}");
    }

    fn remove_domain(&self) {
        let _ = cleanup_domain(&self.domain);
        self.domain.withdraw();
        let _ = std::fs::remove_dir_all(&self.root);
    }
}

impl Drop for TestEnv {
    /// Also on a failed test (ports and nodes are declared after the env, so
    /// they are gone by now).
    fn drop(&mut self) {
        self.remove_domain();
    }
}

fn collect_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    for e in rd.flatten() {
        let p = e.path();
        match e.file_type() {
            Ok(t) if t.is_dir() => collect_files(&p, out),
            Ok(_) => out.push(p),
            Err(_) => {}
        }
    }
}
