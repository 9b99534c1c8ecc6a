//! S-curve moves and MCD `change` end to end, through real processes: the
//! daemon and its `motion-io` (sim) driven by `motionctl`. The machine is
//! `tests/machines/ops.toml` (X: immediate homing, soft limits ±20 while
//! homed, home speed 10, max_speed 20, acceleration and deceleration 100)
//! with `jerk = 400` on X: its moves are S-curves unless a request says
//! otherwise.
//!
//! Everything is checked through `status --json` states (an axis moving,
//! its velocity, its operation id, PC, its position), never wall-clock
//! times.

use motion_harness::*;
use motion_report::{AxisStatus, MotionReport};
use std::time::Duration;

fn speed(a: &AxisStatus) -> f64 {
    value(a.velocity, &a.name).abs()
}

#[test]
fn an_s_curve_move_and_a_change_through_motionctl() {
    let _serial = serial();
    let cfg = Machine::fixture("ops")
        .set("axis.X.jerk", 400.0)
        .write("scurve");
    let d = Daemon::start(&cfg, &["io"]);
    d.ctl(&["enable", "X"]).expect_code(0);
    d.wait_axis("X", 5, |a| a.servo_action);
    d.ctl(&["home", "X"]).expect_code(0);
    d.wait_axis("X", 5, |a| a.homed && at_rest(a));

    // An S-curve move with its own jerk, followed to its end: PC, on the
    // target.
    let r = d.ctl(&["move", "X", "--to", "5", "--jerk", "1000", "--json"]);
    let m: MotionReport = r.expect_code(0).report();
    let row = &m.axes[0];
    assert!(row.pc && !row.er, "{}", r.stdout);
    assert!(
        (value(row.position, "X") - 5.0).abs() <= 2.0 * COUNT,
        "{row:#?}"
    );

    // Nothing runs: a change is refused (3 / 1).
    d.refused_with(&["change", "X", "--speed", "5"], 3, 1);

    // A slow move (2 u/s, the axis's jerk), followed by a motionctl of its
    // own. A change beyond max_deceleration or max_speed is refused (13 /
    // 3, 13 / 1) and leaves it running; changed to 15 u/s, the motion
    // speeds up (a state 2 u/s never reaches), keeps its operation, and the
    // motionctl that follows it reports its end at the target.
    let mut follower = spawn_motionctl(&[
        "--service-prefix",
        &cfg.prefix,
        "move",
        "X",
        "--to",
        "-15",
        "--speed",
        "2",
        "--json",
    ]);
    let before = d.wait_axis("X", 5, |a| a.moving && speed(a) > 1.5);
    d.refused_with(&["change", "X", "--decel", "1000"], 13, 3);
    d.refused_with(&["change", "X", "--speed", "25"], 13, 1);
    assert!(
        d.axis("X").moving,
        "a refused change leaves the move running"
    );
    d.ctl(&["change", "X", "--speed", "15", "--jerk", "2000"])
        .expect_code(0);
    let fast = d.wait_axis("X", 10, |a| speed(a) > 10.0 || !a.moving);
    assert!(fast.moving && speed(&fast) > 10.0, "{fast:#?}");
    assert_eq!(
        fast.op_id, before.op_id,
        "the change kept the move's operation"
    );
    let end = follower.wait_exit(Duration::from_secs(30));
    assert_eq!(end.and_then(|s| s.code()), Some(0), "{}", follower.stderr());
    let x = d.wait_axis("X", 5, at_rest);
    assert!(x.op_pc && !x.er, "{x:#?}");
    assert!(
        (value(x.position, "X") + 15.0).abs() <= 2.0 * COUNT,
        "{x:#?}"
    );

    d.stop().expect_code(0);
    assert_clean(&cfg.prefix);
}
