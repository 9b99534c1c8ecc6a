//! A panic unwinding through a command after the session started ("axes
//! stopped, shared memory cleaned" must hold on every way out): the
//! session is dropped on the way, so the cycle ends through its orderly exit
//! (every axis stopped, every drive disabled: `Control::Exit`), and nothing
//! is left in /dev/shm nor a session file. Injected in-process with
//! `catch_unwind`: the binaries carry no test-only way to panic.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

use motion_config::IoMode;
use motion_ipc::session_path;
use motion_supervisor::session::{Session, SessionOptions};
use motion_supervisor::shared::Phase;

/// As in the binary: the cycle serves its allocations from its own pool.
#[global_allocator]
static ALLOCATOR: motion_rt::RtAllocator = motion_rt::RtAllocator;

#[test]
fn a_panic_after_the_start_stops_the_cycle_and_cleans_up() {
    let (mut m, _) = motion_config::load(None).unwrap();
    let state = tempfile::tempdir().unwrap();
    m.supervisor.lock_memory = false;
    m.supervisor.cpu_dma_latency_us = -1;
    m.supervisor.state_dir = state.path().to_path_buf();
    // No child process: the I/O processes would be started by hand.
    for io in &mut m.ios {
        io.spawn = IoMode::External;
    }
    let prefix = format!("spu{}", std::process::id());
    let dir = PathBuf::from(format!("/tmp/mspu{}", std::process::id() % 1_000_000));
    let _ = std::fs::remove_dir_all(&dir);
    let opts = SessionOptions {
        config_path: None,
        service_prefix: prefix.clone(),
        runtime_dir: Some(dir.clone()),
        io_args: Vec::new(),
        hlog_file: None,
        no_control_plane: false,
    };
    let mut seen = None;
    let r = catch_unwind(AssertUnwindSafe(|| {
        let s = Session::start(m, &opts).unwrap();
        assert!(!s.domain.shm_files().is_empty());
        assert!(session_path(&dir, &prefix).exists());
        seen = Some((s.domain.clone(), s.shared.clone()));
        panic!("injected after the session started");
    }));
    assert!(r.is_err());
    let (domain, shared) = seen.expect("the session started");
    assert!(
        matches!(shared.phase(), Phase::Exited),
        "the cycle did not end through its exit"
    );
    assert_eq!(domain.shm_files(), Vec::<String>::new());
    assert!(!session_path(&dir, &prefix).exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
