//! The frame ports in one process: exclusive creation, layout and key
//! checks, the newest-frame rule, the node-counter guard, clean-up.

mod common;

use std::os::unix::fs::MetadataExt;
use std::time::Duration;

use common::TestEnv;
use iceoryx2::prelude::*;
use motion_frames::*;
use motion_ipc::*;

/// A command frame as a future motion-frames version might define it: same
/// service name, another layout (and so another type name).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, ZeroCopySend, PlacementDefault)]
#[type_name("motion_frames::CommandFrame@layout999")]
struct CommandFrameV2 {
    header: FrameHeader,
    extra: u64,
}

#[test]
fn a_32_character_prefix_fits_the_socket_paths() {
    // The longest prefix the config accepts, in the longest runtime dir.
    let prefix = format!("{:x<32}", format!("p{}", std::process::id()));
    assert_eq!(prefix.len(), 32);
    let dir = std::path::PathBuf::from(format!("/tmp/mflong{:07}", std::process::id()));
    assert!(dir.as_os_str().len() <= motion_config::args::RUNTIME_DIR_MAX);
    let _ = std::fs::remove_dir_all(&dir);
    let d = Domain::establish(&prefix, Some(&dir)).unwrap();
    {
        let node = d.create_node("motion-supervisor").unwrap();
        let _sup = SupervisorPorts::create(&node, &d, "io").unwrap();
        let _io = IoPorts::open(&node, &d, "io").unwrap();
    }
    assert!(cleanup_domain(&d).domain_gone());
    d.withdraw();
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn services_are_created_exclusively() {
    let env = TestEnv::new("dup");
    let node = env.domain.create_node("motion-supervisor").unwrap();
    let _a = SupervisorPorts::create(&node, &env.domain, "io").unwrap();
    let err = SupervisorPorts::create(&node, &env.domain, "io").unwrap_err();
    assert!(matches!(err, IpcError::CreateTopic { .. }), "{err:?}");
    assert!(err.to_string().contains("already exists"), "{err}");
    // Another I/O process name is another set of services.
    let _b = SupervisorPorts::create(&node, &env.domain, "bus1").unwrap();
}

#[test]
fn a_peer_cannot_open_what_no_supervisor_created() {
    let env = TestEnv::new("nos");
    let node = env.domain.create_node("motion-io").unwrap();
    let err = IoPorts::open(&node, &env.domain, "io").unwrap_err();
    assert!(err.is_no_supervisor(), "{err:?}");
}

#[test]
fn peer_with_other_layout_cannot_attach_either_way() {
    let env = TestEnv::new("lay");
    let node = env.domain.create_node("motion-supervisor").unwrap();
    let names = IoServiceNames::new(&env.domain.prefix, "io");
    {
        // current supervisor, "newer" peer
        let _sup = SupervisorPorts::create(&node, &env.domain, "io").unwrap();
        let r = node
            .service_builder(&ServiceName::new(&names.command).unwrap())
            .publish_subscribe::<CommandFrameV2>()
            .open();
        assert!(
            matches!(
                r,
                Err(iceoryx2::service::builder::publish_subscribe::PublishSubscribeOpenError::IncompatibleTypes)
            ),
            "{r:?}"
        );
    }
    // "newer" service, current peer
    let _v2 = node
        .service_builder(&ServiceName::new(&names.feedback).unwrap())
        .publish_subscribe::<CommandFrameV2>()
        .create()
        .unwrap();
    let err = IoPorts::open(&node, &env.domain, "io").unwrap_err();
    assert!(matches!(err, IpcError::LayoutMismatch { .. }), "{err:?}");
    assert!(err.is_version_mismatch());
    let msg = err.to_string();
    assert!(
        msg.contains(&format!("this binary speaks layout {LAYOUT_VERSION}")),
        "{msg}"
    );
}

#[test]
fn frames_without_the_session_key_are_refused_and_counted() {
    let env = TestEnv::new("key");
    let node = env.domain.create_node("motion-supervisor").unwrap();
    let mut sup = SupervisorPorts::create(&node, &env.domain, "io").unwrap();
    // A forger who found the service but not the key publishes feedback.
    let names = IoServiceNames::new(&env.domain.prefix, "io");
    let svc = node
        .service_builder(&ServiceName::new(&names.feedback).unwrap())
        .publish_subscribe::<FeedbackFrame>()
        .open()
        .unwrap();
    let forger = svc.publisher_builder().create().unwrap();
    let mut f = FeedbackFrame::ZERO;
    f.header.layout_version = LAYOUT_VERSION;
    f.header.axis_count = 1;
    f.header.key = [1, 2];
    f.answers_sequence = u64::MAX;
    forger.send_copy(f).unwrap();
    let err = sup.receive_latest().unwrap_err();
    assert!(matches!(err, IpcError::Forged { .. }), "{err:?}");
    assert_eq!(sup.refused(), 1);
    // With the key it is accepted (the key is what binds a peer).
    f.header.key = env.domain.key;
    forger.send_copy(f).unwrap();
    assert!(sup.receive_latest().unwrap().is_some());
    assert_eq!(sup.refused(), 1);
}

#[test]
fn bad_header_is_reported() {
    let env = TestEnv::new("hdr");
    let node = env.domain.create_node("motion-io").unwrap();
    let mut sup = SupervisorPorts::create(&node, &env.domain, "io").unwrap();
    let mut io = IoPorts::open(&node, &env.domain, "io").unwrap();
    sup.publish(|f| f.header.axis_count = MAX_AXES as u32 + 1)
        .unwrap();
    let err = io.receive_latest().unwrap_err();
    assert!(
        matches!(
            err,
            IpcError::Layout {
                error: LayoutError::TooManyAxes { .. },
                ..
            }
        ),
        "{err:?}"
    );
    sup.publish(|f| f.header.axis_count = 1).unwrap();
    let s = io.receive_latest().unwrap().unwrap();
    assert_eq!(s.header.sequence, 2);
    assert_eq!(s.header.layout_version, LAYOUT_VERSION);
    assert_eq!(s.header.key, env.domain.key);
    assert_eq!(s.header.origin, sup.origin());
    assert_ne!(sup.origin(), io.origin());
}

#[test]
fn receive_latest_keeps_the_newest() {
    let env = TestEnv::new("lat");
    let node = env.domain.create_node("motion-io").unwrap();
    let mut sup = SupervisorPorts::create(&node, &env.domain, "io").unwrap();
    let mut io = IoPorts::open(&node, &env.domain, "io").unwrap();
    assert!(io.receive_latest().unwrap().is_none());
    assert!(!io.try_wait().unwrap());
    for i in 0..5u32 {
        let sent = sup
            .send(|f| {
                f.header.axis_count = 1;
                f.axes[0].target_position = i64::from(i);
            })
            .unwrap();
        assert_eq!(sent.sequence, u64::from(i) + 1);
        assert_eq!(sent.receivers, 1);
    }
    assert!(io.try_wait().unwrap());
    assert!(!io.try_wait().unwrap());
    let s = io.receive_latest().unwrap().unwrap();
    assert_eq!(s.header.sequence, 5);
    assert_eq!(s.axes[0].target_position, 4);
    // buffer 2 with safe overflow: 3 frames were overwritten in the buffer,
    // 1 was drained and dropped here
    assert_eq!(io.skipped(), 1);
    assert!(io.receive_latest().unwrap().is_none());
    let t = std::time::Instant::now();
    assert!(!io.wait(Duration::from_millis(20)).unwrap());
    assert!(t.elapsed() >= Duration::from_millis(15));
}

#[test]
fn cleanup_domain_keeps_a_live_domain_and_removes_an_empty_one() {
    let env = TestEnv::new("cln");
    {
        let node = env.domain.create_node("motion-supervisor").unwrap();
        let _sup = SupervisorPorts::create(&node, &env.domain, "io").unwrap();
        let r = cleanup_domain(&env.domain);
        assert_eq!(r.alive, 1, "{r:?}");
        assert!(!r.removed_global_mgmt && !r.domain_gone(), "{r:?}");
        assert!(!env.shm_files().is_empty());
    }
    let r = cleanup_domain(&env.domain);
    assert_eq!(r.alive, 0, "{r:?}");
    assert!(r.removed_global_mgmt && r.domain_gone(), "{r:?}");
    assert_eq!(env.shm_files(), Vec::<String>::new());
    let r = cleanup_domain(&env.domain);
    assert!(!r.removed_global_mgmt && r.domain_gone(), "{r:?}");
}

/// Watches /dev/shm (inotify) while `f` runs and records the mode of every
/// file starting with `prefix` each time it is created, written or has its
/// permissions changed, as seen right after the event: a window in which
/// a file is group- or world-accessible shows up as such a mode.
fn modes_seen_while(prefix: &str, f: impl FnOnce()) -> Vec<(String, u32)> {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    // SAFETY: plain syscalls on a descriptor this function owns.
    let fd = unsafe { libc::inotify_init1(libc::IN_NONBLOCK | libc::IN_CLOEXEC) };
    assert!(fd >= 0);
    let mask = libc::IN_CREATE | libc::IN_ATTRIB | libc::IN_MODIFY | libc::IN_CLOSE_WRITE;
    let wd = unsafe { libc::inotify_add_watch(fd, c"/dev/shm".as_ptr(), mask) };
    assert!(wd >= 0);
    let stop = Arc::new(AtomicBool::new(false));
    let watcher = {
        let stop = stop.clone();
        let prefix = prefix.to_string();
        std::thread::spawn(move || {
            let mut seen = Vec::new();
            let mut buf = [0u64; 1024];
            loop {
                let done = stop.load(Ordering::Acquire);
                let mut pfd = libc::pollfd {
                    fd,
                    events: libc::POLLIN,
                    revents: 0,
                };
                unsafe { libc::poll(&mut pfd, 1, 20) };
                let n = unsafe { libc::read(fd, buf.as_mut_ptr().cast(), 8 * buf.len()) };
                let bytes: &[u8] =
                    unsafe { std::slice::from_raw_parts(buf.as_ptr().cast(), n.max(0) as usize) };
                let mut at = 0;
                while at + 16 <= bytes.len() {
                    let len = u32::from_ne_bytes(bytes[at + 12..at + 16].try_into().unwrap());
                    let raw = &bytes[at + 16..at + 16 + len as usize];
                    let name = String::from_utf8_lossy(raw.split(|&b| b == 0).next().unwrap());
                    if name.starts_with(&prefix) {
                        let path = std::path::Path::new("/dev/shm").join(name.as_ref());
                        if let Ok(m) = std::fs::symlink_metadata(&path) {
                            seen.push((name.into_owned(), m.mode() & 0o7777));
                        }
                    }
                    at += 16 + len as usize;
                }
                if done && n <= 0 {
                    return seen;
                }
            }
        })
    };
    f();
    std::thread::sleep(Duration::from_millis(50));
    stop.store(true, Ordering::Release);
    let seen = watcher.join().unwrap();
    unsafe { libc::close(fd) };
    seen
}

/// Creating a node in a fresh domain never leaves a file that
/// group or others could open, not even for a moment (iceoryx2 makes its
/// node counter 0666 with fchmod; a chmod afterwards left a window).
#[test]
fn no_file_of_a_new_node_is_ever_accessible_to_others() {
    for round in 0..5 {
        let env = TestEnv::new("um");
        let mut node = None;
        let seen = modes_seen_while(&env.domain.file_prefix(), || {
            node = Some(env.domain.create_node("motion-supervisor").unwrap());
        });
        assert!(
            seen.iter().any(|(n, _)| n.ends_with(".global_mgmt")),
            "round {round}: the node counter's creation was not observed: {seen:?}"
        );
        let open: Vec<_> = seen
            .iter()
            .filter(|(_, m)| m & 0o077 != 0)
            .map(|(n, m)| format!("{n}: {m:o}"))
            .collect();
        assert!(
            open.is_empty(),
            "round {round}: accessible to others: {open:?}"
        );
        for f in env.shm_files() {
            let m = std::fs::metadata(std::path::Path::new("/dev/shm").join(&f)).unwrap();
            assert_eq!(m.mode() & 0o777, 0o600, "{f}");
        }
        for f in env.root_files() {
            let m = std::fs::symlink_metadata(&f).unwrap();
            assert_eq!(m.mode() & 0o077, 0, "{}: {:o}", f.display(), m.mode());
        }
        drop(node);
    }
}

/// A hostile local user's attack: the node counter is 0666 in iceoryx2; ours is 0600
/// from its creation on, and a truncated one is refused instead of hanging
/// node creation.
#[test]
fn the_node_counter_is_private_and_a_truncated_one_is_refused() {
    let env = TestEnv::new("gm");
    let node = env.domain.create_node("motion-supervisor").unwrap();
    let mgmt: Vec<String> = env
        .shm_files()
        .into_iter()
        .filter(|f| f.ends_with(".global_mgmt"))
        .collect();
    assert_eq!(mgmt.len(), 1, "{:?}", env.shm_files());
    let path = std::path::Path::new("/dev/shm").join(&mgmt[0]);
    assert_eq!(std::fs::metadata(&path).unwrap().mode() & 0o777, 0o600);
    drop(node);
    // Someone of our user truncates it.
    std::fs::OpenOptions::new()
        .write(true)
        .open(&path)
        .unwrap()
        .set_len(0)
        .unwrap();
    let t = std::time::Instant::now();
    let err = env.domain.create_node("motion-io").unwrap_err();
    assert!(t.elapsed() < Duration::from_secs(1), "no hang");
    assert!(matches!(err, IpcError::Unsafe(_)), "{err:?}");
    assert!(err.to_string().contains("truncated"), "{err}");
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn the_builders_carry_the_frames_settings_for_any_payload() {
    let env = TestEnv::new("bld");
    let node = env.domain.create_node("motion-supervisor").unwrap();
    let _sup = SupervisorPorts::create(&node, &env.domain, "io").unwrap();
    let names = IoServiceNames::new(&env.domain.prefix, "io");
    let name = |s: &str| ServiceName::new(s).unwrap();
    // the frame services open with the builders' settings (iceoryx2 checks
    // them against the ones they were created with)
    let command = ports::topic_builder::<CommandFrame>(&node, &name(&names.command));
    let ready = ports::event_builder(&node, &name(&names.command_ready));
    assert!(command.open().is_ok() && ready.open().is_ok());
    // a byte-array topic gets the same settings
    let bare = name(&format!("{}/bare", env.domain.prefix));
    let t = ports::topic_builder::<[u8; 64]>(&node, &bare)
        .open_or_create()
        .unwrap();
    let c = t.static_config();
    assert!(c.has_safe_overflow());
    assert_eq!(
        (c.history_size(), c.subscriber_max_buffer_size()),
        (0, ports::SUBSCRIBER_BUFFER)
    );
    assert_eq!(
        (c.max_publishers(), c.max_subscribers()),
        (1, ports::MAX_SUBSCRIBERS)
    );
    let e = ports::event_builder(&node, &name(&format!("{}/bare_ready", env.domain.prefix)))
        .open_or_create()
        .unwrap();
    let c = e.static_config();
    assert_eq!(
        (c.max_notifiers(), c.max_listeners()),
        (1, ports::MAX_LISTENERS)
    );
}
