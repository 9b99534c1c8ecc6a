//! The table's own rules, and a round trip of every row through the wire
//! entry and the JSON row.

use crate::axis::{fill, ROWS};
use crate::schema::{Area, Type};
use crate::*;
use motion_homing::{AxisConfig, HomeMode, OpKind, StopCause};
use std::collections::HashSet;

#[test]
fn every_place_key_and_name_is_unique_and_in_the_room() {
    let mut places = HashSet::new();
    let (mut names, mut keys, mut opcua) = (HashSet::new(), HashSet::new(), HashSet::new());
    for r in ROWS {
        let area = r.ty.area();
        assert!(
            (r.place as usize) < area.room(),
            "{}: past the room of {area:?}",
            r.name
        );
        assert!(
            places.insert((area, r.place)),
            "{}: its place is taken",
            r.name
        );
        assert!(names.insert(r.name), "{} twice", r.name);
        assert!(keys.insert(r.json), "JSON key {} twice", r.json);
        if let Some(o) = r.opcua {
            assert!(opcua.insert(o), "OPC UA name {o} twice");
        }
        assert!(
            r.mark.is_none() || area == Area::Flags,
            "{}: a mark on a non-flag",
            r.name
        );
        assert!(!r.doc_line().is_empty(), "{}: no doc", r.name);
    }
    // The spec's names, with these types.
    for (name, key) in [
        ("homed", "HomedStatus"),
        ("homing", "HomingStatus"),
        ("pc", "PC"),
    ] {
        let r = AxisStatusEntry::row(name).unwrap();
        assert!(matches!(r.ty, Type::Flag) && r.opcua == Some(key), "{name}");
    }
    for name in ["err", "exerr"] {
        assert!(matches!(AxisStatusEntry::row(name).unwrap().ty, Type::U16));
    }
}

fn source_facts() -> (AxisSnap, AxisConfig, AxisNote) {
    let mut a = AxisSnap {
        raw: Some(2.5),
        axis: Some(12.5),
        velocity: 3.0,
        torque: 40.0,
        switch: true,
        enabled: true,
        cmd_axis: Some(12.25),
        homes_started: 1,
        aborted_by: Some(3),
        ..Default::default()
    };
    a.status.homed = true;
    a.status.jogging = true;
    a.status.err = 12;
    a.status.exerr = 40;
    a.status.started_ns = 1_000_000_000;
    a.status.finished_ns = Some(3_500_000_000);
    a.status.op.id = 7;
    a.status.op.kind = OpKind::Jog;
    a.status.last_stop = StopCause::LeaseExpired;
    a.status.drive_lost = true; // a lost drive is never "enabled"
    let cfg = AxisConfig {
        home_mode: HomeMode::Active,
        ..Default::default()
    };
    let note = AxisNote {
        warnings: snap::W_DRIFT,
        drift: 0.125,
    };
    (a, cfg, note)
}

#[test]
fn a_snapshot_travels_through_the_entry_into_the_json_row() {
    let (a, cfg, note) = source_facts();
    let mut e = AxisStatusEntry {
        flags: u64::MAX, // what a frame held before: cleared by the fill
        ..Default::default()
    };
    fill(&mut e, &Source::new(&a, &cfg, &note, 9_000_000_000));
    assert!(e.homed() && e.jogging() && e.in_motion() && e.switch() && e.feedback());
    assert!(!e.enabled() && e.drive_lost() && !e.moving() && e.warn_drift());
    assert_eq!(
        (e.err(), e.exerr(), e.op_id(), e.aborted_by()),
        (12, 40, 7, 3)
    );
    assert_eq!(
        (e.home_mode(), e.op_kind(), e.last_stop()),
        ("active", "jog", "lease_expired")
    );
    assert_eq!(
        (e.position(), e.cmd_position(), e.elapsed_s()),
        (Some(12.5), Some(12.25), 2.5)
    );
    assert_eq!(
        (e.event_raw(), e.skew(), e.drift()),
        (None, None, Some(0.125))
    );

    let j = AxisStatus::from_entry(&e);
    assert!(j.homed && j.jogging && !j.moving && j.warn_drift);
    assert_eq!(
        (j.position, j.event_raw, j.home_mode.as_str()),
        (Some(12.5), None, "active")
    );
    let v = serde_json::to_value(&j).unwrap();
    assert_eq!(v["jogging"], true);
    assert_eq!(v["command"], 12.25, "the JSON key, not the field's name");
    assert!(
        v["event_raw"].is_null(),
        "a value that is not there is null"
    );
    let (marks, header) = (j.marks(), AxisStatus::marks_header());
    assert!(header.starts_with("EN DN ER IP PC SJMTxF-+sm"), "{header}");
    assert_eq!(marks.len(), header.len());
    let set = marks
        .chars()
        .zip(header.chars())
        .filter(|&(m, _)| m != '.' && m != ' ');
    let set: String = set.map(|(m, h)| if m == h { m } else { '?' }).collect();
    assert_eq!(set, "Js", "{marks} under {header}");
}

#[test]
fn no_feedback_no_reading() {
    let (mut a, cfg, note) = source_facts();
    a.raw = None;
    let mut e = AxisStatusEntry::default();
    fill(&mut e, &Source::new(&a, &cfg, &note, 0));
    assert_eq!((e.position(), e.velocity(), e.raw()), (None, None, None));
    assert!(!e.feedback());
    e.values[0] = f64::INFINITY; // a careless peer's number is no reading
    assert_eq!(e.position(), None);
}

#[test]
fn an_unknown_enumeration_number_reads_as_a_question_mark() {
    let mut e = AxisStatusEntry::default();
    e.ints[AxisStatusEntry::row("op_kind").unwrap().place as usize] = 250;
    assert_eq!(e.op_kind(), "?");
    let names = AxisStatusEntry::row("home_mode").unwrap().ty.enum_names();
    assert_eq!(names, ["passive", "active", "absolute"]);
}

#[test]
fn the_motion_mask_is_the_bits_of_its_rows() {
    let mut e = AxisStatusEntry::default();
    for name in axis::IN_MOTION {
        let r = AxisStatusEntry::row(name).unwrap();
        e.flags = 1 << r.place;
        assert!(e.in_motion(), "{name}");
    }
    e.flags = axis::mask(&["homed", "stopping"]);
    assert!(!e.in_motion());
}
