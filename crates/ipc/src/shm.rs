//! A domain's files in `/dev/shm`: what is there while it runs, and what
//! must be gone once every process of it has left.

use crate::domain::Domain;

impl Domain {
    /// This domain's files in `/dev/shm`, sorted.
    pub fn shm_files(&self) -> Vec<String> {
        list_shm(&self.file_prefix())
    }

    /// Every file of every domain of `prefix` in `/dev/shm` (what must be
    /// empty once every process of the prefix has gone).
    pub fn shm_files_of_prefix(prefix: &str) -> Vec<String> {
        list_shm(&format!("{prefix}."))
    }
}

/// The names in `/dev/shm` that start with `prefix`, sorted.
fn list_shm(prefix: &str) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir("/dev/shm")
        .map(|rd| {
            rd.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with(prefix))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}
