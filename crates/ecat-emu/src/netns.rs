//! A veth pair with one end in its own network namespace, for tests: the
//! master opens the root-namespace end, the emulator the other one. Both
//! go away when the value is dropped (deleting the namespace deletes the
//! pair).

use std::process::Command;
use std::sync::atomic::{AtomicU32, Ordering};

/// Why the environment cannot run the wire tests.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Skip(pub String);

impl std::fmt::Display for Skip {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SKIPPED: needs root and ip netns ({})", self.0)
    }
}

/// The pair.
#[derive(Debug)]
pub struct VethPair {
    /// Namespace of the emulator's end.
    pub netns: String,
    /// The master's end (root namespace).
    pub master: String,
    /// The emulator's end (inside `netns`).
    pub subdevice: String,
}

static COUNTER: AtomicU32 = AtomicU32::new(0);

fn ip(args: &[&str]) -> Result<(), String> {
    let out = Command::new("ip")
        .args(args)
        .output()
        .map_err(|e| format!("`ip` not runnable: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!(
            "`ip {}` failed: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr).trim()
        ))
    }
}

impl VethPair {
    /// Creates namespace and pair with unique names; `Err(Skip)` without
    /// root or without `ip netns`.
    pub fn new() -> Result<VethPair, Skip> {
        // SAFETY: geteuid has no preconditions.
        if unsafe { libc::geteuid() } != 0 {
            return Err(Skip("not running as root".into()));
        }
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let pid = std::process::id();
        let tag = format!("{:x}{:x}", pid % 0xFFFFF, n);
        let pair = VethPair {
            netns: format!("ecat-emu-{tag}"),
            master: format!("ecm{tag}"),
            subdevice: format!("ecs{tag}"),
        };
        // leftovers of an earlier crashed run with the same pid
        let _ = ip(&["netns", "del", &pair.netns]);
        let _ = ip(&["link", "del", &pair.master]);
        let setup = || -> Result<(), String> {
            ip(&["netns", "add", &pair.netns])?;
            ip(&[
                "link",
                "add",
                &pair.master,
                "type",
                "veth",
                "peer",
                "name",
                &pair.subdevice,
            ])?;
            ip(&["link", "set", &pair.subdevice, "netns", &pair.netns])?;
            ip(&["link", "set", &pair.master, "up"])?;
            ip(&["-n", &pair.netns, "link", "set", &pair.subdevice, "up"])?;
            Ok(())
        };
        match setup() {
            Ok(()) => Ok(pair),
            Err(e) => Err(Skip(e)), // drop cleans up what was made
        }
    }
}

impl VethPair {
    /// [`VethPair::new`], or `None` after printing why the test calling it
    /// is skipped (`SKIPPED: needs root and ip netns (…)`).
    pub fn or_skip() -> Option<VethPair> {
        VethPair::new().map_err(|skip| eprintln!("{skip}")).ok()
    }
}

impl Drop for VethPair {
    fn drop(&mut self) {
        let _ = ip(&["link", "del", &self.master]);
        let _ = ip(&["netns", "del", &self.netns]);
    }
}
