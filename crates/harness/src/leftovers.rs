//! What a service prefix leaves behind: its iceoryx2 files in `/dev/shm`
//! and its session file. Every test and bench run uses a prefix of its
//! own, so each can check that it left nothing.

use std::time::{Duration, Instant};

use motion_ipc::{
    cleanup_domain, cleanup_stale_domains, default_runtime_dir, session_path, Domain,
};

/// Files of every iceoryx2 domain of `prefix` in `/dev/shm`.
pub fn shm_leftovers(prefix: &str) -> Vec<String> {
    Domain::shm_files_of_prefix(prefix)
}

/// Its files in `/dev/shm` and its session file.
pub fn leftovers(prefix: &str) -> Vec<String> {
    let mut v = shm_leftovers(prefix);
    let session = session_path(&default_runtime_dir(), prefix);
    if session.exists() {
        v.push(session.display().to_string());
    }
    v
}

/// Asserts that the processes of `prefix` left nothing in `/dev/shm`
/// (waits up to 3 s: a process may still be cleaning up when its parent has
/// already returned). Cleans nothing itself.
#[track_caller]
pub fn assert_clean(prefix: &str) {
    let until = Instant::now() + Duration::from_secs(3);
    loop {
        let left = shm_leftovers(prefix);
        if left.is_empty() {
            return;
        }
        assert!(Instant::now() < until, "left in /dev/shm: {left:?}");
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// For a test that joined the domain itself (its own nodes leave the
/// domain's node counter): cleans the domain (`domain`, if the test made
/// one) and the stale ones of `prefix` with the helpers the processes use,
/// retrying while a killed peer does not yet show as dead, then asserts
/// that nothing is left.
#[track_caller]
pub fn clean_and_assert_empty(domain: Option<&Domain>, prefix: &str) {
    let until = Instant::now() + Duration::from_secs(5);
    loop {
        let gone = domain.is_none_or(|d| cleanup_domain(d).domain_gone());
        cleanup_stale_domains(prefix, &default_runtime_dir());
        if (gone && shm_leftovers(prefix).is_empty()) || Instant::now() >= until {
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let left = shm_leftovers(prefix);
    assert!(left.is_empty(), "left in /dev/shm: {left:?}");
}

/// Declared right after a test's prefix (so dropped after its processes
/// and ports): if the test panicked, tidies the domain anyway, so that a
/// failed run leaves nothing in `/dev/shm` either.
pub struct DomainGuard(pub String);

impl Drop for DomainGuard {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            return;
        }
        let dir = default_runtime_dir();
        let until = Instant::now() + Duration::from_secs(2);
        while !shm_leftovers(&self.0).is_empty() && Instant::now() < until {
            cleanup_stale_domains(&self.0, &dir);
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}
