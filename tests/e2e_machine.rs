//! A whole machine through real processes: the shipped gantry example
//! (`deploy/gantry.toml`) — home order, a racked gantry, an absolute axis
//! that comes up homed after a restart, and the homing record.
//!
//! Positions: 1000 counts per unit, so every reported position is known to
//! ± one count. Expected values are worked out next to each check.

use motion_tests::*;
use std::time::Duration;

/// The example's axes and gantry under a test's own `[supervisor]` (unique
/// prefix, its own state directory); `edit` changes the axis text.
fn gantry_machine(tag: &str, edit: impl Fn(&str) -> String) -> TempConfig {
    let text = motion_config::GANTRY_TOML;
    let axes = &text[text.find("[[axis]]").expect("axes")..];
    config(tag, "", &edit(axes))
}

fn record(cfg: &TempConfig) -> Vec<serde_json::Value> {
    std::fs::read_to_string(cfg.state_dir.join("homing-record.jsonl"))
        .unwrap_or_default()
        .lines()
        .map(|l| serde_json::from_str(l).expect("record line is JSON"))
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
    let cfg = gantry_machine("gantry", str::to_string);
    let run = supervisor(&["home", "--json", "--config", cfg.path.to_str().unwrap()]);
    assert_eq!(run.code, Some(0), "{}\n{}", run.stdout, run.stderr);
    let v = run.json();
    let names: Vec<&str> = v["axes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["name"].as_str().unwrap())
        .collect();
    assert!(!names.contains(&"W"), "W has no home order: {names:?}");
    for n in ["Z", "Y1", "Y2", "X"] {
        let a = axis(&v, n);
        assert_eq!(
            (a["pc"].clone(), a["homed"].clone()),
            (true.into(), true.into()),
            "{a}"
        );
    }
    let (y1, y2) = (axis(&v, "Y1"), axis(&v, "Y2"));
    close(y1, "event_raw", -7.5, COUNT);
    close(y2, "event_raw", -7.2, COUNT);
    close(y1, "final_raw", -6.5, COUNT);
    close(y2, "final_raw", -5.7, COUNT);
    close(y1, "final_position", 0.0, COUNT);
    close(y2, "final_position", 0.0, COUNT);
    close(y1, "skew", 0.3, 0.005);
    close(y2, "skew", 0.3, 0.005);

    // The record: one line per homing, Z's first. Each line is written when
    // the homing was seen to end (within a few ms); order 1 started after
    // Z ended: its start (end - duration) is not before Z's end.
    let rec = record(&cfg);
    assert_eq!(rec.len(), 4, "{rec:#?}");
    assert_eq!(rec[0]["axis"], "Z");
    let end_ms = |e: &serde_json::Value| e["unix_ms"].as_f64().unwrap();
    let start_ms = |e: &serde_json::Value| end_ms(e) - num(e, "duration_s") * 1000.0;
    for e in &rec[1..] {
        assert_eq!(e["kind"], "homing");
        assert_eq!(e["result"], "homed", "{e}");
        assert!(
            start_ms(e) >= end_ms(&rec[0]) - 30.0,
            "{} started before Z ended: {e} / {}",
            e["axis"],
            rec[0]
        );
    }
    let y2 = rec.iter().find(|e| e["axis"] == "Y2").unwrap();
    assert_eq!(y2["gantry"], "Y");
    close(y2, "skew", 0.3, 0.005);
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
    let cfg = gantry_machine("absolute", str::to_string);
    let d = Daemon::start(&cfg, &["io"]);
    assert_eq!(axis(&d.status(), "W")["homed"], false);
    let r = ctl(&cfg.prefix, &["home", "W", "--json"]);
    assert_eq!(r.code, Some(0), "{}\n{}", r.stdout, r.stderr);
    let w = axis(&d.status(), "W").clone();
    close(&w, "position", 250.0, COUNT);
    close(&w, "raw", 37.5, COUNT);
    assert_eq!(w["restored"], false);
    assert_eq!(d.stop().code, Some(0));

    let d = Daemon::start(&cfg, &["io"]);
    assert!(
        wait_for(Duration::from_secs(5), || axis(&d.status(), "W")["homed"]
            == true),
        "W not restored: {}",
        d.stderr()
    );
    let v = d.status();
    let w = axis(&v, "W");
    assert_eq!(w["restored"], true, "{w}");
    assert_eq!(w["pc"], false, "no instruction ran");
    close(w, "position", 250.0, COUNT);
    assert_eq!(axis(&v, "Y1")["homed"], false);
    assert_eq!(d.stop().code, Some(0));
    let rec = record(&cfg);
    assert_eq!(rec.last().unwrap()["kind"], "restored", "{rec:#?}");

    let changed = gantry_machine("absolute_changed", |axes| {
        axes.replace("home_position = 250.0", "home_position = 260.0")
    });
    // Same state directory as before, another prefix.
    let text = std::fs::read_to_string(&changed.path).unwrap().replace(
        &changed.state_dir.display().to_string(),
        &cfg.state_dir.display().to_string(),
    );
    std::fs::write(&changed.path, text).unwrap();
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
    let v = d.status();
    let w = axis(&v, "W");
    assert_eq!(w["homed"], false, "{w}");
    assert!(
        w["warnings"]
            .to_string()
            .contains("stored reference invalidated"),
        "{w}"
    );
    assert_eq!(d.stop().code, Some(0));
    let rec = record(&cfg);
    let last = rec.last().unwrap();
    assert_eq!(last["kind"], "invalidated");
    assert_eq!(
        last["reason"],
        "axis configuration changed: home_position 250 → 260"
    );
    assert_clean(&cfg.prefix);
    assert_clean(&changed.prefix);
}
