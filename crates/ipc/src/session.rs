//! The session file `{runtime_dir}/{prefix}.session` (0600, created
//! exclusively): the supervisor claims its prefix with it and draws the
//! domain id and key; peers join the domain by reading it. Only the
//! supervisor's user can read it (see [`crate::domain`]).

use std::fs::OpenOptions;
use std::io::{Read, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

use motion_frames::LAYOUT_VERSION;
use serde::{Deserialize, Serialize};

use crate::cleanup::cleanup_stale_domains;
use crate::dir::{ensure_private_dir, euid, runtime_dir_or_default};
use crate::domain::Domain;
use crate::error::IpcError;
use crate::liveness::{process_alive, session_alive};

/// Largest session file accepted.
const SESSION_FILE_MAX: u64 = 4096;

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

/// `{runtime_dir}/{prefix}.session`.
pub fn session_path(runtime_dir: &Path, prefix: &str) -> PathBuf {
    runtime_dir.join(format!("{prefix}.session"))
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
        cleanup_stale_domains(prefix, &dir);

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
}

#[cfg(test)]
mod tests {
    use std::os::unix::fs::PermissionsExt;

    use super::*;
    use crate::test_dir as dir;

    #[test]
    fn keys_and_ids_round_trip() {
        let k = [0x0123_4567_89ab_cdef, 0xfedc_ba98_7654_3210];
        assert_eq!(parse_key(&hex_key(k)), Some(k));
        assert_eq!(parse_key("xyz"), None);
        assert!(valid_id("0a1b2c3d"));
        assert!(!valid_id("0A1B2C3D") && !valid_id("../../x"));
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
}
