//! Homing with limit switches through real processes: the fixture machine
//! `limits` (`tests/machines/limits.toml`, where the arithmetic behind each
//! expected value is) on the `sim` backend and on `ecat-emu`'s CiA 402
//! drives over a veth pair (0x60FD bits 0/1 → the frames' overtravel bits;
//! probe 2 wired to the limit for registration), and the shipped example
//! `deploy/limit_switch.toml` through `motion-supervisor check` and `home`.
//!
//! Units: 1000 counts per unit: a latched event is exact to the count; a
//! sampled edge is within R·T/2 on the sim and R·T over EtherCAT (two
//! clocks of one period, see e2e_ethercat.rs).

use motion_harness::ecat::Bus;
use motion_harness::{assert_close, *};
use motion_report::{AxisResult, HomeReport};

/// The limit switches of the fixture's axes (raw): no axis may rest on one.
fn off_the_limits(a: &AxisResult, lo: f64, hi: f64) {
    let raw = value(a.final_raw, a);
    assert!(lo < raw && raw < hi, "{} rests on a limit: {a:#?}", a.name);
}

/// The expected values of `tests/machines/limits.toml`; `sampled`: the
/// bound of a sampled edge on this backend.
fn check_limits_machine(v: &HomeReport, sampled: f64, in_flight: f64) {
    let l = homed(v, "L");
    assert_eq!(
        (l.sequence.as_str(), l.direction.as_str()),
        ("limit_switch_then_marker", "bidirectional_reverse")
    );
    assert_close!(l, event_raw, -37.5, COUNT);
    assert_close!(l, final_raw, -35.5, in_flight);
    assert_close!(l, final_position, 0.0, in_flight);
    off_the_limits(l, -40.0, 40.0);

    let m = homed(v, "M");
    assert_close!(m, event_raw, 40.0, sampled + COUNT);
    let e = value(m.event_raw, m);
    assert_close!(m, final_raw, e - 2.0, in_flight);
    assert_close!(m, final_position, 0.0, in_flight);
    off_the_limits(m, -40.0, 40.0);

    let r = homed(v, "R");
    assert_close!(r, event_raw, -30.0, COUNT);
    assert_close!(r, final_raw, -29.0, in_flight);
    off_the_limits(r, -30.0, 30.0);

    let n = homed(v, "N");
    assert_close!(n, event_raw, -7.5, COUNT);
    assert_close!(n, final_raw, -7.5, in_flight);
    assert_close!(n, final_position, 0.0, in_flight);
}

#[test]
fn limit_switch_homing_on_the_sim() {
    let _serial = serial();
    let cfg = Machine::fixture("limits").write("limits");
    let (v, _) = home_all(&cfg);
    // sampled at R = 2 u/s once per 1 ms cycle: ± 0.001
    check_limits_machine(&v, 0.001, COUNT);
}

#[test]
fn limit_switch_homing_over_ethercat() {
    let _serial = serial();
    let Some(b) = Bus::start("ecat_limits", &Machine::fixture("limits"), |_| {}) else {
        return;
    };
    let (v, _) = home_all(&b.cfg);
    // A sampled edge over EtherCAT: ± one cycle of travel (0.002); the last
    // set-points of a move may still be on their way (5 counts).
    check_limits_machine(&v, 0.002, 5.0 * COUNT);
    // The drives' plants rest where the engine left them: off the limits.
    for (k, want) in [(0, -35.5), (2, -29.0), (3, -7.5)] {
        let d = b.drive(k).drive;
        assert!(
            (d.position - want).abs() <= COUNT,
            "drive {k} at {}",
            d.position
        );
    }
}

const DEPLOY: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../deploy/limit_switch.toml");

/// `motion-supervisor check` accepts the shipped example and says how each
/// axis homes on or reverses at its limit switches.
#[test]
fn the_deploy_example_checks() {
    let run = supervisor(&["check", "--config", DEPLOY]);
    run.expect_code(0);
    for want in [
        "axis X: home_sequence limit_switch_then_marker: homes on its negative limit switch \
         (CiA 402 homing method 1, PLCopen MC_StepLimitSwitch + MC_StepReferencePulse)",
        "axis Y: home_reverse_at_limit: a search that meets the positive limit switch before \
         the home switch reverses",
        "(CiA 402 homing method 7,",
        "axis Z: home_sequence limit_switch: homes on its positive limit switch \
         (CiA 402 homing method 18",
    ] {
        assert!(run.stdout.contains(want), "no {want:?} in\n{}", run.stdout);
    }
}

/// The shipped example homes on the sim (its own prefix and state dir):
/// the values of its comments.
#[test]
fn the_deploy_example_homes() {
    let _serial = serial();
    let text = std::fs::read_to_string(DEPLOY).unwrap();
    let cfg = Machine::parse(&text)
        .without("supervisor")
        .write("deploy_limits");
    let (v, _) = home_all(&cfg);
    let x = homed(&v, "X");
    assert_close!(x, event_raw, -4.0, COUNT);
    assert_close!(x, final_raw, -2.0, COUNT);
    assert_close!(x, final_position, 0.0, COUNT);
    let y = homed(&v, "Y");
    assert_close!(y, event_raw, 196.0, COUNT);
    assert_close!(y, final_position, 0.0, COUNT);
    let z = homed(&v, "Z");
    assert_close!(z, event_raw, 5.0, COUNT);
    assert_close!(z, final_raw, 0.0, COUNT);
    let names: Vec<&str> = v.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["X", "Y", "Z"], "rows in config order");
}
