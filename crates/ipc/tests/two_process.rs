//! Supervisor in this process, motion-io peer in a child process (this test
//! binary re-executed with `MOTION_IPC_CHILD_ROLE=io`, running only
//! `child_io_peer`). The child starts FIRST and creates the services, the
//! supervisor attaches afterwards. After round trips the child is killed with
//! SIGKILL mid-run: the supervisor must neither block nor crash, and cleaning
//! up the dead node must leave /dev/shm clean.

mod common;

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use common::TestEnv;
use iceoryx2::prelude::*;
use motion_frames::{axis_to_command, axis_to_feedback, command_to_axis, feedback_to_axis};
use motion_homing::Feedback;
use motion_ipc::{monotonic_ns, IoPorts, SupervisorPorts};

const ROLE_VAR: &str = "MOTION_IPC_CHILD_ROLE";
const PREFIX_VAR: &str = "MOTION_IPC_CHILD_PREFIX";
const ROOT_VAR: &str = "MOTION_IPC_CHILD_ROOT";
const CPU: f64 = 1000.0;

/// The io peer. Does nothing unless started by `supervisor_with_io_child...`.
#[test]
fn child_io_peer() {
    if std::env::var(ROLE_VAR).as_deref() != Ok("io") {
        return;
    }
    let env = TestEnv::from_parts(
        std::env::var(PREFIX_VAR).unwrap(),
        PathBuf::from(std::env::var(ROOT_VAR).unwrap()),
    );
    let node = env.domain.create_node("motion-io").unwrap();
    let mut io = IoPorts::open(&node, &env.domain, "io").unwrap();
    println!("READY"); // libtest may put "test child_io_peer ... " in front
    let mut idle_since = Instant::now();
    loop {
        if !io.wait(Duration::from_millis(100)).unwrap() {
            // orphaned (parent gone without killing us): leave
            assert!(
                idle_since.elapsed() < Duration::from_secs(20),
                "no supervisor"
            );
            continue;
        }
        idle_since = Instant::now();
        let Some(c) = io.receive_latest().unwrap() else {
            continue;
        };
        let taken = monotonic_ns();
        let answers = c.header.sequence;
        let n = c.header.axis_count_clamped();
        let mut fb = [Feedback::default(); 4];
        for (a, f) in c.active_axes().iter().zip(fb.iter_mut()) {
            let cmd = axis_to_command(a, CPU);
            f.position = cmd.position; // ideal drive
            f.velocity = cmd.velocity;
            f.drive.enabled = cmd.enable;
        }
        drop(c);
        io.send(|f| {
            f.header.axis_count = n as u32;
            f.answers_sequence = answers;
            f.io_received_ns = taken;
            for (w, fb) in f.axes.iter_mut().zip(fb.iter()).take(n) {
                *w = feedback_to_axis(fb, CPU);
            }
        })
        .unwrap();
    }
}

/// Kills (SIGKILL) and reaps the child on every path, also when the test fails.
struct ChildGuard(Option<Child>);

impl ChildGuard {
    fn id(&self) -> u32 {
        self.0.as_ref().map_or(0, Child::id)
    }
    fn kill(&mut self) -> Option<ExitStatus> {
        let mut child = self.0.take()?;
        child.kill().unwrap(); // SIGKILL on Unix
        Some(child.wait().unwrap())
    }
}

impl Drop for ChildGuard {
    fn drop(&mut self) {
        if let Some(mut child) = self.0.take() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

#[test]
fn supervisor_with_io_child_survives_sigkill_and_cleans_up() {
    let env = TestEnv::new("2p");
    // The supervisor creates the services (exclusively); the peer opens them.
    let node = env.domain.create_node("motion-supervisor").unwrap();
    let mut sup = SupervisorPorts::create(&node, &env.domain, "io").unwrap();
    let mut child = ChildGuard(Some(
        Command::new(std::env::current_exe().unwrap())
            .args([
                "--exact",
                "child_io_peer",
                "--nocapture",
                "--test-threads=1",
            ])
            .env(ROLE_VAR, "io")
            .env(PREFIX_VAR, &env.domain.prefix)
            .env(ROOT_VAR, &env.root)
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap(),
    ));

    // wait until the child's ports exist
    let stdout = child.0.as_mut().unwrap().stdout.take().unwrap();
    let mut lines = BufReader::new(stdout).lines();
    loop {
        let line = lines.next().expect("child exited before READY").unwrap();
        if line.trim_end().ends_with("READY") {
            break;
        }
    }
    // keep draining the child's stdout so it never blocks on a full pipe
    let drain = std::thread::spawn(move || for _ in lines {});

    {
        sup.update_connections().unwrap();

        // ---- round trips -------------------------------------------------
        const AXES: usize = 4;
        const ROUND_TRIPS: u64 = 500;
        let mut rtt_us = Vec::with_capacity(ROUND_TRIPS as usize);
        for i in 1..=ROUND_TRIPS {
            let cmd = motion_homing::Command {
                enable: true,
                position: i as f64 / CPU,
                velocity: 2.0,
                ..Default::default()
            };
            let t0 = Instant::now();
            let sent = sup
                .send(|f| {
                    f.header.axis_count = AXES as u32;
                    for a in &mut f.axes[..AXES] {
                        *a = command_to_axis(&cmd, CPU);
                    }
                })
                .unwrap();
            assert_eq!(sent.sequence, i);
            assert_eq!(sent.receivers, 1, "io child not attached");
            // wait for the answer to exactly this frame
            let deadline = Instant::now() + Duration::from_secs(2);
            let fb = loop {
                let left = deadline.saturating_duration_since(Instant::now());
                assert!(!left.is_zero(), "no answer to sequence {i}");
                if !sup.wait(left).unwrap() {
                    continue;
                }
                if let Some(f) = sup.receive_latest().unwrap() {
                    if f.answers_sequence == sent.sequence {
                        break f;
                    }
                    assert!(f.answers_sequence < sent.sequence);
                }
            };
            rtt_us.push(t0.elapsed().as_secs_f64() * 1e6);
            assert_eq!(fb.active_axes().len(), AXES);
            let back = axis_to_feedback(&fb.axes[AXES - 1], CPU);
            assert_eq!(back.position, cmd.position);
            assert!(back.drive.enabled);
            assert!(fb.io_received_ns <= fb.header.timestamp_ns);
            assert!(fb.io_received_ns >= 1); // clocks comparable across processes
        }
        rtt_us.sort_by(f64::total_cmp);
        println!(
            "two-process round trip ({ROUND_TRIPS}x, unpinned, {} build): p50 {:.0} us, \
             p99 {:.0} us, max {:.0} us; frames skipped {}",
            if cfg!(debug_assertions) {
                "debug"
            } else {
                "release"
            },
            rtt_us[rtt_us.len() / 2],
            rtt_us[rtt_us.len() * 99 / 100],
            rtt_us[rtt_us.len() - 1],
            sup.skipped()
        );

        // ---- SIGKILL mid-run ---------------------------------------------
        // keep publishing while the child is being killed
        let pid = child.id();
        let mut killed = false;
        let mut killed_at = Instant::now();
        let mut worst_publish = (Duration::ZERO, 0);
        let mut worst_notify = Duration::ZERO;
        let mut timeouts = 0;
        for k in 0..100 {
            if k == 10 {
                let status = child.kill().unwrap(); // SIGKILL
                println!("io child {pid} killed: {status:?}");
                killed = true;
                killed_at = Instant::now();
            }
            let t = Instant::now();
            let sent = sup.publish(|f| f.header.axis_count = 1).unwrap();
            worst_publish = worst_publish.max((t.elapsed(), k));
            let t = Instant::now();
            sup.notify().unwrap();
            worst_notify = worst_notify.max(t.elapsed());
            let t = Instant::now();
            let woken = sup.wait(Duration::from_millis(20)).unwrap();
            let waited = t.elapsed();
            let fb = sup.receive_latest().unwrap();
            if killed && k > 12 {
                // nobody answers any more: the wait times out, nothing arrives
                assert!(!woken, "woken after the peer died (cycle {k})");
                assert!(fb.is_none());
                assert!(waited >= Duration::from_millis(15));
                assert!(waited < Duration::from_millis(500));
                timeouts += 1;
            }
            assert!(sent.receivers <= 1);
        }
        println!(
            "after SIGKILL (in cycle 10 of 100): {timeouts} waits timed out, worst publish {:?} \
             (cycle {}), worst notify {worst_notify:?}",
            worst_publish.0, worst_publish.1
        );
        assert!(worst_publish.0 < Duration::from_millis(100));
        assert!(worst_notify < Duration::from_millis(100));

        // ---- dead node detection and cleanup ------------------------------
        let icfg = env.domain.iceoryx2_config().unwrap();
        let mut dead = 0;
        while killed_at.elapsed() < Duration::from_secs(10) {
            dead = 0;
            Node::<ipc::Service>::list(&icfg, |state| {
                if let NodeState::Dead(_) = state {
                    dead += 1;
                }
                CallbackProgression::Continue
            })
            .unwrap();
            if dead > 0 {
                break;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        println!(
            "first Node::list after the kill ({:?} later) reports the io node dead",
            killed_at.elapsed()
        );
        assert_eq!(dead, 1, "the killed io node is not reported dead");
        let before = env.shm_files().len();
        let state = node.try_cleanup_dead_nodes();
        println!(
            "try_cleanup_dead_nodes: {state:?}; /dev/shm entries {before} -> {}",
            env.shm_files().len()
        );
        assert_eq!(state.cleanups, 1);
        assert_eq!(state.failed_cleanups, 0);

        // the dead subscriber is gone: frames reach nobody, nothing blocks
        let sent = sup.publish(|_| {}).unwrap();
        assert_eq!(sent.receivers, 0);
        assert_eq!(sup.notify().unwrap(), 0);
        assert!(!sup.wait(Duration::from_millis(5)).unwrap());
    }
    drop(sup);
    drop(node);
    drain.join().unwrap();
    env.assert_clean_and_remove();
}
