//! Helpers shared by the integration tests: an isolated iceoryx2 domain per
//! test (unique service prefix AND unique root directory) and leftover checks.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};

use iceoryx2::prelude::ipc;
use motion_frames::IpcConfig;

static COUNTER: AtomicU32 = AtomicU32::new(0);

pub struct TestEnv {
    pub cfg: IpcConfig,
    pub root: PathBuf,
}

impl TestEnv {
    /// Fresh domain: prefix `mf{tag}{pid}x{n}`, root `$TMPDIR/mf-{tag}-{pid}-{n}`.
    pub fn new(tag: &str) -> Self {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let pid = std::process::id();
        let root = std::env::temp_dir().join(format!("mf-{tag}-{pid}-{n}"));
        std::fs::create_dir_all(&root).unwrap();
        Self {
            cfg: IpcConfig::new(format!("mf{tag}{pid}x{n}")).with_root(&root),
            root,
        }
    }

    /// Same domain as another process announced through the environment.
    pub fn from_parts(prefix: String, root: PathBuf) -> Self {
        Self {
            cfg: IpcConfig::new(prefix).with_root(&root),
            root,
        }
    }

    /// Files in /dev/shm that belong to this domain.
    pub fn shm_files(&self) -> Vec<String> {
        self.cfg.shm_files()
    }

    /// Regular files (not directories) anywhere under the root directory.
    pub fn root_files(&self) -> Vec<PathBuf> {
        let mut out = Vec::new();
        collect_files(&self.root, &mut out);
        out
    }

    /// Checks that dropping every port and node left nothing behind except
    /// iceoryx2's persistent per-domain node counter (`*.global_mgmt`, created
    /// by design on the first node of a domain and never removed by iceoryx2),
    /// then removes that one segment and the root directory.
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
        println!(
            "cleanup check: /dev/shm entries of {:?} after drop: {:?} (only the persistent \
             node-counter segment is expected); files under root: {}",
            self.cfg.file_prefix(),
            shm,
            files.len()
        );
        self.remove_domain();
        let left = self.shm_files();
        assert!(left.is_empty(), "still in /dev/shm: {left:?}");
    }

    /// Best-effort removal of the domain's persistent segment and root directory.
    fn remove_domain(&self) {
        if let Ok(icfg) = self.cfg.iceoryx2_config() {
            // SAFETY: only called when no process uses this test-private domain.
            unsafe {
                let _ = iceoryx2::testing::remove_global_mgmt_segment::<ipc::Service>(&icfg);
            }
        }
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
