//! The supervisor's iceoryx2 *domain*: where its services live, who may open
//! them, and how its peers find it.
//!
//! # Why a domain per start
//!
//! iceoryx2 0.10 names every file after `global.prefix` and keeps shared
//! memory in `/dev/shm`, which every local user may write to; its per-domain
//! node counter (`…_node.0_10_0.global_mgmt`) is even created mode 0666 on
//! purpose, and a truncated one makes every later node creation hang. With a
//! fixed, guessable prefix another user can plant or truncate that file, or
//! create the services first and feed the machine forged frames. So:
//!
//! * **Unpredictable names.** Each supervisor start draws a random domain id
//!   and a 128-bit session key. iceoryx2's file prefix is
//!   `{service_prefix}.{id}.` — `.` never occurs in a service prefix, so two
//!   prefixes never share files, and nobody can create our files before we do.
//! * **A private runtime directory** (`/run/motion` for root and for the
//!   user that owns it, else `/tmp/motion-<uid>`; `[supervisor]
//!   runtime_dir`) is iceoryx2's root
//!   (service and node files, event sockets). It must be a real directory
//!   owned by us and writable by nobody else, or we refuse to start: a
//!   directory another user created first is never used.
//! * **The session file** `{runtime_dir}/{prefix}.session` (0600, created
//!   exclusively) tells peers the domain id, the key and the supervisor's pid.
//!   Only the supervisor's user can read it; peers (motion-io, motionctl,
//!   Python clients) join the domain through it and put the key in every
//!   frame and request; the supervisor refuses what lacks it, and so do they.
//! * **The node counter** is checked before any node is created (a regular
//!   16-byte file of our own, else refuse: no hang) and set to 0600 right after
//!   the supervisor's node made it.
//! * **Stale state** of a supervisor that died (its session file, dead nodes,
//!   its node counter) is removed at the next start; a live one is refused.
//!
//! What this does not stop: a process running as the *same* user can read
//! the session file and so act as a peer. It could as well ptrace or kill
//! the supervisor; the boundary is the user id.
//!
//! Where each part lives: the directory policy in [`crate::dir`], the session
//! file in [`crate::session`], liveness in [`crate::liveness`], node creation
//! and the node counter in [`crate::node`], the `/dev/shm` listing in
//! [`crate::shm`] and its clean-up in [`crate::cleanup`]. This file holds the
//! [`Domain`] itself and how it maps onto iceoryx2's configuration.

use std::os::unix::ffi::OsStrExt;
use std::path::{Path, PathBuf};

use iceoryx2::config::Config;
use iceoryx2::prelude::{FileName, SemanticString};

use crate::error::IpcError;

/// The session of one supervisor start: everything a peer needs to reach it.
#[derive(Clone, PartialEq, Eq)]
pub struct Domain {
    /// `service_prefix` (first part of every service name).
    pub prefix: String,
    /// The private directory holding the session file and iceoryx2's files.
    pub runtime_dir: PathBuf,
    /// Random per supervisor start, 8 hex digits.
    pub id: String,
    /// The session key every frame and request carries.
    pub key: [u64; 2],
    /// The supervisor's process id.
    pub pid: u32,
}

impl std::fmt::Debug for Domain {
    /// Never prints the key.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Domain")
            .field("prefix", &self.prefix)
            .field("runtime_dir", &self.runtime_dir)
            .field("id", &self.id)
            .field("pid", &self.pid)
            .finish_non_exhaustive()
    }
}

impl Domain {
    /// A domain of `prefix` with a given id, for cleaning up what a dead
    /// supervisor left (no key).
    pub(crate) fn stale(prefix: &str, dir: &Path, id: &str) -> Domain {
        Domain {
            prefix: prefix.to_string(),
            runtime_dir: dir.to_path_buf(),
            id: id.to_string(),
            key: [0; 2],
            pid: 0,
        }
    }

    /// Prefix of every file iceoryx2 creates for this domain:
    /// `{service_prefix}.{id}.`.
    pub fn file_prefix(&self) -> String {
        format!("{}.{}.", self.prefix, self.id)
    }

    /// The iceoryx2 config: `Config::default()` (no `iceoryx2.toml` is read),
    /// `global.prefix` = [`Self::file_prefix`], root = the runtime directory.
    pub fn iceoryx2_config(&self) -> Result<Config, IpcError> {
        let mut cfg = Config::default();
        let fp = self.file_prefix();
        cfg.global.prefix = FileName::new(fp.as_bytes()).map_err(|e| {
            IpcError::Config(format!(
                "the file prefix {fp:?} is not accepted by iceoryx2 ({e:?})"
            ))
        })?;
        let mut bytes = self.runtime_dir.as_os_str().as_bytes().to_vec();
        if !bytes.ends_with(b"/") {
            bytes.push(b'/');
        }
        let path = iceoryx2::prelude::Path::new(&bytes).map_err(|e| {
            IpcError::Config(format!(
                "runtime directory {} is not usable by iceoryx2 ({e:?})",
                self.runtime_dir.display()
            ))
        })?;
        cfg.global.set_root_path(&path);
        Ok(cfg)
    }
}
