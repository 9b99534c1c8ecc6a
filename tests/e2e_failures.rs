//! Failures end to end: a dead I/O process, a dead supervisor, a signal,
//! a broken config. Nothing may hang, move on bad data, or leave shared
//! memory behind.

use motion_harness::*;
use motion_report::HomeReport;
use nix::sys::signal::Signal;
use std::time::Duration;

/// Starts `home --json` on the slow switch axis (`tests/machines/
/// slow_switch.toml`: 8 s of seeking) and returns once it seeks.
fn homing(tag: &str) -> (Running, TempConfig) {
    let cfg = Machine::fixture("slow_switch").write(tag);
    let w = spawn_supervisor(&["home", "--json", "--config", cfg.arg()]);
    assert!(
        w.wait_line("home S: accepted", Duration::from_secs(20))
            .is_some(),
        "homing never started"
    );
    // Into the seek.
    std::thread::sleep(Duration::from_millis(500));
    (w, cfg)
}

fn io_pid(prefix: &str) -> i32 {
    let mut pid = None;
    assert!(
        wait_for(Duration::from_secs(10), || {
            pid = find_process("motion-io", prefix);
            pid.is_some()
        }),
        "motion-io for {prefix} never appeared"
    );
    pid.unwrap()
}

fn io_gone(prefix: &str) -> bool {
    wait_for(Duration::from_secs(5), || {
        find_process("motion-io", prefix).is_none()
    })
}

#[test]
fn io_killed_mid_homing_aborts_the_axis_and_exits_cleanly() {
    let _serial = serial();
    let (w, cfg) = homing("killio");
    signal_pid(io_pid(&cfg.prefix), Signal::SIGKILL);
    let run = w.finish();
    let v: HomeReport = run.expect_code(1).report();
    let s = named(&v.axes, "S");
    assert!(s.er, "{s:#?}");
    assert_eq!((s.err, s.exerr), (12, 40), "feedback lost: {s:#?}");
    // The error says how long the feedback was missing (on a dead peer
    // about feedback_timeout_ms, 20 here; less if earlier gaps had left the
    // leaky bucket part full, so only its presence is checked).
    let ms: f64 = (s.error.as_deref().unwrap_or_default())
        .split("no valid feedback for ")
        .nth(1)
        .and_then(|t| t.split(" ms").next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("no gap in the error: {s:#?}"));
    assert!(ms > 0.0 && ms < 5000.0, "{s:#?}");
    assert!(!s.homed);
    assert!(run.stderr.contains("motion-io"), "{}", run.stderr);
    assert_clean(&cfg.prefix);
}

#[test]
fn supervisor_killed_mid_homing_makes_io_stop_its_axes() {
    let _serial = serial();
    let (w, cfg) = homing("killsup");
    let io = io_pid(&cfg.prefix);
    w.signal(Signal::SIGKILL);
    // motion-io shares the supervisor's stderr: reading it to the end waits
    // for motion-io to stop its axes and exit on its own.
    let run = w.finish();
    assert!(
        run.stderr.contains("watchdog: no command"),
        "no watchdog report:\n{}",
        run.stderr
    );
    assert!(
        run.stderr.contains("every axis stopped"),
        "axes not reported stopped:\n{}",
        run.stderr
    );
    assert!(io_gone(&cfg.prefix), "motion-io {io} still running");
    assert_clean(&cfg.prefix);
}

#[test]
fn sigterm_stops_every_axis_and_exits_cleanly() {
    let _serial = serial();
    let (w, cfg) = homing("sigterm");
    w.signal(Signal::SIGTERM);
    let run = w.finish();
    let v: HomeReport = run.expect_code(128 + 15).report();
    let s = named(&v.axes, "S");
    assert_eq!((s.err, s.exerr), (12, 1), "stopped on request: {s:#?}");
    assert!(run.stderr.contains("stopping every axis"), "{}", run.stderr);
    assert!(io_gone(&cfg.prefix));
    assert_clean(&cfg.prefix);
}

#[test]
fn a_config_with_several_mistakes_prints_all_of_them() {
    let _serial = serial();
    let cfg = Machine::parse(
        r#"
[supervisor]
stale_cycles = -1

[[axis]]
name = "X"
home_sequence = "marker"
home_speed = 0.0
home_return_speed = 1.0
home_acceleration = 100.0
home_deceleration = 0.0
home_mood = "happy"

[[axis]]
name = "Y"
travel = "cyclic"
unwind = 360.0
home_position = 400.0
home_direction = "sideways"
"#,
    )
    .write("badcfg");
    for cmd in ["check", "home"] {
        let run = supervisor(&[cmd, "--config", cfg.arg()]);
        run.expect_code(2);
        for want in [
            "supervisor.stale_cycles: -1 is not a non-negative 32-bit integer",
            "axis X: home_mood: unknown key",
            "axis X: home_speed: home speed is zero (ERR 41 EXERR 6)",
            "axis X: home_deceleration: home deceleration is zero",
            "axis X: home_sequence: marker sequence but the feedback device has no marker (marker = false) (ERR 41 EXERR 21)",
            "axis Y: home_direction: \"sideways\"",
            "axis Y: home_position: 400 is outside [0, 360) of the cyclic axis (ERR 41 EXERR 24)",
        ] {
            assert!(run.stderr.contains(want), "{cmd}: missing {want:?} in\n{}", run.stderr);
        }
    }
    assert_clean(&cfg.prefix);
}

#[test]
fn check_accepts_the_default_machine() {
    let _serial = serial();
    let run = supervisor(&["check"]);
    run.expect_code(0);
    assert!(run.stdout.contains("4 axes"), "{}", run.stdout);
    assert!(
        run.stdout.contains("real-time environment"),
        "{}",
        run.stdout
    );
    // The operations' bounds of every axis, defaults resolved.
    assert!(
        run.stdout.contains(
            "axis X: operations: soft limits [-100, 100] while homed, max_speed 40, \
             unhomed_speed 20, max_deceleration 500, limit switches"
        ),
        "{}",
        run.stdout
    );
    let json = supervisor(&["check", "--json"]);
    json.expect_code(0);
    let v: motion_report::CheckReport = serde_json::from_str(&json.stdout).unwrap();
    let z = v.operations.iter().find(|a| a.axis == "Z").unwrap();
    assert_eq!((z.max_deceleration, z.stream_timeout_ms), (200.0, 50.0));
    assert!(!v.operations.iter().find(|a| a.axis == "U").unwrap().movable);
}

#[test]
fn unknown_axis_is_refused() {
    let _serial = serial();
    let run = supervisor(&[
        "home",
        "--axis",
        "W",
        "--service-prefix",
        &unique_prefix("noaxis"),
    ]);
    run.expect_code(2);
    assert!(run.stderr.contains("no axis W"), "{}", run.stderr);
}
