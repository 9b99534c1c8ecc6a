//! Gearing (MAG) end to end, through real processes: the daemon and its
//! `motion-io` (sim), `motionctl gear`, `jog`, `stop` and `status`. The
//! machine is `tests/machines/ops.toml`: X and Z (immediate homing, soft
//! limits ±20 while homed, max_speed 20). Z is geared to X.
//!
//! Every wait is for a state of the status service, never a time.

use motion_harness::*;
use motion_report::AxisStatus;

/// The commanded position (axis coordinates).
fn cmd(a: &AxisStatus) -> f64 {
    value(a.cmd_position, &a.name)
}

#[test]
fn a_geared_slave_follows_its_jogged_master_by_the_ratio_until_a_stop() {
    let _serial = serial();
    let cfg = Machine::fixture("ops").write("gear_follow");
    let d = Daemon::start(&cfg, &["io"]);
    d.ctl(&["home", "X", "Z"]).expect_code(0);
    d.ctl(&["enable", "X", "Z"]).expect_code(0);
    d.wait_axis("X", 5, |a| a.homed && a.servo_action);
    d.wait_axis("Z", 5, |a| a.homed && a.servo_action);

    // refused: itself, a ratio of 0, an unknown master
    d.refused_with(&["gear", "Z", "--master", "Z", "--ratio", "1"], 1025, 4);
    d.refused_with(&["gear", "Z", "--master", "X", "--ratio", "0"], 13, 9);
    assert_ne!(
        d.ctl(&["gear", "Z", "--master", "Q", "--ratio", "1"])
            .code(),
        Some(0)
    );
    assert!(!d.axis("Z").gearing);

    // geared at -0.5: the master jogs +4 u/s for 1 s, the slave follows
    d.ctl(&["gear", "Z", "--master", "X", "--ratio", "-0.5"])
        .expect_code(0);
    let z = d.wait_axis("Z", 5, |a| a.gearing);
    assert!(!z.er, "{z:#?}");
    d.ctl(&["jog", "X", "--speed", "4", "--for", "1"])
        .expect_code(0);
    let x = d.wait_axis("X", 5, |a| !a.jogging && !a.stopping && !a.op_ip);
    let z = d.wait_axis("Z", 5, |a| (cmd(a) + 0.5 * cmd(&x)).abs() <= COUNT);
    assert!(cmd(&x) > 3.0, "{x:#?}");
    assert!(
        z.gearing && !z.er,
        "the master's jog ending is no stop: {z:#?}"
    );

    // a stop of the slave ends it, normally
    d.ctl(&["stop", "Z"]).expect_code(0);
    let z = d.wait_axis("Z", 5, at_rest);
    assert!(!z.er && z.enabled, "{z:#?}");

    // geared again: a stop of the master ends it too
    d.ctl(&["gear", "Z", "--master", "X", "--ratio", "1"])
        .expect_code(0);
    d.wait_axis("Z", 5, |a| a.gearing);
    d.ctl(&["stop", "X"]).expect_code(0);
    let z = d.wait_axis("Z", 5, at_rest);
    assert!(!z.er, "{z:#?}");
    d.stop().expect_code(0);
    assert_clean(&cfg.prefix);
}

#[test]
fn a_slave_at_its_travel_limit_stops_inside_it_and_stops_its_master() {
    let _serial = serial();
    let cfg = Machine::fixture("ops").write("gear_limit");
    let d = Daemon::start(&cfg, &["io"]);
    d.ctl(&["home", "X", "Z"]).expect_code(0);
    d.ctl(&["enable", "X", "Z"]).expect_code(0);
    d.wait_axis("Z", 5, |a| a.homed && a.servo_action);
    d.wait_axis("X", 5, |a| a.homed && a.servo_action);

    // ratio 4: Z reaches its limit 20 when X is at 5
    d.ctl(&[
        "gear", "Z", "--master", "X", "--ratio", "4", "--clutch", "50",
    ])
    .expect_code(0);
    let r = d.ctl(&["jog", "X", "--speed", "4", "--for", "10"]);
    assert!(r.code().is_some(), "{}", r.stderr);
    let z = d.wait_axis("Z", 10, |a| a.er && !a.stopping);
    assert_eq!((z.err, z.exerr), (1025, 1), "{z:#?}");
    assert!(!z.gearing && cmd(&z) <= 20.0 + COUNT, "{z:#?}");
    let x = d.wait_axis("X", 5, |a| !a.jogging && !a.stopping);
    assert!(!x.er && cmd(&x) < 5.5, "the master was stopped: {x:#?}");
    d.stop().expect_code(0);
    assert_clean(&cfg.prefix);
}
