//! `motion-supervisor home --json` end to end, one machine per sequence
//! family (`tests/machines/`, where the arithmetic behind every expected
//! value is), each with a real `motion-io` process behind iceoryx2.
//!
//! Units: positions in units, 1000 counts per unit (the frames carry counts,
//! so every position is known to ±0.0005); 1 kHz cycle.

use motion_harness::{assert_close, *};
use motion_report::HomeReport;

fn home(machine: &str) -> HomeReport {
    let cfg = Machine::fixture(machine).write(machine);
    home_all(&cfg).0
}

#[test]
fn switch_family() {
    let _serial = serial();
    let v = home("switch");
    // A: the switch's edge sampled at 2 u/s, ± 0.001; rests 1 beyond it.
    let a = homed(&v, "A");
    assert_close!(a, event_raw, 5.0, 0.001 + COUNT);
    let e = value(a.event_raw, a);
    assert_close!(a, final_raw, e + 1.0, COUNT);
    assert_close!(a, final_position, 10.0, COUNT);
    // B: latched marker 3.3; rest in [3.7, 3.74].
    let b = homed(&v, "B");
    assert_close!(b, event_raw, 3.3, COUNT);
    let raw = value(b.final_raw, b);
    assert!((3.7 - COUNT..=3.74 + COUNT).contains(&raw), "{b:#?}");
    assert_close!(b, final_position, raw - 3.3, COUNT);
}

#[test]
fn marker_family_on_cyclic_axes() {
    let _serial = serial();
    let v = home("marker");
    let c = homed(&v, "C");
    assert_close!(c, event_raw, 100.0, COUNT);
    assert_close!(c, final_raw, 100.0, COUNT);
    assert_close!(c, final_position, 90.0, COUNT);
    let d = homed(&v, "D");
    assert_close!(d, event_raw, -260.0, COUNT);
    assert_close!(d, final_raw, -305.0, COUNT);
    let p = value(d.final_position, d);
    assert!(!(COUNT..=360.0 - COUNT).contains(&p), "cyclic 0: {d:#?}");
}

#[test]
fn torque_family() {
    let _serial = serial();
    let v = home("torque");
    let e = homed(&v, "E");
    assert_close!(e, event_raw, 50.0, COUNT);
    assert_close!(e, final_raw, 47.0, COUNT);
    assert_close!(e, final_position, 0.0, COUNT);
    let f = homed(&v, "F");
    assert_close!(f, event_raw, -19.0, COUNT);
    assert_close!(f, final_raw, -19.0, COUNT);
    assert_close!(f, final_position, 0.0, COUNT);
}

#[test]
fn passive_and_immediate_family() {
    let _serial = serial();
    let v = home("passive");
    // G: the switch's edge 3 sampled at 4 u/s, ± 0.002.
    let g = homed(&v, "G");
    assert_close!(g, event_raw, 3.0, 0.002 + COUNT);
    // The axis keeps moving: position and raw differ by the redefinition.
    let offset = 50.0 - value(g.event_raw, g);
    assert_close!(g, final_position, value(g.final_raw, g) + offset, COUNT);
    let h = homed(&v, "H");
    assert!(h.event_raw.is_none(), "{h:#?}");
    assert_close!(h, final_raw, 12.5, COUNT);
    assert_close!(h, final_position, 7.0, COUNT);
    let vv = homed(&v, "V");
    assert_close!(vv, final_position, 3.0, 1e-9);
}

#[test]
fn default_machine() {
    let _serial = serial();
    let prefix = unique_prefix("demo");
    let run = supervisor(&["home", "--json", "--service-prefix", &prefix]);
    let v: HomeReport = run.expect_code(0).report();
    // deploy/demo.toml, with the arithmetic in its comments.
    let x = homed(&v, "X");
    assert_close!(x, event_raw, -7.5, COUNT);
    assert_close!(x, final_raw, -7.5, COUNT);
    assert_close!(x, final_position, 0.0, COUNT);
    let c = homed(&v, "C");
    assert_close!(c, event_raw, 123.4, COUNT);
    assert_close!(c, final_raw, 168.4, COUNT);
    let p = value(c.final_position, c);
    assert!(!(COUNT..=360.0 - COUNT).contains(&p), "{c:#?}");
    let z = homed(&v, "Z");
    assert_close!(z, event_raw, -30.0, COUNT);
    assert_close!(z, final_raw, -28.0, COUNT);
    assert_close!(z, final_position, 0.0, COUNT);
    let u = homed(&v, "U");
    assert_close!(u, event_raw, 2.0, COUNT);
    assert_close!(
        u,
        final_position,
        value(u.final_raw, u) - 2.0 + 100.0,
        COUNT
    );
    let names: Vec<&str> = v.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["U", "X", "C", "Z"], "config order");
    assert_clean(&prefix);
}
