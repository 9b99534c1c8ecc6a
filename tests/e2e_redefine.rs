//! Redefine position (MRP) end to end, through real processes: the daemon
//! and its `motion-io` (sim), `motionctl`. Only the offset between the
//! axis's positions and the machine changes: the status shows the shifted
//! position and soft limits, a move to a limit still ends at the same
//! machine place (raw), and an absolute axis reads the redefined position
//! after a daemon restart.
//!
//! Positions: 1000 counts per unit, so every reported one is known to ±
//! one count. States are waited for, never wall-clock times.

use motion_harness::{assert_close, *};
use motion_report::{AxisStatus, MotionReport};
use motion_state::record::{RecordEntry, RecordKind};
use std::time::Duration;

#[track_caller]
fn wait_axis(d: &Daemon, name: &str, f: impl Fn(&AxisStatus) -> bool) -> AxisStatus {
    let mut last = AxisStatus::default();
    let ok = wait_for(Duration::from_secs(10), || {
        last = d.axis(name);
        f(&last)
    });
    assert!(ok, "{name} never got there: {last:#?}");
    last
}

fn record(cfg: &TempConfig) -> Vec<RecordEntry> {
    std::fs::read_to_string(cfg.state_dir.join(motion_state::record::FILE))
        .unwrap_or_default()
        .lines()
        .map(|l| serde_json::from_str(l).expect("a record line"))
        .collect()
}

/// X of `tests/machines/ops.toml`: immediate homing at raw 0 (position 0),
/// soft limits [-20, 20]. `redefine X --by 5`: position 5, limits read
/// [-15, 25], raw unchanged; a move to 25 ends on raw 20 (the same machine
/// place as the limit before), 25.5 is refused (13 / 4); Z (not homed)
/// refuses (1021 / 1).
#[test]
fn redefine_by_shifts_the_position_and_the_limits_numbers_not_the_machine() {
    let _serial = serial();
    let cfg = Machine::fixture("ops").write("redefine_by");
    let d = Daemon::start(&cfg, &["io"]);
    d.ctl(&["home", "X"]).expect_code(0);
    d.ctl(&["enable", "X"]).expect_code(0);
    let x = wait_axis(&d, "X", |a| a.homed && a.servo_action && !a.op_ip);
    assert_close!(x, position, 0.0, COUNT);
    assert_eq!(
        (x.soft_limit_negative, x.soft_limit_positive),
        (Some(-20.0), Some(20.0))
    );
    let raw_before = value(x.raw, "X");

    d.ctl(&["redefine", "X", "--by", "5"]).expect_code(0);
    let x = wait_axis(&d, "X", |a| a.op_kind == "redefine" && a.op_pc);
    assert_close!(x, position, 5.0, COUNT);
    assert_close!(x, cmd_position, 5.0, 1e-9);
    assert_close!(x, raw, raw_before, COUNT);
    assert!(x.homed && !x.er, "{x:#?}");
    // `status --json` shows the shifted limits.
    let v = d.status();
    let row = named(&v.axes, "X");
    assert_eq!(
        (row.soft_limit_negative, row.soft_limit_positive),
        (Some(-15.0), Some(25.0))
    );

    // Past the shifted limit: refused; to it: ends on the same machine place.
    let r = d.ctl(&["move", "X", "--to", "25.5", "--json"]);
    assert!(
        r.expect_code(1).stdout.contains("\"err\":13"),
        "{}",
        r.stdout
    );
    let r = d.ctl(&["move", "X", "--to", "25", "--json"]);
    let m: MotionReport = r.expect_code(0).report();
    assert!(m.axes[0].pc, "{}", r.stdout);
    let x = wait_axis(&d, "X", |a| !a.moving && !a.stopping);
    assert_close!(x, position, 25.0, COUNT);
    assert_close!(x, raw, 20.0, COUNT);
    // A jog further out is refused at the limit (13 / 4), as before.
    let r = d.ctl(&["jog", "X", "--speed", "1", "--json"]);
    assert!(
        r.expect_code(1).stdout.contains("\"exerr\":4"),
        "{}",
        r.stdout
    );

    // Not homed: refused with its code, nothing changes.
    let r = d.ctl(&["redefine", "Z", "--position", "3", "--json"]);
    let out = r.expect_code(1).stdout.clone();
    assert!(
        out.contains("\"err\":1021") && out.contains("\"exerr\":1"),
        "{out}"
    );
    let z = d.axis("Z");
    assert_close!(z, position, 0.0, COUNT);
    d.stop().expect_code(0);
    assert_clean(&cfg.prefix);
}

/// W of the gantry example: absolute, Home Position 250 at raw 37.5.
/// Homed, then `redefine W --position 260`: reads 260 (raw 37.5); the
/// record has a `redefined` line; a new daemon restores W reading 260 with
/// its limits [0, 400] read [10, 410] — the same machine places.
#[test]
fn an_absolute_axis_keeps_its_redefined_position_over_a_restart() {
    let _serial = serial();
    let cfg = Machine::gantry().write("redefine_abs");
    let d = Daemon::start(&cfg, &["io"]);
    d.ctl(&["home", "W", "--json"]).expect_code(0);
    let w = wait_axis(&d, "W", |a| a.homed);
    assert_close!(w, position, 250.0, COUNT);
    d.ctl(&["redefine", "W", "--position", "260"])
        .expect_code(0);
    let w = wait_axis(&d, "W", |a| a.op_kind == "redefine" && a.op_pc);
    assert_close!(w, position, 260.0, COUNT);
    assert_close!(w, raw, 37.5, COUNT);
    // The keeper writes the record line and the reference on its next look.
    assert!(
        wait_for(Duration::from_secs(5), || record(&cfg)
            .iter()
            .any(|e| e.kind == Some(RecordKind::Redefined))),
        "{:#?}",
        record(&cfg)
    );
    let e = record(&cfg)
        .into_iter()
        .rfind(|e| e.kind == Some(RecordKind::Redefined))
        .unwrap();
    assert_eq!((e.axis.as_str(), e.result.as_str()), ("W", "redefined"));
    assert!(e.shift.is_some_and(|x| (x - 10.0).abs() < 1e-6), "{e:#?}");
    assert!(
        e.position.is_some_and(|x| (x - 260.0).abs() < 1e-6),
        "{e:#?}"
    );
    d.stop().expect_code(0);

    let d = Daemon::start(&cfg, &["io"]);
    let w = wait_axis(&d, "W", |a| a.homed);
    assert!(w.restored && !w.pc, "{w:#?}");
    assert_close!(w, position, 260.0, COUNT);
    assert_eq!(
        (w.soft_limit_negative, w.soft_limit_positive),
        (Some(10.0), Some(410.0))
    );
    d.stop().expect_code(0);
    assert_clean(&cfg.prefix);
}
