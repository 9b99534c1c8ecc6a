//! Creating an iceoryx2 node in a domain, with the guard on iceoryx2's
//! per-domain node counter: a regular 16-byte file of ours (else refuse: a
//! truncated one makes iceoryx2 hang), made 0600 where iceoryx2 would make it
//! 0666 (see [`crate::domain`]).

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::os::unix::fs::{MetadataExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};

use iceoryx2::node::{Node, NodeBuilder};
use iceoryx2::prelude::{ipc, NodeName, SignalHandlingMode};

use crate::dir::{check_private_dir, euid};
use crate::domain::Domain;
use crate::error::IpcError;

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

impl Domain {
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
    use crate::test_dir as dir;

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
