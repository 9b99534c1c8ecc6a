//! SIGTERM/SIGINT: every axis stopped, exit 0, nothing left in /dev/shm.
//! SIGKILL: the stale resources are removed by the cleanup helper.

use std::time::{Duration, Instant};

use motion_frames::SW_ENABLED;
use motion_harness::peer::{
    enabled, io_on_own_prefix, io_with_peer, one_axis, pace_like_the_supervisor, Pacer,
    SupervisorPeer,
};
use motion_harness::*;
use motion_ipc::cleanup_domain;
use nix::sys::signal::Signal;

const STOP_LINE: &str = "motion-io: signal: every axis stopped";

#[test]
fn sigterm_while_moving_stops_every_axis_and_exits_0() {
    // 50 ms of silence would trip motion-io's watchdog mid-move
    pace_like_the_supervisor();
    let (_cfg, _guard, mut io, mut sup) = io_on_own_prefix(&Machine::fixture("io_marker"));
    sup.connect(1);
    let mut pacer = Pacer::new(Duration::from_millis(1));
    let mut pos = 0;
    for k in 0..50 {
        pacer.wait();
        pos += 30;
        let a = sup
            .exchange(one_axis(enabled(pos, 30_000.0)), Duration::from_secs(2))
            .expect("answer");
        if k >= 2 {
            assert_eq!(a.fb.axes[0].status_word, SW_ENABLED);
        }
    }

    let t0 = Instant::now();
    io.signal(Signal::SIGTERM);
    let st = io
        .wait_exit(Duration::from_secs(2))
        .expect("not exited within 2 s of SIGTERM");
    let took = t0.elapsed();
    println!("exit {st:?} {took:?} after SIGTERM");
    assert_eq!(st.code(), Some(0), "{}", io.stderr());
    assert!(io.find(STOP_LINE).is_some(), "{}", io.stderr());
    assert!(io.find("SIGTERM received after").is_some());
    // the last frame, if still readable, shows the axis at rest
    if let Some(f) = sup.latest() {
        println!("last feedback after SIGTERM: {:?}", f.axes[0]);
        assert_eq!(f.answers_sequence, 0);
        assert_eq!(f.axes[0].velocity, 0.0);
        assert_eq!(f.axes[0].status_word & SW_ENABLED, 0);
    }
    sup.finish();
}

#[test]
fn sigint_while_waiting_for_a_supervisor_exits_0_and_creates_nothing() {
    let prefix = unique_prefix("iotest");
    let _guard = DomainGuard(prefix.clone());
    let mut io = spawn_io(&["--service-prefix", &prefix]);
    io.wait_line("waiting for the supervisor", Duration::from_secs(10))
        .expect("waiting line");
    assert_eq!(shm_leftovers(&prefix), Vec::<String>::new());
    io.signal(Signal::SIGINT);
    let st = io.wait_exit(Duration::from_secs(2)).expect("no exit");
    assert_eq!(st.code(), Some(0), "{}", io.stderr());
    assert_eq!(shm_leftovers(&prefix), Vec::<String>::new());
}

#[test]
fn sigint_before_any_command_exits_0_and_leaves_nothing() {
    let prefix = unique_prefix("iotest");
    let _guard = DomainGuard(prefix.clone());
    // built-in demo machine, prefix overridden
    let mut io = spawn_io(&["--service-prefix", &prefix]);
    let sup = SupervisorPeer::new(&prefix);
    let start = io
        .wait_line("backend sim", Duration::from_secs(10))
        .expect("start line");
    let (demo, _) = motion_config::load(None).expect("demo machine");
    let names: Vec<_> = demo.axes.iter().map(|a| a.name.as_str()).collect();
    let axes = format!("{} axes ({})", names.len(), names.join(", "));
    assert!(start.1.contains(&axes), "{axes:?} not in {}", start.1);
    assert!(
        start.1.contains("deploy/demo.toml (built in)"),
        "{}",
        start.1
    );
    assert!(
        !shm_leftovers(&prefix).is_empty(),
        "no iceoryx2 files while running?"
    );
    let t0 = Instant::now();
    io.signal(Signal::SIGINT);
    let st = io.wait_exit(Duration::from_secs(2)).expect("no exit");
    println!("exit after SIGINT in {:?}", t0.elapsed());
    assert_eq!(st.code(), Some(0), "{}", io.stderr());
    assert!(io.find(STOP_LINE).is_some());
    // with the supervisor side gone too, nothing of the domain is left
    sup.finish();
}

#[test]
fn sigkilled_peer_is_cleaned_up_by_the_helper() {
    let prefix = unique_prefix("iotest");
    let _guard = DomainGuard(prefix.clone());
    let (mut io, mut sup) = io_with_peer(&["--service-prefix", &prefix], &prefix);
    sup.connect(4);
    let domain = sup.domain.clone();
    drop(sup);
    let killed = Instant::now();
    io.kill();
    assert!(
        !shm_leftovers(&prefix).is_empty(),
        "a killed process leaves files"
    );

    // the killed node shows as dead after a moment; the helper cleans it
    let mut cleaned = 0;
    loop {
        let r = cleanup_domain(&domain);
        cleaned += r.dead_cleaned;
        if r.domain_gone() && r.removed_global_mgmt {
            println!(
                "{:?} after SIGKILL: {r}; dead nodes cleaned: {cleaned}",
                killed.elapsed()
            );
            break;
        }
        assert!(
            killed.elapsed() < Duration::from_secs(5),
            "not cleaned: {r:?}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    assert_eq!(cleaned, 1);
    assert_eq!(shm_leftovers(&prefix), Vec::<String>::new());
}
