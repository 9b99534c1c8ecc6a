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
//! * **A private runtime directory** (`/run/motion` for root, else
//!   `/tmp/motion-<uid>`; `[supervisor] runtime_dir`) is iceoryx2's root
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

use std::fs::{DirBuilder, File, OpenOptions};
use std::io::{Read, Write};
use std::os::unix::ffi::OsStrExt;
use std::os::unix::fs::{DirBuilderExt, MetadataExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};

use iceoryx2::config::Config;
use iceoryx2::node::{Node, NodeBuilder};
use iceoryx2::prelude::{ipc, FileName, NodeName, SemanticString, SignalHandlingMode};
use serde::{Deserialize, Serialize};

use crate::error::IpcError;
use crate::frame::LAYOUT_VERSION;

/// Longest runtime directory path: iceoryx2 puts its event sockets directly
/// in it, named `{file prefix}{40 hex}.event`, and a unix socket path has at
/// most 107 bytes. With a 32-character service prefix that leaves 19.
pub const RUNTIME_DIR_MAX: usize = 19;
/// Largest session file accepted.
const SESSION_FILE_MAX: u64 = 4096;
/// Suffix of iceoryx2's per-domain node counter segment.
const GLOBAL_MGMT_SUFFIX: &str = "_node.0_10_0.global_mgmt";
/// Name of iceoryx2's per-domain node counter segment after the file prefix:
/// the SHA-1 (hex) of its type name
/// `iceoryx2::node::global_management_segment::State`, `_node`, the package
/// version, `.global_mgmt` (iceoryx2-cal's `path_for_with_type`). A test
/// checks that iceoryx2 0.10 creates exactly this name.
const GLOBAL_MGMT_NAME: &str = "9204dd183d1c4d8e1ff592a30766ffa6765aa8b5_node.0_10_0.global_mgmt";
/// Size of a healthy node counter segment.
const GLOBAL_MGMT_SIZE: u64 = 16;
/// iceoryx2's package version as its dynamic storages record it in their
/// first 8 bytes: `major << 32 | minor << 16 | patch` (0.10.0).
const ICEORYX2_VERSION_WORD: u64 = 10 << 16;

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

/// The session file's content.
#[derive(Serialize, Deserialize)]
struct SessionFile {
    /// Format of this file.
    format: u32,
    prefix: String,
    id: String,
    /// 32 hex digits.
    key: String,
    pid: u32,
    /// Frame layout the supervisor speaks.
    layout: u32,
}

fn euid() -> u32 {
    nix::unistd::geteuid().as_raw()
}

/// The default runtime directory: `/run/motion` for root (systemd's
/// `RuntimeDirectory=motion`), else `/tmp/motion-<uid>`.
pub fn default_runtime_dir() -> PathBuf {
    match euid() {
        0 => PathBuf::from("/run/motion"),
        uid => PathBuf::from(format!("/tmp/motion-{uid}")),
    }
}

/// `dir`, or the default.
pub fn runtime_dir_or_default(dir: Option<&Path>) -> PathBuf {
    dir.map_or_else(default_runtime_dir, Path::to_path_buf)
}

/// `{runtime_dir}/{prefix}.session`.
pub fn session_path(runtime_dir: &Path, prefix: &str) -> PathBuf {
    runtime_dir.join(format!("{prefix}.session"))
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

fn hex_key(key: [u64; 2]) -> String {
    format!("{:016x}{:016x}", key[0], key[1])
}

fn parse_key(s: &str) -> Option<[u64; 2]> {
    if s.len() != 32 || !s.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    Some([
        u64::from_str_radix(&s[..16], 16).ok()?,
        u64::from_str_radix(&s[16..], 16).ok()?,
    ])
}

fn valid_id(s: &str) -> bool {
    s.len() == 8 && s.bytes().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f'))
}

/// Whether process `pid` exists.
fn process_alive(pid: u32) -> bool {
    pid > 0 && Path::new(&format!("/proc/{pid}")).exists()
}

/// Whether the session `old` still has its supervisor: the process exists
/// and is a motion-supervisor, or its domain has a live node (a test
/// harness or benchmark playing the supervisor). A pid reused by an
/// unrelated program does not count.
fn session_alive(old: &Domain) -> bool {
    if !process_alive(old.pid) {
        return false;
    }
    let is_supervisor = std::fs::read(format!("/proc/{}/cmdline", old.pid))
        .map(|c| {
            let argv0 = c.split(|&b| b == 0).next().unwrap_or_default();
            argv0.ends_with(b"motion-supervisor")
        })
        .unwrap_or(false);
    is_supervisor || crate::cleanup::live_nodes(old) > 0
}

impl Domain {
    /// Supervisor side: claims `prefix` in `runtime_dir` (or the default).
    ///
    /// Refuses if a live supervisor holds the prefix; removes what a dead
    /// one left (session file, dead nodes, node counters); draws a fresh
    /// domain id and key; writes the session file exclusively (0600), so two
    /// supervisors starting at once cannot both succeed.
    pub fn establish(prefix: &str, runtime_dir: Option<&Path>) -> Result<Domain, IpcError> {
        let dir = runtime_dir_or_default(runtime_dir);
        ensure_private_dir(&dir)?;
        let path = session_path(&dir, prefix);
        match Self::read_session(&dir, prefix) {
            Ok(old) if old.pid != std::process::id() && session_alive(&old) => {
                return Err(IpcError::AlreadyRunning(format!(
                    "a motion-supervisor (pid {}) already runs with service prefix {prefix:?} \
                     (session file {})",
                    old.pid,
                    path.display()
                )));
            }
            Ok(_) | Err(IpcError::NoSupervisor(_)) => {}
            Err(e @ IpcError::Unsafe(_)) => return Err(e),
            Err(_) => {}
        }
        // Whatever is left is stale: remove the file (if it is a file we may
        // judge; `read_session` refused anything unsafe above) and the
        // domains of dead supervisors of this prefix.
        let _ = std::fs::remove_file(&path);
        crate::cleanup::cleanup_stale_domains(prefix, &dir);

        let mut bytes = [0u8; 20];
        getrandom::fill(&mut bytes)
            .map_err(|e| IpcError::Config(format!("no randomness for the session key: {e}")))?;
        let id = format!(
            "{:08x}",
            u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])
        );
        let k = |i: usize| {
            let mut b = [0u8; 8];
            b.copy_from_slice(&bytes[i..i + 8]);
            u64::from_le_bytes(b)
        };
        let d = Domain {
            prefix: prefix.to_string(),
            runtime_dir: dir,
            id,
            key: [k(4), k(12)],
            pid: std::process::id(),
        };
        let leftovers = d.shm_files();
        if !leftovers.is_empty() {
            return Err(IpcError::Unsafe(format!(
                "files of a domain that was just drawn at random already exist in /dev/shm \
                 ({}): refusing to use them",
                leftovers.join(", ")
            )));
        }
        d.write_session()?;
        Ok(d)
    }

    fn write_session(&self) -> Result<(), IpcError> {
        let path = session_path(&self.runtime_dir, &self.prefix);
        let content = SessionFile {
            format: 1,
            prefix: self.prefix.clone(),
            id: self.id.clone(),
            key: hex_key(self.key),
            pid: self.pid,
            layout: LAYOUT_VERSION,
        };
        let text = serde_json::to_string(&content).expect("plain struct serializes");
        let mut f = OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(0o600)
            .custom_flags(libc::O_NOFOLLOW)
            .open(&path)
            .map_err(|e| {
                if e.kind() == std::io::ErrorKind::AlreadyExists {
                    IpcError::AlreadyRunning(format!(
                        "another motion-supervisor claimed service prefix {:?} at the same \
                         moment ({})",
                        self.prefix,
                        path.display()
                    ))
                } else {
                    IpcError::Unsafe(format!("cannot write {}: {e}", path.display()))
                }
            })?;
        f.write_all(text.as_bytes())
            .and_then(|()| f.sync_all())
            .map_err(|e| IpcError::Unsafe(format!("cannot write {}: {e}", path.display())))
    }

    /// Supervisor side, on the way out: removes the session file if it is
    /// still this session's.
    pub fn withdraw(&self) {
        if let Ok(cur) = Self::read_session(&self.runtime_dir, &self.prefix) {
            if cur.id == self.id {
                let _ = std::fs::remove_file(session_path(&self.runtime_dir, &self.prefix));
            }
        }
    }

    /// Peer side, when the supervisor is gone: removes its session file if
    /// it still names this session and its process has ended (a supervisor
    /// killed with SIGKILL could not remove it itself).
    pub fn withdraw_if_dead(&self) {
        if !process_alive(self.pid) {
            self.withdraw();
        }
    }

    /// Peer side: the domain of the supervisor running under `prefix`, read
    /// from its session file. A missing file or a supervisor that is gone is
    /// [`IpcError::NoSupervisor`]; a file that is not safe to trust (another
    /// owner, readable by others, a symlink, too large, malformed) is
    /// [`IpcError::Unsafe`].
    pub fn join(prefix: &str, runtime_dir: Option<&Path>) -> Result<Domain, IpcError> {
        let dir = runtime_dir_or_default(runtime_dir);
        let d = Self::read_session(&dir, prefix)?;
        if !process_alive(d.pid) {
            return Err(IpcError::NoSupervisor(format!(
                "no motion-supervisor runs with service prefix {prefix:?}: its session file {} \
                 names pid {}, which has ended",
                session_path(&dir, prefix).display(),
                d.pid
            )));
        }
        Ok(d)
    }

    /// The session file of `prefix` in `dir`, checked like [`Self::join`] but
    /// without asking whether the supervisor still runs (for tools and tests).
    pub fn read_session(dir: &Path, prefix: &str) -> Result<Domain, IpcError> {
        let path = session_path(dir, prefix);
        let shown = path.display();
        let f = match OpenOptions::new()
            .read(true)
            .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
            .open(&path)
        {
            Ok(f) => f,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(IpcError::NoSupervisor(format!(
                    "no motion-supervisor runs with service prefix {prefix:?} (no session file \
                     {shown})"
                )))
            }
            Err(e) => return Err(IpcError::Unsafe(format!("cannot read {shown}: {e}"))),
        };
        let m = f
            .metadata()
            .map_err(|e| IpcError::Unsafe(format!("cannot read {shown}: {e}")))?;
        if !m.is_file() {
            return Err(IpcError::Unsafe(format!("{shown} is not a regular file")));
        }
        if m.uid() != euid() {
            return Err(IpcError::Unsafe(format!(
                "{shown} belongs to uid {}, not to this user ({}): not trusting it",
                m.uid(),
                euid()
            )));
        }
        if m.mode() & 0o077 != 0 {
            return Err(IpcError::Unsafe(format!(
                "{shown} is readable or writable by others (mode {:o}): not trusting it",
                m.mode() & 0o7777
            )));
        }
        if m.len() > SESSION_FILE_MAX {
            return Err(IpcError::Unsafe(format!("{shown} is too large")));
        }
        let mut text = String::new();
        f.take(SESSION_FILE_MAX)
            .read_to_string(&mut text)
            .map_err(|e| IpcError::Unsafe(format!("cannot read {shown}: {e}")))?;
        let s: SessionFile = serde_json::from_str(&text)
            .map_err(|e| IpcError::Unsafe(format!("{shown} is malformed: {e}")))?;
        let key = parse_key(&s.key);
        match key {
            Some(key) if s.prefix == prefix && valid_id(&s.id) && s.pid > 0 => {
                if s.layout != LAYOUT_VERSION {
                    return Err(IpcError::Config(format!(
                        "the supervisor under prefix {prefix:?} speaks frame layout {}, this \
                         binary {LAYOUT_VERSION}: rebuild both from the same tree",
                        s.layout
                    )));
                }
                Ok(Domain {
                    prefix: s.prefix,
                    runtime_dir: dir.to_path_buf(),
                    id: s.id,
                    key,
                    pid: s.pid,
                })
            }
            _ => Err(IpcError::Unsafe(format!(
                "{shown} is malformed (prefix, id, key or pid)"
            ))),
        }
    }

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

    /// This domain's files in `/dev/shm`, sorted.
    pub fn shm_files(&self) -> Vec<String> {
        list_shm(&self.file_prefix())
    }

    /// Every file of every domain of `prefix` in `/dev/shm` (what must be
    /// empty once every process of the prefix has gone).
    pub fn shm_files_of_prefix(prefix: &str) -> Vec<String> {
        list_shm(&format!("{prefix}."))
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

    /// Creates an iceoryx2 node in this domain, named `name`, with iceoryx2's
    /// signal handling disabled. Used by every program (supervisor, I/O
    /// process, motionctl, the control server).
    ///
    /// The domain's node counter, if it exists, must be a regular 16-byte
    /// file of this user (iceoryx2 would hang forever on a truncated one,
    /// and must never trust a planted one). If it does not exist, it is
    /// created here, 0600 from the start: iceoryx2 would create it itself and
    /// then `fchmod` it to 0666 so that other users may share a domain —
    /// exactly what must not happen here (and a umask cannot prevent an
    /// explicit `fchmod`). iceoryx2 then opens ours instead of creating one.
    pub fn create_node(&self, name: &str) -> Result<Node<ipc::Service>, IpcError> {
        check_private_dir(&self.runtime_dir)?;
        for f in self.global_mgmt_files() {
            check_global_mgmt(&f)?;
        }
        self.create_global_mgmt()?;
        let cfg = self.iceoryx2_config()?;
        let node_name = NodeName::new(name).map_err(|e| {
            IpcError::Config(format!(
                "node name {name:?} is not valid for iceoryx2 ({e:?})"
            ))
        })?;
        let node = NodeBuilder::new()
            .name(&node_name)
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .config(&cfg)
            .create::<ipc::Service>()
            .map_err(IpcError::Node)?;
        for f in self.global_mgmt_files() {
            restrict_global_mgmt(&f);
        }
        Ok(node)
    }

    /// Where iceoryx2 keeps this domain's node counter.
    fn global_mgmt_path(&self) -> PathBuf {
        Path::new("/dev/shm").join(format!("{}{GLOBAL_MGMT_NAME}", self.file_prefix()))
    }

    /// Creates the node counter as iceoryx2 would, but private: exclusively,
    /// write-only while it is initialized (iceoryx2's "not ready yet" sign
    /// for other openers), then the version word and a zero counter, then
    /// 0600 (iceoryx2's last step would be 0666). One that exists already
    /// (another node of the domain made it) is checked like any other.
    fn create_global_mgmt(&self) -> Result<(), IpcError> {
        let path = self.global_mgmt_path();
        let shown = path.display();
        let mut f = match OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(0o200)
            .custom_flags(libc::O_NOFOLLOW | libc::O_CLOEXEC)
            .open(&path)
        {
            Ok(f) => f,
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                return wait_global_mgmt(&path);
            }
            Err(e) => return Err(IpcError::Unsafe(format!("cannot create {shown}: {e}"))),
        };
        let mut content = [0u8; GLOBAL_MGMT_SIZE as usize];
        content[..8].copy_from_slice(&ICEORYX2_VERSION_WORD.to_ne_bytes());
        let done = f
            .write_all(&content)
            .and_then(|()| f.set_permissions(std::fs::Permissions::from_mode(0o600)));
        if let Err(e) = done {
            let _ = std::fs::remove_file(&path);
            return Err(IpcError::Unsafe(format!("cannot create {shown}: {e}")));
        }
        Ok(())
    }

    fn global_mgmt_files(&self) -> Vec<PathBuf> {
        self.shm_files()
            .into_iter()
            .filter(|n| n.ends_with(GLOBAL_MGMT_SUFFIX))
            .map(|n| Path::new("/dev/shm").join(n))
            .collect()
    }
}

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

/// A node counter segment is trusted only as a regular 16-byte file of ours.
fn check_global_mgmt(path: &Path) -> Result<(), IpcError> {
    let shown = path.display();
    let m = match std::fs::symlink_metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(IpcError::Unsafe(format!("{shown}: {e}"))),
    };
    if !m.is_file() {
        return Err(IpcError::Unsafe(format!(
            "{shown} is not a regular file: refusing to create an iceoryx2 node"
        )));
    }
    if m.uid() != euid() {
        return Err(IpcError::Unsafe(format!(
            "{shown} belongs to uid {}, not to this user: planted by someone else; refusing to \
             create an iceoryx2 node",
            m.uid()
        )));
    }
    if m.len() != GLOBAL_MGMT_SIZE {
        return Err(IpcError::Unsafe(format!(
            "{shown} has {} bytes instead of {GLOBAL_MGMT_SIZE} (truncated or overwritten): \
             iceoryx2 would hang or fail on it; stop every process of this prefix and start \
             the supervisor again",
            m.len()
        )));
    }
    Ok(())
}

/// A node counter that appeared between the check and the creation: another
/// node of this user may be writing it this very moment (it then becomes 16
/// bytes within microseconds); anything else is judged as usual.
fn wait_global_mgmt(path: &Path) -> Result<(), IpcError> {
    let until = std::time::Instant::now() + std::time::Duration::from_millis(200);
    loop {
        let r = check_global_mgmt(path);
        let young = matches!(
            std::fs::symlink_metadata(path),
            Ok(m) if m.is_file() && m.uid() == euid() && m.len() < GLOBAL_MGMT_SIZE
        );
        if r.is_ok() || !young || std::time::Instant::now() >= until {
            return r;
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
}

/// Takes group and other access off a node counter of ours that was not
/// made by [`Domain::create_global_mgmt`] (a domain created by other code).
fn restrict_global_mgmt(path: &Path) {
    if let Ok(f) = File::open(path) {
        if f.metadata().map(|m| m.uid() == euid()).unwrap_or(false) {
            let _ = f.set_permissions(std::fs::Permissions::from_mode(0o600));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(tag: &str) -> PathBuf {
        PathBuf::from(format!("/tmp/mdt{}{tag}", std::process::id() % 100_000))
    }

    #[test]
    fn keys_and_ids_round_trip() {
        let k = [0x0123_4567_89ab_cdef, 0xfedc_ba98_7654_3210];
        assert_eq!(parse_key(&hex_key(k)), Some(k));
        assert_eq!(parse_key("xyz"), None);
        assert!(valid_id("0a1b2c3d"));
        assert!(!valid_id("0A1B2C3D") && !valid_id("../../x"));
    }

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

    #[test]
    fn session_file_is_private_exclusive_and_checked() {
        let d = dir("s");
        let _ = std::fs::remove_dir_all(&d);
        let prefix = format!("dt{}", std::process::id());
        let a = Domain::establish(&prefix, Some(&d)).unwrap();
        let path = session_path(&d, &prefix);
        assert_eq!(std::fs::metadata(&path).unwrap().mode() & 0o777, 0o600);
        assert_eq!(a.file_prefix(), format!("{prefix}.{}.", a.id));
        // The session's process (this test) is alive: peers can join.
        assert_eq!(Domain::join(&prefix, Some(&d)).unwrap().id, a.id);
        let read = Domain::read_session(&d, &prefix).unwrap();
        assert_eq!((read.id.as_str(), read.key), (a.id.as_str(), a.key));
        // A session file readable by others is not trusted.
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o644)).unwrap();
        assert!(matches!(
            Domain::read_session(&d, &prefix),
            Err(IpcError::Unsafe(_))
        ));
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).unwrap();
        // A second start of the same process replaces its own session.
        let b = Domain::establish(&prefix, Some(&d)).unwrap();
        assert_ne!(a.id, b.id);
        assert_ne!(a.key, b.key);
        a.withdraw(); // not ours any more: stays
        assert!(path.exists());
        b.withdraw();
        assert!(!path.exists());
        std::fs::remove_dir_all(&d).unwrap();
    }

    fn raw_node(d: &Domain, name: &str) -> Node<ipc::Service> {
        NodeBuilder::new()
            .name(&NodeName::new(name).unwrap())
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .config(&d.iceoryx2_config().unwrap())
            .create::<ipc::Service>()
            .unwrap()
    }

    /// Why the node counter is made here: iceoryx2 alone names it
    /// [`GLOBAL_MGMT_NAME`] and leaves it 0666. And iceoryx2 opens and counts
    /// on the one [`Domain::create_node`] makes, which stays 0600.
    #[test]
    fn the_node_counter_is_made_private_where_iceoryx2_would_make_it_0666() {
        let d = dir("g");
        let _ = std::fs::remove_dir_all(&d);
        let prefix = format!("dg{}", std::process::id());
        let dom = Domain::establish(&prefix, Some(&d)).unwrap();
        let path = dom.global_mgmt_path();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().mode() & 0o7777;
        let counter = |p: &Path| {
            let b = std::fs::read(p).unwrap();
            assert_eq!(b.len() as u64, GLOBAL_MGMT_SIZE);
            let version = u64::from_ne_bytes(b[..8].try_into().unwrap());
            assert_eq!(version, ICEORYX2_VERSION_WORD);
            u32::from_ne_bytes(b[8..12].try_into().unwrap())
        };

        // iceoryx2 by itself: this very name, 0666.
        let raw = raw_node(&dom, "raw");
        assert_eq!(dom.global_mgmt_files(), vec![path.clone()]);
        assert_eq!(mode(&path), 0o666);
        assert_eq!(counter(&path), 1);
        drop(raw);
        std::fs::remove_file(&path).unwrap();

        // Ours: made before iceoryx2 looks, 0600, and iceoryx2 uses it.
        let a = dom.create_node("a").unwrap();
        assert_eq!(mode(&path), 0o600);
        assert_eq!(counter(&path), 1);
        let b = raw_node(&dom, "b");
        assert_eq!(mode(&path), 0o600);
        assert_eq!(counter(&path), 2);
        let c = dom.create_node("c").unwrap();
        assert_eq!(counter(&path), 3);
        assert_eq!(dom.global_mgmt_files(), vec![path.clone()]);
        drop((a, b, c));
        assert!(crate::cleanup::cleanup_domain(&dom).domain_gone());
        dom.withdraw();
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// One that another node of ours is still writing is waited for, not
    /// refused as truncated; a planted empty one still is, after the wait.
    #[test]
    fn a_node_counter_being_written_is_waited_for() {
        let d = dir("w");
        let _ = std::fs::remove_dir_all(&d);
        let prefix = format!("dw{}", std::process::id());
        let dom = Domain::establish(&prefix, Some(&d)).unwrap();
        let path = dom.global_mgmt_path();
        std::fs::File::create(&path).unwrap();
        let writer = {
            let path = path.clone();
            std::thread::spawn(move || {
                std::thread::sleep(std::time::Duration::from_millis(30));
                let mut content = [0u8; GLOBAL_MGMT_SIZE as usize];
                content[..8].copy_from_slice(&ICEORYX2_VERSION_WORD.to_ne_bytes());
                std::fs::write(&path, content).unwrap();
            })
        };
        assert!(wait_global_mgmt(&path).is_ok());
        writer.join().unwrap();
        std::fs::write(&path, b"").unwrap();
        let t = std::time::Instant::now();
        let err = wait_global_mgmt(&path).unwrap_err();
        assert!(err.to_string().contains("truncated"), "{err}");
        assert!(t.elapsed() < std::time::Duration::from_secs(1));
        std::fs::remove_file(&path).unwrap();
        dom.withdraw();
        std::fs::remove_dir_all(&d).unwrap();
    }
}
