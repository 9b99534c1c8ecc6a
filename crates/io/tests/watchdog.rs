//! The command watchdog: the supervisor falls silent, motion-io stops every
//! axis, disables it with a fault, and (with `--exit-with-supervisor`) exits;
//! without the flag it serves a new supervisor when commands resume.

use std::time::{Duration, Instant};

use motion_frames::{AxisCommand, FeedbackFrame, CW_ENABLE, SW_ENABLED, SW_FAULT};
use motion_harness::leftovers::clean_and_assert_empty;
use motion_harness::peer::{
    enabled, io_on_own_prefix, one_axis, pace_like_the_supervisor, Pacer, SupervisorPeer,
};
use motion_harness::*;
use nix::sys::signal::Signal;

const WATCHDOG_CYCLES: u32 = 20;
const STEP: i64 = 30; // counts per cycle = 30 units/s
const WATCHDOG_LINE: &str = "motion-io: warning: watchdog: no command for ";
const STOPPED_LINE: &str = "motion-io: warning: watchdog: every axis stopped and disabled";

/// `tests/machines/io_marker.toml` with a watchdog of [`WATCHDOG_CYCLES`].
fn machine() -> Machine {
    Machine::fixture("io_marker").set("supervisor.io_watchdog_cycles", i64::from(WATCHDOG_CYCLES))
}

fn moving(pos: i64) -> impl FnOnce(&mut motion_frames::CommandFrame) {
    one_axis(enabled(pos, (STEP * 1000) as f64))
}

/// 100 commands, enabled and moving; returns the last commanded position
/// and when its answer arrived.
fn drive_100(sup: &mut SupervisorPeer) -> (i64, Instant) {
    let mut pacer = Pacer::new(Duration::from_millis(1));
    let mut pos = 0;
    let mut last = None;
    for k in 0..100 {
        pacer.wait();
        if k >= 3 {
            pos += STEP;
        }
        let a = sup
            .exchange(moving(pos), Duration::from_secs(2))
            .expect("answer");
        if k >= 2 {
            assert_eq!(a.fb.axes[0].status_word, SW_ENABLED, "k {k}");
            assert_eq!(a.fb.axes[0].position, pos);
        }
        last = Some(Instant::now());
    }
    (pos, last.unwrap())
}

/// Keeps receiving feedback until `until` holds or `timeout` passes.
fn collect_until(
    sup: &mut SupervisorPeer,
    io: &Running,
    timeout: Duration,
    mut until: impl FnMut(&Running) -> bool,
) -> Vec<FeedbackFrame> {
    let deadline = Instant::now() + timeout;
    let mut frames = Vec::new();
    while Instant::now() < deadline {
        let _ = sup.ports.wait(Duration::from_millis(2));
        while let Some(f) = sup.latest() {
            frames.push(*f);
        }
        if until(io) {
            break;
        }
    }
    frames
}

/// Checks the stop as seen in the unsolicited feedback frames.
fn check_stop(frames: &[FeedbackFrame], last_pos: i64) -> FeedbackFrame {
    let stop: Vec<_> = frames.iter().filter(|f| f.answers_sequence == 0).collect();
    assert!(!stop.is_empty(), "no feedback during the stop");
    let mut prev_pos = last_pos;
    let mut prev_vel = (STEP * 1000) as f64;
    for f in &stop {
        assert_eq!(f.header.axis_count, 1);
        assert_eq!(f.io_received_ns, 0);
        let ax = &f.axes[0];
        assert!(ax.position >= prev_pos, "moved backwards: {ax:?}");
        assert!(ax.velocity <= prev_vel + 1e-6, "accelerated: {ax:?}");
        assert!(ax.velocity >= 0.0);
        prev_pos = ax.position;
        prev_vel = ax.velocity;
    }
    let last = stop[stop.len() - 1];
    let ax = &last.axes[0];
    assert_eq!(ax.velocity, 0.0, "{ax:?}");
    assert_ne!(ax.status_word & SW_FAULT, 0, "no fault: {ax:?}");
    assert_eq!(ax.status_word & SW_ENABLED, 0, "still enabled: {ax:?}");
    // 30 units/s at 500 units/s²: 0.9 units ideal, 0.885 in 1 ms steps
    let travelled = ax.position - last_pos;
    assert!(
        (850..=920).contains(&travelled),
        "stopping distance {travelled} counts"
    );
    println!(
        "stop seen in {} feedback frames: {travelled} counts after the last command",
        stop.len()
    );
    *last
}

fn parse_watchdog_line(line: &str) -> (u64, f64) {
    // "motion-io: watchdog: no command for N cycles (X ms): stopping every axis"
    let rest = line.split(WATCHDOG_LINE).nth(1).expect("watchdog line");
    let (n, rest) = rest.split_once(" cycles (").expect("cycles");
    let (ms, tail) = rest.split_once(" ms)").expect("ms");
    assert_eq!(tail, ": stopping every axis", "{line}");
    (n.parse().unwrap(), ms.parse().unwrap())
}

/// The machine's config, a prefix of its own (tidied after a panic) and
/// the supervisor played on it, the test's thread paced like the
/// supervisor. A 20 ms silence is the watchdog's trigger: the tests take
/// turns (a spinning motion-io of another test next to this one, on 2
/// vCPUs, can starve this test's commands that long).
fn played() -> (TempConfig, String, DomainGuard, SupervisorPeer) {
    pace_like_the_supervisor();
    let cfg = machine().write("iotest_unused");
    let prefix = unique_prefix("iotest");
    let guard = DomainGuard(prefix.clone());
    let sup = SupervisorPeer::new(&prefix);
    (cfg, prefix, guard, sup)
}

fn watchdog_stop_and_exit(spin: bool) {
    let _serial = serial();
    // --quiet: no start line to wait for, so the supervisor side comes first
    let (cfg, prefix, _guard, mut sup) = played();
    let mut args = vec![
        "--config",
        cfg.arg(),
        "--service-prefix",
        &prefix,
        "--exit-with-supervisor",
        "--quiet",
    ];
    if spin {
        args.push("--spin");
    }
    let mut io = spawn_io(&args);
    sup.connect(1);
    let (last_pos, last_at) = drive_100(&mut sup);

    // silence: keep receiving feedback as a live supervisor would
    let frames = collect_until(&mut sup, &io, Duration::from_secs(10), |io| {
        io.find(STOPPED_LINE).is_some()
    });
    let w = io.find(WATCHDOG_LINE).expect("watchdog line");
    let s = io.find(STOPPED_LINE).expect("stopped line");
    assert!(w < s);
    assert_eq!(io.count(WATCHDOG_LINE), 1, "one watchdog line");
    let (wd_at, wd_line) = io.lines()[w].clone();
    let (cycles, ms) = parse_watchdog_line(&wd_line);
    let after = wd_at.duration_since(last_at);
    println!("watchdog line {after:?} after the last answer: {cycles} cycles, {ms} ms");
    assert!(cycles >= u64::from(WATCHDOG_CYCLES));
    assert!(ms >= f64::from(WATCHDOG_CYCLES) - 0.5);
    assert!(
        after < Duration::from_millis(u64::from(WATCHDOG_CYCLES) + 1000),
        "watchdog too late: {after:?}"
    );
    check_stop(&frames, last_pos);
    // --quiet hides the informational lines, not the watchdog
    assert!(io.find("first command").is_none(), "{}", io.stderr());

    // gone supervisor: exit 0 about 1 s after the stop
    let stopped_at = io.lines()[s].0;
    let st = io
        .wait_exit(Duration::from_secs(10))
        .expect("motion-io did not exit");
    let exit_after = stopped_at.elapsed();
    println!("exited {exit_after:?} after the stopped line: {st:?}");
    assert_eq!(st.code(), Some(0), "{}", io.stderr());
    assert!(exit_after >= Duration::from_millis(900), "{exit_after:?}");
    sup.finish();
}

#[test]
fn watchdog_stops_every_axis_then_exits_with_the_supervisor() {
    watchdog_stop_and_exit(false);
}

#[test]
fn watchdog_in_spin_mode() {
    watchdog_stop_and_exit(true);
}

#[test]
fn watchdog_then_commands_resume_with_the_fault_handshake() {
    let _serial = serial();
    pace_like_the_supervisor();
    let (_cfg, _guard, mut io, mut sup) = io_on_own_prefix(&machine());
    sup.connect(1);
    let (last_pos, _) = drive_100(&mut sup);
    let frames = collect_until(&mut sup, &io, Duration::from_secs(10), |io| {
        io.find(STOPPED_LINE).is_some()
    });
    let stopped = check_stop(&frames, last_pos);
    let at = stopped.axes[0].position;
    assert!(io.find("commands resumed").is_none());

    // without --exit-with-supervisor it keeps waiting (well past 1 s)
    let frames = collect_until(&mut sup, &io, Duration::from_millis(1500), |_| false);
    assert!(io.wait_exit(Duration::ZERO).is_none(), "exited");
    // status heartbeat while stopped
    assert!(
        frames
            .iter()
            .any(|f| f.answers_sequence == 0 && f.axes[0].status_word == SW_FAULT),
        "no heartbeat"
    );

    let hold = |enable: bool| {
        one_axis(AxisCommand {
            control_word: if enable { CW_ENABLE } else { 0 },
            ..enabled(at, 0.0)
        })
    };
    let t = Duration::from_secs(2);
    // enable still requested: no edge, the fault stays
    let a = sup.exchange(hold(true), t).expect("answer");
    assert_eq!(a.fb.axes[0].status_word, SW_FAULT);
    assert_eq!(a.fb.axes[0].position, at);
    assert!(io
        .wait_line(
            "motion-io: warning: commands resumed",
            Duration::from_secs(2)
        )
        .is_some());
    // false -> true resets the fault; enabled after the enable delay
    let a = sup.exchange(hold(false), t).expect("answer");
    assert_eq!(
        a.fb.axes[0].status_word, SW_FAULT,
        "still reported while off"
    );
    let mut status = Vec::new();
    for _ in 0..4 {
        let a = sup.exchange(hold(true), t).expect("answer");
        status.push(a.fb.axes[0].status_word);
    }
    assert_eq!(status, [0, 0, SW_ENABLED, SW_ENABLED]);
    assert_eq!(io.count("commands resumed"), 1);

    io.signal(Signal::SIGTERM);
    let st = io.wait_exit(Duration::from_secs(5)).expect("exit");
    assert_eq!(st.code(), Some(0), "{}", io.stderr());
    sup.finish();
}

/// stderr a pipe that nobody reads any more, full (a supervisor that
/// stopped reading, a stuck terminal): motion-io's watchdog still stops
/// every axis in its bound — it stops first and says so after, and its
/// messages wait in a writer thread, never in the main loop — and SIGTERM
/// still ends it (the exit waits at most 1 s for the writer).
#[test]
fn a_full_stderr_never_delays_the_watchdog_stop() {
    use std::io::{Read, Write};
    use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
    use std::os::unix::fs::OpenOptionsExt;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;

    let _serial = serial();
    let (cfg, prefix, _guard, mut sup) = played();
    // the pipe: small, its read end ours alone; a second, non-blocking
    // description of its write end to fill it with
    let mut fds = [0; 2];
    // SAFETY: pipe2 fills two descriptors we then own.
    assert_eq!(unsafe { libc::pipe2(fds.as_mut_ptr(), libc::O_CLOEXEC) }, 0);
    // SAFETY: both are open and owned from here on.
    let (rd, wr) = unsafe { (OwnedFd::from_raw_fd(fds[0]), OwnedFd::from_raw_fd(fds[1])) };
    // SAFETY: F_SETPIPE_SZ on a pipe we own.
    unsafe { libc::fcntl(wr.as_raw_fd(), libc::F_SETPIPE_SZ, 4096) };
    let mut filler = std::fs::OpenOptions::new()
        .write(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_CLOEXEC)
        .open(format!("/proc/self/fd/{}", wr.as_raw_fd()))
        .expect("the pipe's write end");
    // SAFETY: O_NONBLOCK on our own read end (the child never has it).
    unsafe { libc::fcntl(rd.as_raw_fd(), libc::F_SETFL, libc::O_NONBLOCK) };
    let mut reader = std::fs::File::from(rd);
    // read while it starts and serves, as a supervisor would
    let draining = Arc::new(AtomicBool::new(true));
    let drain = {
        let draining = draining.clone();
        std::thread::spawn(move || {
            let mut text = Vec::new();
            let mut buf = [0u8; 4096];
            while draining.load(Ordering::Relaxed) {
                match reader.read(&mut buf) {
                    Ok(n) if n > 0 => text.extend_from_slice(&buf[..n]),
                    _ => std::thread::sleep(Duration::from_millis(5)),
                }
            }
            (reader, String::from_utf8_lossy(&text).into_owned())
        })
    };
    let mut child = std::process::Command::new(bins::test_bin("motion-io"))
        .args(["--config", cfg.arg(), "--service-prefix", &prefix])
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::from(wr))
        .spawn()
        .expect("motion-io");
    let pid = nix::unistd::Pid::from_raw(child.id() as i32);
    struct Kill(nix::unistd::Pid);
    impl Drop for Kill {
        fn drop(&mut self) {
            let _ = nix::sys::signal::kill(self.0, Signal::SIGKILL);
        }
    }
    let _kill = Kill(pid);
    sup.connect(1);
    let (last_pos, _) = drive_100(&mut sup);
    // nobody reads any more, and the pipe is full
    draining.store(false, Ordering::Relaxed);
    let (_reader, said) = drain.join().unwrap();
    let mut filled = 0;
    while filler.write(&[b'x'; 512]).is_ok() {
        filled += 512;
    }
    println!("pipe filled with {filled} bytes; motion-io said before:\n{said}");

    // silence: the stop, read from the feedback frames
    let t0 = Instant::now();
    let mut frames = Vec::new();
    let stopped = |f: &FeedbackFrame| {
        let a = &f.axes[0];
        f.answers_sequence == 0 && a.velocity == 0.0 && a.status_word == SW_FAULT
    };
    while !frames.last().is_some_and(stopped) {
        assert!(
            t0.elapsed() < Duration::from_secs(5),
            "no stop within 5 s: {} frames, last {:?}",
            frames.len(),
            frames.last().map(|f: &FeedbackFrame| f.axes[0])
        );
        let _ = sup.ports.wait(Duration::from_millis(2));
        while let Some(f) = sup.latest() {
            frames.push(*f);
        }
    }
    println!("stopped {:?} after the last command", t0.elapsed());
    check_stop(&frames, last_pos);

    // SIGTERM: it leaves although its last lines cannot be written
    nix::sys::signal::kill(pid, Signal::SIGTERM).unwrap();
    let t1 = Instant::now();
    let st = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        assert!(t1.elapsed() < Duration::from_secs(5), "did not exit");
        std::thread::sleep(Duration::from_millis(10));
    };
    println!("exited {:?} after SIGTERM: {st:?}", t1.elapsed());
    assert_eq!(st.code(), Some(0));
    sup.finish();
}

#[test]
fn exit_with_supervisor_but_no_supervisor_exits_1_after_10_s() {
    let cfg = machine().write("iotest_unused");
    let prefix = unique_prefix("iotest");
    let _guard = DomainGuard(prefix.clone());
    let t0 = Instant::now();
    let mut io = spawn_io(&[
        "--config",
        cfg.arg(),
        "--service-prefix",
        &prefix,
        "--exit-with-supervisor",
    ]);
    let st = io.wait_exit(Duration::from_secs(20)).expect("no exit");
    let took = t0.elapsed();
    println!("exited after {took:?}: {st:?}");
    assert_eq!(st.code(), Some(1), "{}", io.stderr());
    assert!(took >= Duration::from_secs(10), "{took:?}");
    assert!(
        io.find("error: no supervisor within 10 s").is_some(),
        "{}",
        io.stderr()
    );
    clean_and_assert_empty(None, &prefix);
}
