//! Round trips against the real binary: the sim follows the commands in
//! counts, the marker latch arms and latches exactly, sequence numbers and
//! timestamps are right; bad frames are ignored without a crash.

use std::time::Duration;

use motion_frames::{AxisCommand, CW_ENABLE, SW_ENABLED};
use motion_harness::peer::{
    enabled, io_on_own_prefix, io_with_peer, one_axis, pace_like_the_supervisor, quantile, Pacer,
};
use motion_harness::*;
use nix::sys::signal::Signal;

const ANSWER_TIMEOUT: Duration = Duration::from_secs(2);
/// Counts per cycle while moving (30 units/s at 1000 counts/unit, 1 kHz).
const STEP: i64 = 30;
/// Commands before the axis starts moving.
const HOLD: i64 = 10;
/// Marker at 2.5 units.
const MARKER: i64 = 2500;

fn target(k: i64) -> i64 {
    (k - HOLD).max(0) * STEP
}

fn round_trip(spin: bool) {
    // The timing tests run one at a time (2 vCPUs: a spinning peer next to
    // another test would distort both), paced like the supervisor.
    let _serial = serial();
    pace_like_the_supervisor();
    // the prefix comes from the TOML here (no --service-prefix)
    let cfg = Machine::fixture("io_marker").write("iotest_rt");
    let prefix = cfg.prefix.clone();
    let _guard = DomainGuard(prefix.clone());
    let mut args = vec!["--config", cfg.arg()];
    if spin {
        args.push("--spin");
    }
    let (mut io, mut sup) = io_with_peer(&args, &prefix);
    let start = io
        .wait_line("backend sim", Duration::from_secs(10))
        .expect("start line");
    assert!(start.1.contains("1 axis (X)"), "{}", start.1);
    assert!(start.1.contains(&format!("{prefix:?}")), "{}", start.1);
    assert!(start.1.contains("cycle 1000 us"), "{}", start.1);

    let first = sup.connect(1);
    assert_eq!(first.fb.header.axis_count, 1);
    assert_eq!(first.fb.axes[0].position, 0);
    assert_eq!(first.fb.axes[0].status_word, 0);

    const N: i64 = 500;
    let mut rtts = Vec::with_capacity(N as usize);
    let mut pacer = Pacer::new(Duration::from_millis(1));
    let mut last_seq = first.fb.header.sequence;
    let mut latched_at = None;
    for k in 0..N {
        pacer.wait();
        let pos = target(k);
        let a = sup
            .exchange(
                one_axis(AxisCommand {
                    marker_arm_id: if k >= 5 { 1 } else { 0 },
                    ..enabled(pos, if k >= HOLD { (STEP * 1000) as f64 } else { 0.0 })
                }),
                ANSWER_TIMEOUT,
            )
            .unwrap_or_else(|| panic!("no answer to command {k}"));
        rtts.push(a.rtt);
        let fb = &a.fb;
        let ax = &fb.axes[0];
        assert_eq!(fb.answers_sequence, a.sent.sequence);
        assert_eq!(fb.header.axis_count, 1);
        assert!(
            fb.header.sequence > last_seq,
            "feedback sequence not increasing"
        );
        last_seq = fb.header.sequence;
        assert!(fb.io_received_ns >= a.sent_ns, "taken before it was sent?");
        assert!(fb.io_received_ns <= fb.header.timestamp_ns);
        assert_eq!(a.sent.receivers, 1);

        // enable delay: two cycles, enabled with the third command
        if k < 2 {
            assert_eq!(ax.status_word, 0, "k {k}");
            assert_eq!(ax.position, 0);
        } else {
            assert_eq!(ax.status_word, SW_ENABLED, "k {k}");
            // the answer to command k carries its position: the supervisor
            // reads it one cycle after commanding it
            assert_eq!(ax.position, pos, "k {k}");
        }
        if k > HOLD + 1 {
            assert!(
                (ax.velocity - (STEP * 1000) as f64).abs() < 1.0,
                "k {k}: {}",
                ax.velocity
            );
        }
        // marker latch: armed with id 1 from command 5, latched exactly in
        // the cycle that crosses 2.5 units, held afterwards
        if k >= 5 {
            assert_eq!(ax.marker_latch_id, 1, "k {k}");
            let crossed = pos >= MARKER;
            assert_eq!(ax.marker_latched != 0, crossed, "k {k} pos {pos}");
            if crossed {
                assert_eq!(ax.marker_latch_position, MARKER);
                if latched_at.is_none() {
                    latched_at = Some(k);
                    assert!(target(k - 1) < MARKER && pos >= MARKER);
                }
            }
        } else {
            assert_eq!(ax.marker_latch_id, 0);
            assert_eq!(ax.marker_latched, 0);
        }
    }
    assert!(latched_at.is_some(), "marker never crossed");
    rtts.sort();
    println!(
        "ROUND TRIP motion-io ({}, {N} commands at 1 kHz, {} build): p50 {:.1} us, p99 {:.1} us, \
         max {:.1} us; skipped {}",
        if spin { "--spin" } else { "event wake-up" },
        if cfg!(debug_assertions) {
            "debug"
        } else {
            "release"
        },
        quantile(&rtts, 0.5).as_secs_f64() * 1e6,
        quantile(&rtts, 0.99).as_secs_f64() * 1e6,
        rtts[rtts.len() - 1].as_secs_f64() * 1e6,
        sup.ports.skipped()
    );

    io.signal(Signal::SIGTERM);
    let st = io.wait_exit(Duration::from_secs(5)).expect("exit");
    assert_eq!(st.code(), Some(0), "{}", io.stderr());
    sup.finish();
}

#[test]
fn round_trip_event_mode() {
    round_trip(false);
}

#[test]
fn round_trip_spin_mode() {
    round_trip(true);
}

#[test]
fn wrong_axis_count_and_bad_frames_are_ignored() {
    let (_cfg, _guard, mut io, mut sup) = io_on_own_prefix(&Machine::fixture("io_marker"));
    sup.connect(1);

    // two axes for a one-axis config: answered with our one axis, not applied
    for _ in 0..5 {
        let a = sup
            .exchange(
                |f| {
                    f.header.axis_count = 2;
                    for ax in &mut f.axes[..2] {
                        ax.target_position = 7000;
                        ax.control_word = CW_ENABLE;
                        ax.torque_limit_positive = 100.0;
                        ax.torque_limit_negative = 100.0;
                    }
                },
                ANSWER_TIMEOUT,
            )
            .expect("answer to a mismatched frame");
        assert_eq!(a.fb.header.axis_count, 1);
        assert_eq!(a.fb.axes[0].position, 0);
        assert_eq!(a.fb.axes[0].status_word, 0);
    }
    let line = "command frame has 2 axes, config has 1: ignoring commands \
                (are both processes using the same config?)";
    assert!(io.wait_line(line, Duration::from_secs(2)).is_some());
    assert_eq!(io.count("command frame has 2 axes"), 1, "printed once");

    // a frame whose header is invalid (too many axes): ignored, reported once
    for _ in 0..5 {
        let sent = sup
            .ports
            .send(|f| f.header.axis_count = motion_frames::MAX_AXES as u32 + 1)
            .unwrap();
        std::thread::sleep(Duration::from_millis(5));
        while let Some(f) = sup.latest() {
            assert_ne!(f.answers_sequence, sent.sequence, "bad frame answered");
        }
    }
    assert!(io
        .wait_line("bad frame received on", Duration::from_secs(2))
        .is_some());
    assert!(io
        .find("ignoring frames until a good one arrives")
        .is_some());
    assert_eq!(io.count("bad frame received on"), 1, "printed once");

    // a good frame is served again
    let a = sup
        .exchange(
            |f| {
                f.header.axis_count = 1;
                f.axes[0].target_position = 0;
            },
            ANSWER_TIMEOUT,
        )
        .expect("good frame answered");
    assert_eq!(a.fb.header.axis_count, 1);
    assert!(io
        .wait_line("good command frames again", Duration::from_secs(2))
        .is_some());

    io.signal(Signal::SIGTERM);
    let st = io.wait_exit(Duration::from_secs(5)).expect("exit");
    assert_eq!(st.code(), Some(0), "{}", io.stderr());
    sup.finish();
}
