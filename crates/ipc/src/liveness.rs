//! Whether a session's supervisor still runs: a session file or a domain of
//! a supervisor that died is stale and may be removed; a live one is refused.

use std::path::Path;

use iceoryx2::node::{Node, NodeState};
use iceoryx2::prelude::{ipc, CallbackProgression};

use crate::domain::Domain;

/// Whether process `pid` exists.
pub(crate) fn process_alive(pid: u32) -> bool {
    pid > 0 && Path::new(&format!("/proc/{pid}")).exists()
}

/// Whether the session `old` still has its supervisor: the process exists
/// and is a motion-supervisor, or its domain has a live node (a test
/// harness or benchmark playing the supervisor). A pid reused by an
/// unrelated program does not count.
pub(crate) fn session_alive(old: &Domain) -> bool {
    if !process_alive(old.pid) {
        return false;
    }
    let is_supervisor = std::fs::read(format!("/proc/{}/cmdline", old.pid))
        .map(|c| {
            let argv0 = c.split(|&b| b == 0).next().unwrap_or_default();
            argv0.ends_with(b"motion-supervisor")
        })
        .unwrap_or(false);
    is_supervisor || live_nodes(old) > 0
}

/// Nodes of `domain` whose process is alive (or undeterminable).
pub(crate) fn live_nodes(domain: &Domain) -> usize {
    let Ok(icfg) = domain.iceoryx2_config() else {
        return 0;
    };
    let mut n = 0;
    let _ = Node::<ipc::Service>::list(&icfg, |state| {
        if !matches!(state, NodeState::Dead(_)) {
            n += 1;
        }
        CallbackProgression::Continue
    });
    n
}
