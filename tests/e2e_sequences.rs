//! `motion-supervisor home --json` end to end, one config per sequence
//! family, each with a real `motion-io` process behind iceoryx2.
//!
//! Units: positions in units, 1000 counts per unit (the frames carry counts,
//! so every position is known to ±0.0005); 1 kHz cycle. Arithmetic for each
//! expected value is next to it.

use motion_tests::*;

const COMMON: &str = "counts_per_unit = 1000.0\nhome_timeout = 30.0\n";

fn home(cfg: &TempConfig) -> serde_json::Value {
    let run = supervisor(&["home", "--json", "--config", cfg.path.to_str().unwrap()]);
    assert_eq!(
        run.code,
        Some(0),
        "home failed\nstdout: {}\nstderr: {}",
        run.stdout,
        run.stderr
    );
    let v = run.json();
    let lat = &v["latency"];
    assert!(lat["cycles"].as_u64().unwrap() > 500, "{lat}");
    for k in ["wakeup_us", "compute_us", "io_roundtrip_us"] {
        for p in ["min", "p50", "p99", "p999", "max"] {
            assert!(lat[k][p].is_number(), "{k}.{p} missing: {lat}");
        }
    }
    assert!(lat["deadline_misses"].is_u64());
    assert_clean(&cfg.prefix);
    v
}

fn homed(v: &serde_json::Value, name: &str) -> serde_json::Value {
    let a = axis(v, name).clone();
    assert_eq!(a["pc"], true, "{a}");
    assert_eq!(a["er"], false, "{a}");
    assert_eq!(a["homed"], true, "{a}");
    assert!(num(&a, "duration_s") >= 0.0, "{a}");
    a
}

#[test]
fn switch_family() {
    let _serial = serial();
    let cfg = config(
        "switch",
        "",
        &format!(
            r#"
# Bidirectional switch, reverse, offset +1, Home Position 10.
# Seek -20 u/s from 20 meets the switch's upper edge 5; back at +2 u/s it
# clears 5 again: event 5 ± (2 u/s x 1 ms / 2 = 0.001) ± a count.
# Rest at event + 1 = 6, which reads Home Position 10.
[[axis]]
name = "A"
{COMMON}
home_sequence = "switch"
home_direction = "bidirectional_reverse"
home_position = 10.0
home_offset = 1.0
home_speed = 20.0
home_return_speed = 2.0
home_acceleration = 500.0
home_deceleration = 500.0
travel_limits = [-100.0, 100.0]
[axis.sim]
start = 20.0
switch = [0.0, 5.0]
hard_stop = [-100.0, 100.0]

# Unidirectional switch then marker, forward, normally-closed switch.
# Seek +20 u/s from -10 detects the switch at 0, the first marker after it
# is 3.3 (markers every 5 at 3.3): event 3.3, exact (latched).
# Offset 0: decelerate past it, V^2/2D = 400/1000 = 0.4, plus up to two
# cycles of travel (0.04): rest in [3.7, 3.74], reading [0.4, 0.44].
[[axis]]
name = "B"
{COMMON}
marker = true
home_sequence = "switch_then_marker"
home_direction = "unidirectional_forward"
home_switch_normally_closed = true
home_speed = 20.0
home_acceleration = 500.0
home_deceleration = 500.0
[axis.sim]
start = -10.0
switch = [0.0, 2.0]
marker_every = 5.0
marker_at = 3.3
"#
        ),
    );
    let v = home(&cfg);
    let a = homed(&v, "A");
    close(&a, "event_raw", 5.0, 0.001 + COUNT);
    let e = num(&a, "event_raw");
    close(&a, "final_raw", e + 1.0, COUNT);
    close(&a, "final_position", 10.0, COUNT);
    let b = homed(&v, "B");
    close(&b, "event_raw", 3.3, COUNT);
    let raw = num(&b, "final_raw");
    assert!((3.7 - COUNT..=3.74 + COUNT).contains(&raw), "{b}");
    close(&b, "final_position", raw - 3.3, COUNT);
}

#[test]
fn marker_family_on_cyclic_axes() {
    let _serial = serial();
    let cfg = config(
        "marker",
        "",
        &format!(
            r#"
# Cyclic 360, bidirectional marker, forward, Home Position 90.
# One marker per revolution at 100: event 100 (latched). Decelerate
# (90^2/1440 = 5.6 deg past), come back to 100 the short way: rest at raw 100,
# reading 90.
[[axis]]
name = "C"
{COMMON}
travel = "cyclic"
unwind = 360.0
marker = true
home_sequence = "marker"
home_direction = "bidirectional_forward"
home_position = 90.0
home_speed = 90.0
home_return_speed = 10.0
home_acceleration = 720.0
home_deceleration = 720.0
[axis.sim]
start = 0.0
marker_every = 360.0
marker_at = 100.0

# Cyclic 360, unidirectional marker, reverse, offset -45 (ahead in the
# direction of travel, farther than the 5.6 deg stopping distance).
# Reverse from 0 the first marker is 100 - 360 = -260: event -260.
# Home Position 0 lies 45 further on: raw -305, never reversing.
[[axis]]
name = "D"
{COMMON}
travel = "cyclic"
unwind = 360.0
marker = true
home_sequence = "marker"
home_direction = "unidirectional_reverse"
home_position = 0.0
home_offset = -45.0
home_speed = 90.0
home_acceleration = 720.0
home_deceleration = 720.0
[axis.sim]
start = 0.0
marker_every = 360.0
marker_at = 100.0
"#
        ),
    );
    let v = home(&cfg);
    let c = homed(&v, "C");
    close(&c, "event_raw", 100.0, COUNT);
    close(&c, "final_raw", 100.0, COUNT);
    close(&c, "final_position", 90.0, COUNT);
    let d = homed(&v, "D");
    close(&d, "event_raw", -260.0, COUNT);
    close(&d, "final_raw", -305.0, COUNT);
    let p = num(&d, "final_position");
    assert!(!(COUNT..=360.0 - COUNT).contains(&p), "cyclic 0: {d}");
}

#[test]
fn torque_family() {
    let _serial = serial();
    let cfg = config(
        "torque",
        "",
        &format!(
            r#"
# Torque, forward into the hard stop at 50, offset -3 (away from the stop).
# The stop clamps the position at 50 while torque builds past 25 % for
# 20 ms: event 50 exactly. Release, then back to 50 - 3 = 47, reading 0.
[[axis]]
name = "E"
{COMMON}
home_sequence = "torque"
home_direction = "bidirectional_forward"
home_offset = -3.0
home_speed = 10.0
home_return_speed = 2.0
home_acceleration = 200.0
home_deceleration = 200.0
home_torque_level = 40.0
home_torque_threshold = 25.0
home_torque_time = 0.02
position_error_tolerance = 0.5
[axis.sim]
start = 0.0
hard_stop = [-100.0, 50.0]

# Torque then marker, reverse: hard stop at -20, then forward to the first
# marker (every 4 at 1: ..., -23, -19, ...): event -19, rest there (offset 0).
[[axis]]
name = "F"
{COMMON}
marker = true
home_sequence = "torque_then_marker"
home_direction = "bidirectional_reverse"
home_speed = 10.0
home_return_speed = 2.0
home_acceleration = 200.0
home_deceleration = 200.0
home_torque_level = 40.0
home_torque_threshold = 25.0
home_torque_time = 0.02
[axis.sim]
start = 0.0
hard_stop = [-20.0, 100.0]
marker_every = 4.0
marker_at = 1.0
"#
        ),
    );
    let v = home(&cfg);
    let e = homed(&v, "E");
    close(&e, "event_raw", 50.0, COUNT);
    close(&e, "final_raw", 47.0, COUNT);
    close(&e, "final_position", 0.0, COUNT);
    let f = homed(&v, "F");
    close(&f, "event_raw", -19.0, COUNT);
    close(&f, "final_raw", -19.0, COUNT);
    close(&f, "final_position", 0.0, COUNT);
}

#[test]
fn passive_and_immediate_family() {
    let _serial = serial();
    let cfg = config(
        "passive",
        "",
        &format!(
            r#"
# Passive switch on a feedback-only axis moved at -4 u/s from 10: the switch
# [2, 3] is detected at its upper edge 3 ± (4 x 0.001 / 2 = 0.002); that
# point reads Home Position 50.
[[axis]]
name = "G"
{COMMON}
configuration = "feedback_only"
home_mode = "passive"
home_sequence = "switch"
home_position = 50.0
[axis.sim]
start = 10.0
switch = [2.0, 3.0]
external_speed = -4.0

# Active immediate: no motion, the position 12.5 becomes Home Position 7.
[[axis]]
name = "H"
{COMMON}
home_sequence = "immediate"
home_position = 7.0
[axis.sim]
start = 12.5

# Virtual axis, immediate: no hardware; its position (0) becomes 3.
[[axis]]
name = "V"
{COMMON}
configuration = "virtual"
home_sequence = "immediate"
home_position = 3.0
"#
        ),
    );
    let v = home(&cfg);
    let g = homed(&v, "G");
    close(&g, "event_raw", 3.0, 0.002 + COUNT);
    // The axis keeps moving: position and raw differ by the redefinition.
    let offset = 50.0 - num(&g, "event_raw");
    close(&g, "final_position", num(&g, "final_raw") + offset, COUNT);
    let h = homed(&v, "H");
    assert!(h["event_raw"].is_null());
    close(&h, "final_raw", 12.5, COUNT);
    close(&h, "final_position", 7.0, COUNT);
    let vv = homed(&v, "V");
    close(&vv, "final_position", 3.0, 1e-9);
}

#[test]
fn default_machine() {
    let _serial = serial();
    let prefix = unique_prefix("demo");
    let run = supervisor(&["home", "--json", "--service-prefix", &prefix]);
    assert_eq!(run.code, Some(0), "{}\n{}", run.stdout, run.stderr);
    let v = run.json();
    // deploy/demo.toml, with the arithmetic in its comments.
    let x = homed(&v, "X");
    close(&x, "event_raw", -7.5, COUNT);
    close(&x, "final_raw", -7.5, COUNT);
    close(&x, "final_position", 0.0, COUNT);
    let c = homed(&v, "C");
    close(&c, "event_raw", 123.4, COUNT);
    close(&c, "final_raw", 168.4, COUNT);
    let p = num(&c, "final_position");
    assert!(!(COUNT..=360.0 - COUNT).contains(&p), "{c}");
    let z = homed(&v, "Z");
    close(&z, "event_raw", -30.0, COUNT);
    close(&z, "final_raw", -28.0, COUNT);
    close(&z, "final_position", 0.0, COUNT);
    let u = homed(&v, "U");
    close(&u, "event_raw", 2.0, COUNT);
    close(
        &u,
        "final_position",
        num(&u, "final_raw") - 2.0 + 100.0,
        COUNT,
    );
    let names: Vec<&str> = v["axes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["U", "X", "C", "Z"], "config order");
    assert_clean(&prefix);
}
