//! Leaving nothing behind in `/dev/shm`.
//!
//! Dropping every port and node removes a domain's shared memory, except one
//! small segment iceoryx2 0.10 keeps by design per domain: the node counter
//! `{file prefix}<hash>_node.0_10_0.global_mgmt`. Resources of a process that
//! died (kill -9) stay until someone cleans its dead node. [`cleanup_domain`],
//! called by each process after it dropped its node, does both.

use std::path::Path;
use std::time::Duration;

use iceoryx2::node::{Node, NodeState};
use iceoryx2::prelude::{ipc, CallbackProgression, SemanticString};
use iceoryx2_bb_posix::shared_memory::SharedMemory;

use crate::domain::Domain;

/// What [`cleanup_domain`] found and did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CleanupReport {
    /// Nodes of the domain whose process is alive (e.g. the peer still runs).
    pub alive: usize,
    /// Dead nodes (process gone without cleaning up, e.g. after `kill -9`)
    /// whose stale resources were removed now.
    pub dead_cleaned: usize,
    /// Dead nodes whose resources could not be removed.
    pub dead_failed: usize,
    /// Nodes whose state could not be determined (another user's, or a node
    /// caught half-created). Counted as alive: the domain is not torn down.
    pub unknown: usize,
    /// The domain's node-counter segment was removed.
    pub removed_global_mgmt: bool,
    /// Why the domain could not be inspected or the segment not removed.
    pub error: Option<String>,
}

impl CleanupReport {
    /// True if nothing of the domain is known to remain.
    pub fn domain_gone(&self) -> bool {
        self.alive == 0 && self.unknown == 0 && self.dead_failed == 0 && self.error.is_none()
    }
}

impl std::fmt::Display for CleanupReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} live node(s), {} dead node(s) cleaned",
            self.alive + self.unknown,
            self.dead_cleaned
        )?;
        if self.dead_failed > 0 {
            write!(f, ", {} dead node(s) NOT cleaned", self.dead_failed)?;
        }
        if self.removed_global_mgmt {
            write!(f, ", node-counter segment removed")?;
        }
        if let Some(e) = &self.error {
            write!(f, "; {e}")?;
        }
        Ok(())
    }
}

/// How long [`cleanup_domain`] waits for another process that is cleaning up
/// the same dead node at the same moment.
const CLEANUP_WAIT: Duration = Duration::from_millis(200);

/// Tidies `domain` on the way out. Call it after this process dropped all its
/// ports and its node; it creates nothing.
///
/// 1. Lists the nodes of the domain (`Node::list`).
/// 2. Removes the stale resources of every dead node.
/// 3. If no live (or undeterminable) node remains and every dead one was
///    cleaned, removes the domain's node-counter segment (by name, with the
///    public `SharedMemory::remove`: iceoryx2 0.10 has no API for it outside
///    its `testing` module). After that nothing of the domain is left in
///    `/dev/shm`.
///
/// The race: a node created in the same domain between steps 1 and 3 keeps
/// its mapping and works; only a node *being created* at that instant can
/// fail, and reports it. The window exists only while the domain has no live
/// node at all; the domain id is random per supervisor start, so in practice
/// only the domain's own last process can be there.
///
/// Never panics; failures are reported in [`CleanupReport::error`].
pub fn cleanup_domain(domain: &Domain) -> CleanupReport {
    let mut report = CleanupReport::default();
    let icfg = match domain.iceoryx2_config() {
        Ok(c) => c,
        Err(e) => {
            report.error = Some(e.to_string());
            return report;
        }
    };
    let listed = Node::<ipc::Service>::list(&icfg, |state| {
        match state {
            NodeState::Alive(_) => report.alive += 1,
            NodeState::Dead(dead) => match dead.blocking_remove_stale_resources(CLEANUP_WAIT) {
                Ok(()) => report.dead_cleaned += 1,
                Err(_) => report.dead_failed += 1,
            },
            NodeState::Inaccessible(_) | NodeState::Undefined(_) => report.unknown += 1,
        }
        CallbackProgression::Continue
    });
    if let Err(e) = listed {
        report.error = Some(format!(
            "cannot list the nodes of the iceoryx2 domain {:?} (iceoryx2: {e:?})",
            domain.file_prefix()
        ));
        return report;
    }
    if !report.domain_gone() {
        return report;
    }
    match remove_global_mgmt(&domain.file_prefix()) {
        Ok(removed) => report.removed_global_mgmt = removed,
        Err(e) => report.error = Some(e),
    }
    report
}

/// Removes the node-counter segment of the domain with file prefix `prefix`.
fn remove_global_mgmt(prefix: &str) -> Result<bool, String> {
    let mut removed = false;
    for name in SharedMemory::list() {
        let n = name.as_bytes();
        let n = String::from_utf8_lossy(n);
        if n.starts_with(prefix) && n.ends_with(".global_mgmt") {
            removed |= SharedMemory::remove(&name).map_err(|e| {
                format!("cannot remove the node-counter segment {n} (iceoryx2: {e:?})")
            })?;
        }
    }
    Ok(removed)
}

/// Cleans every domain of `prefix` found in `/dev/shm` that has no live node
/// (what supervisors of this prefix that died left behind). Domains with a
/// live node are left alone.
pub fn cleanup_stale_domains(prefix: &str, runtime_dir: &Path) {
    let mut ids: Vec<String> = Domain::shm_files_of_prefix(prefix)
        .iter()
        .filter_map(|n| n[prefix.len() + 1..].split('.').next().map(str::to_string))
        .collect();
    ids.sort();
    ids.dedup();
    for id in ids {
        let _ = cleanup_domain(&Domain::stale(prefix, runtime_dir, &id));
    }
}
