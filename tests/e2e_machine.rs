//! A whole machine through real processes: the shipped gantry example
//! (`deploy/gantry.toml`) — home order, a racked gantry, an absolute axis
//! that comes up homed after a restart, and the homing record.
//!
//! Positions: 1000 counts per unit, so every reported position is known to
//! ± one count. Expected values are worked out next to each check.

use motion_harness::{assert_close, *};
use motion_report::HomeReport;
use motion_state::record::{RecordEntry, RecordKind};
use std::time::Duration;

fn record(cfg: &TempConfig) -> Vec<RecordEntry> {
    std::fs::read_to_string(cfg.state_dir.join(motion_state::record::FILE))
        .unwrap_or_default()
        .lines()
        .map(|l| serde_json::from_str(l).expect("a record line"))
        .collect()
}

/// `motion-supervisor home` (home-all): Z (order 0), then Y1, Y2, X
/// together (order 1); W (absolute, no order) is not homed.
///
/// Y1: switch [0, 5], markers every 10 at 2.5: bidirectional forward finds
/// the switch at 0, returns to the first marker beyond the edge, -7.5
/// (latched, exact); rests at -7.5 + home_offset 1 = -6.5 raw, reading 0.
/// Y2 (racked 0.3): marker -7.2, rests at -7.2 + 1.5 = -5.7. Skew 0.3 ± the
/// two switch edges' sampling (R x T = 2 x 0.001 each) ± a count.
#[test]
fn a_two_order_machine_with_a_racked_gantry_homes_in_order() {
    let _serial = serial();
    let cfg = Machine::gantry().write("gantry");
    let run = supervisor(&["home", "--json", "--config", cfg.arg()]);
    let v: HomeReport = run.expect_code(0).report();
    assert!(
        v.axes.iter().all(|a| a.name != "W"),
        "W has no home order: {v:#?}"
    );
    for n in ["Z", "Y1", "Y2", "X"] {
        let a = named(&v.axes, n);
        assert!(a.pc && a.homed, "{a:#?}");
    }
    let (y1, y2) = (named(&v.axes, "Y1"), named(&v.axes, "Y2"));
    assert_close!(y1, event_raw, -7.5, COUNT);
    assert_close!(y2, event_raw, -7.2, COUNT);
    assert_close!(y1, final_raw, -6.5, COUNT);
    assert_close!(y2, final_raw, -5.7, COUNT);
    assert_close!(y1, final_position, 0.0, COUNT);
    assert_close!(y2, final_position, 0.0, COUNT);
    assert_close!(y1, skew, 0.3, 0.005);
    assert_close!(y2, skew, 0.3, 0.005);

    // The record: one line per homing, Z's first. Each line is written when
    // the homing was seen to end (within a few ms); order 1 started after
    // Z ended: its start (end - duration) is not before Z's end.
    let rec = record(&cfg);
    assert_eq!(rec.len(), 4, "{rec:#?}");
    assert_eq!(rec[0].axis, "Z");
    let end_ms = |e: &RecordEntry| e.unix_ms as f64;
    let start_ms = |e: &RecordEntry| end_ms(e) - value(e.duration_s, e) * 1000.0;
    for e in &rec[1..] {
        assert_eq!(e.kind, Some(RecordKind::Homing));
        assert_eq!(e.result, "homed", "{e:#?}");
        assert!(
            start_ms(e) >= end_ms(&rec[0]) - 30.0,
            "{} started before Z ended: {e:#?} / {:#?}",
            e.axis,
            rec[0]
        );
    }
    let y2 = rec.iter().find(|e| e.axis == "Y2").unwrap();
    assert_eq!(y2.gantry.as_deref(), Some("Y"));
    assert!((value(y2.skew, y2) - 0.3).abs() <= 0.005, "{y2:#?}");
    assert_clean(&cfg.prefix);
}

/// W: absolute encoder at raw 37.5, Home Position 250. Homed by name (no
/// motion): offset 250 - 37.5 = 212.5, stored. The next daemon comes up
/// with W homed from the stored reference (position 250) while the
/// incremental axes are not; with W's Home Position changed to 260 the
/// stored reference is invalidated and W comes up unhomed.
#[test]
fn an_absolute_axis_is_homed_at_start_until_its_configuration_changes() {
    let _serial = serial();
    let cfg = Machine::gantry().write("absolute");
    let d = Daemon::start(&cfg, &["io"]);
    assert!(!d.axis("W").homed);
    d.ctl(&["home", "W", "--json"]).expect_code(0);
    let w = d.axis("W");
    assert_close!(w, position, 250.0, COUNT);
    assert_close!(w, raw, 37.5, COUNT);
    assert!(!w.restored);
    d.stop().expect_code(0);

    let d = Daemon::start(&cfg, &["io"]);
    assert!(
        wait_for(Duration::from_secs(5), || d.axis("W").homed),
        "W not restored: {}",
        d.stderr()
    );
    let v = d.status();
    let w = named(&v.axes, "W");
    assert!(w.restored, "{w:#?}");
    assert!(!w.pc, "no instruction ran");
    assert_close!(w, position, 250.0, COUNT);
    assert!(!named(&v.axes, "Y1").homed);
    d.stop().expect_code(0);
    let rec = record(&cfg);
    assert_eq!(
        rec.last().unwrap().kind,
        Some(RecordKind::Restored),
        "{rec:#?}"
    );

    // Home Position changed; the same state directory as before, another prefix.
    let changed = Machine::gantry()
        .set("axis.W.home_position", 260.0)
        .set("supervisor.state_dir", cfg.state_dir.display().to_string())
        .write("absolute_changed");
    let d = Daemon::start(&changed, &["io"]);
    assert!(
        d.wait_line(
            "stored reference invalidated: axis configuration changed: home_position 250 → 260",
            Duration::from_secs(5)
        ),
        "{}",
        d.stderr()
    );
    std::thread::sleep(Duration::from_millis(300));
    let w = d.axis("W");
    assert!(!w.homed, "{w:#?}");
    assert!(
        w.warnings
            .iter()
            .any(|x| x.contains("stored reference invalidated")),
        "{w:#?}"
    );
    d.stop().expect_code(0);
    let rec = record(&cfg);
    let last = rec.last().unwrap();
    assert_eq!(last.kind, Some(RecordKind::Invalidated));
    assert_eq!(
        last.reason.as_deref(),
        Some("axis configuration changed: home_position 250 → 260")
    );
    assert_clean(&cfg.prefix);
    assert_clean(&changed.prefix);
}

/// Waits (at most 10 s) until W is homed; its status then.
#[track_caller]
fn wait_homed_w(d: &Daemon) -> motion_report::AxisStatus {
    assert!(
        wait_for(Duration::from_secs(10), || d.axis("W").homed),
        "W not homed: {}",
        d.stderr()
    );
    d.axis("W")
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
    let w = wait_homed_w(&d);
    assert_close!(w, position, 250.0, COUNT);
    d.ctl(&["redefine", "W", "--position", "260"])
        .expect_code(0);
    assert!(wait_for(Duration::from_secs(5), || d.axis("W").op_kind == "redefine"));
    let w = d.axis("W");
    assert!(w.op_pc, "{w:#?}");
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
    let w = wait_homed_w(&d);
    assert!(w.restored && !w.pc, "{w:#?}");
    assert_close!(w, position, 260.0, COUNT);
    assert_eq!(
        (w.soft_limit_negative, w.soft_limit_positive),
        (Some(10.0), Some(410.0))
    );
    d.stop().expect_code(0);
    assert_clean(&cfg.prefix);
}
