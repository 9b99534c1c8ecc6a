//! The keeper with the cycle and simulated plants, no threads: homings
//! recorded, drift and switch-to-marker checks, absolute references stored,
//! restored after a restart without motion, and invalidated. Expected values
//! are worked out by hand next to each case.

use super::*;
use crate::core::testbench::Bench;
use crate::shared::{Ask, AxisAck, Control, Refusal};
use motion_plant::Plant;
use motion_state::reference::References;
use motion_state::{Loaded, RecordKind};

/// The cycle and the keeper as the daemon runs them: the keeper looks at
/// every snapshot, its restore requests reach the cycle, the answers come
/// back.
struct Kb {
    b: Bench,
    keeper: Keeper,
    next_id: u32,
}

impl Kb {
    fn new(toml: &str) -> Self {
        let b = Bench::new(toml);
        let keeper = Keeper::open(&b.m);
        Self {
            b,
            keeper,
            next_id: 1000,
        }
    }

    fn cycle(&mut self) {
        self.b.cycle();
        let snap = self.b.snap();
        let mut sends = Vec::new();
        let next = &mut self.next_id;
        self.keeper
            .observe(&self.b.m, &snap, |axis, offset, shift| {
                *next += 1;
                let ask = Ask::Restore {
                    axis,
                    offset,
                    shift,
                };
                sends.push(Control::undated(*next, ask));
                Some(*next)
            });
        for c in sends {
            self.b.control(c);
        }
        for a in std::mem::take(&mut self.b.acks) {
            self.keeper.ack(&self.b.m, &a);
        }
    }

    fn run(&mut self, n: u64) {
        for _ in 0..n {
            self.cycle();
        }
    }

    /// Homes the axes of `mask` and runs until they settled.
    fn home(&mut self, mask: u64) {
        let ack = self.b.home(mask, true);
        assert!(ack.axes.iter().all(|a| !matches!(
            a,
            AxisAck::Refused(r) if *r != Refusal::NotStarted
        )));
        for _ in 0..60_000 {
            self.cycle();
            let s = self.b.snap();
            let n = self.b.m.axes.len();
            if (0..n)
                .all(|i| mask & (1 << i) == 0 || (s.axes[i].settled() && !s.axes[i].in_sequence))
            {
                self.run(5);
                return;
            }
        }
        panic!("homing did not end");
    }

    fn record(&self) -> Vec<RecordEntry> {
        let p = self
            .b
            .m
            .supervisor
            .state_dir
            .join(motion_state::record::FILE);
        std::fs::read_to_string(p)
            .unwrap_or_default()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    }

    /// Replaces the plant of axis `i` by one whose switch lies `shift`
    /// further, at the same position (the switch moved; the encoder did not).
    fn move_switch(&mut self, i: usize, shift: f64) {
        self.b.plants[i].move_switch(shift);
    }
}

fn state_dir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

/// The `[supervisor]` of these machines: 1 kHz, the state in `dir/state`.
fn supervisor(dir: &std::path::Path) -> String {
    format!(
        "[supervisor]\ncycle_us = 1000\ncpu = 0\nstate_dir = \"{}\"\n",
        dir.join("state").display()
    )
}

/// Switch homing, bidirectional forward: seek at 20 onto the switch [0, 5],
/// return at 2 until it clears at 0 — the event, sampled to within
/// R x T = 0.002. Home Position 0, no offset: the event becomes axis
/// position 0, so in the previous reference every later event lies at
/// 0 ± 0.002 — until the switch moves.
fn switch_axis(dir: &std::path::Path, sequence: &str, drift_limit: f64, marker_at: f64) -> String {
    format!(
        r#"{}
[[axis]]
name = "X"
counts_per_unit = 1000.0
marker = true
home_sequence = "{sequence}"
home_speed = 20.0
home_return_speed = 2.0
home_acceleration = 500.0
home_deceleration = 500.0
travel_limits = [-100.0, 100.0]
drift_limit = {drift_limit}
marker_min_distance = 0.2
[axis.sim]
start = -20.0
switch = [0.0, 5.0]
marker_every = 10.0
marker_at = {marker_at}
hard_stop = [-110.0, 110.0]
"#,
        supervisor(dir)
    )
}

#[test]
fn every_homing_is_recorded_and_a_moved_switch_is_reported_as_drift() {
    let t = state_dir();
    let mut k = Kb::new(&switch_axis(t.path(), "switch", 0.05, 2.5));
    k.run(5);
    // 1: not homed before: no event in an earlier reference.
    // 2, 3: the event lies at 0 ± 0.002 in the reference of the homing before.
    for _ in 0..3 {
        k.home(1);
    }
    let rec = k.record();
    assert_eq!(rec.len(), 3);
    assert!(rec.iter().all(RecordEntry::succeeded), "{rec:#?}");
    assert_eq!(rec[0].event, None);
    for e in &rec[1..] {
        assert!(e.event.unwrap().abs() <= 0.002, "{e:?}");
        assert!(e.warnings.is_empty(), "{e:?}");
        assert_eq!(e.sequence, "switch");
        assert_eq!(e.mode, "active");
        let off = e.offset.unwrap();
        // offset = Home Position - event raw.
        assert!((off + e.event_raw.unwrap()).abs() < 1e-9);
        assert!(e.duration_s.unwrap() > 0.0, "{e:?}");
    }
    // The switch moves 0.2 forward (wear, a loose bracket): the event lies
    // at 0.2 ± 0.002 in the previous reference, 0.2 from the median of the
    // two before (≈ 0) — beyond drift_limit 0.05.
    k.move_switch(0, 0.2);
    k.home(1);
    let rec = k.record();
    let last = rec.last().unwrap();
    assert!(last.succeeded());
    assert!((last.event.unwrap() - 0.2).abs() <= 0.004, "{last:?}");
    assert_eq!(last.warnings.len(), 1, "{last:?}");
    assert!(last.warnings[0].starts_with("drift:"), "{last:?}");
    let note = k.keeper.notes()[0];
    assert_eq!(note.warnings & W_DRIFT, W_DRIFT);
    assert!((note.drift - 0.2).abs() <= 0.004, "{note:?}");
    // Homed again on the moved switch: in the new reference the event is
    // back at 0; the median of [≈0, ≈0, 0.2] is ≈ 0: no warning.
    k.home(1);
    let rec = k.record();
    assert!(rec.last().unwrap().warnings.is_empty(), "{:?}", rec.last());
    assert_eq!(k.keeper.notes()[0].warnings & W_DRIFT, 0);
}

#[test]
fn the_drift_history_survives_a_restart() {
    let t = state_dir();
    let toml = switch_axis(t.path(), "switch", 0.05, 2.5);
    let plants = {
        let mut k = Kb::new(&toml);
        k.run(5);
        for _ in 0..3 {
            k.home(1);
        }
        k.b.plants.clone()
    };
    // A new run reads the recent events (≈ 0, ≈ 0) from the record. The
    // incremental encoder is not homed after the restart, so the first
    // homing has no event to compare; home twice, the switch moved in
    // between: 0.2 from the recorded median.
    let mut k = Kb::new(&toml);
    k.b.plants = plants;
    k.run(5);
    k.home(1);
    k.move_switch(0, 0.2);
    k.home(1);
    let last = k.record().pop().unwrap();
    assert!((last.event.unwrap() - 0.2).abs() <= 0.004, "{last:?}");
    assert!(last.warnings[0].starts_with("drift:"), "{last:?}");
}

/// Switch then marker, bidirectional forward: switch edge at 0 (cleared on
/// the return), first marker beyond it going reverse at -7.5 (markers every
/// 10 at 2.5): 7.5 from the edge. The switch moves 0.3 forward: edge 0.3,
/// same marker, 7.8 — 0.3 from the median, beyond drift_limit 0.1. The
/// event (the marker, fixed to the encoder) does not move: no event drift.
#[test]
fn the_switch_to_marker_distance_shows_a_moving_switch() {
    let t = state_dir();
    let mut k = Kb::new(&switch_axis(t.path(), "switch_then_marker", 0.1, 2.5));
    k.run(5);
    k.home(1);
    k.home(1);
    let rec = k.record();
    for e in &rec {
        assert!(
            (e.switch_to_marker.unwrap_or_else(|| panic!("{e:?}")) - 7.5).abs() <= 0.002,
            "{e:?}"
        );
        assert!((e.event_raw.unwrap() + 7.5).abs() < 1e-9, "latched: exact");
    }
    assert!(rec[1].event.unwrap().abs() < 1e-9);
    k.move_switch(0, 0.3);
    k.home(1);
    let last = k.record().pop().unwrap();
    assert!(
        (last.switch_to_marker.unwrap_or_else(|| panic!("{last:?}")) - 7.8).abs() <= 0.002,
        "{last:?}"
    );
    assert!(last.event.unwrap().abs() < 1e-9, "{last:?}");
    assert_eq!(last.warnings.len(), 1, "{last:?}");
    assert!(
        last.warnings[0].contains("switch edge to marker"),
        "{last:?}"
    );
    let note = k.keeper.notes()[0];
    assert_eq!(note.warnings, W_SWITCH_DRIFT);
    assert!((note.drift - 0.3).abs() <= 0.002);
}

/// Markers every 10 at 9.9: the first beyond the edge at 0 going reverse
/// is -0.1, closer than marker_min_distance 0.2: homed, with the warning.
#[test]
fn an_ambiguous_marker_is_recorded_as_a_warning() {
    let t = state_dir();
    let mut k = Kb::new(&switch_axis(t.path(), "switch_then_marker", 0.0, 9.9));
    k.run(5);
    k.home(1);
    let e = k.record().pop().unwrap();
    assert!(e.succeeded(), "{e:?}");
    assert!((e.switch_to_marker.unwrap() - 0.1).abs() <= 0.002, "{e:?}");
    assert!(e.warnings[0].starts_with("ambiguous marker"), "{e:?}");
    assert!(k.b.snap().axes[0].status.ambiguous_marker);
}

/// An absolute rotary-table-like axis: raw 113.4 at rest (the encoder's
/// position since the machine was built), Home Position 10: homing
/// (absolute mode, no motion) gives offset 10 - 113.4 = -103.4.
fn absolute_axis(dir: &std::path::Path, home_position: f64, start: f64) -> String {
    format!(
        r#"{}
[[axis]]
name = "A"
counts_per_unit = 1000.0
absolute = true
home_mode = "absolute"
home_sequence = "immediate"
home_position = {home_position}
travel_limits = [-50.0, 400.0]
max_speed = 100.0
[axis.sim]
start = {start}
"#,
        supervisor(dir)
    )
}

#[test]
fn an_absolute_axis_is_homed_again_after_a_restart_without_motion() {
    let t = state_dir();
    let toml = absolute_axis(t.path(), 10.0, 113.4);
    {
        let mut k = Kb::new(&toml);
        k.run(50);
        assert!(!k.b.snap().axes[0].status.homed, "nothing stored yet");
        k.home(1);
        let s = k.b.snap();
        assert!(s.axes[0].status.homed && s.axes[0].status.pc);
        assert!((s.axes[0].offset.unwrap() + 103.4).abs() < 1e-9);
    }
    let refs = References::new(StateDir::open(&t.path().join("state")).unwrap());
    let Loaded::Valid(r) = refs.load("A") else {
        panic!("not stored")
    };
    assert!((r.offset + 103.4).abs() < 1e-9);

    // Restart: a new cycle and keeper; the encoder still reads 113.4.
    let mut k = Kb::new(&toml);
    let mut moved = false;
    for _ in 0..100 {
        k.cycle();
        let s = k.b.snap();
        moved |= s.axes[0].cmd_velocity != 0.0 || s.axes[0].enable;
    }
    let s = k.b.snap();
    let a = &s.axes[0];
    assert!(a.status.homed && a.restored, "{a:?}");
    assert!(!a.status.pc && !a.status.ip, "no instruction ran");
    assert!((a.axis.unwrap() - 10.0).abs() < 1e-9);
    assert!(!moved, "restored without motion");
    assert_eq!(k.record().last().unwrap().result, "restored");

    // Homing again never adds the offset twice: still -103.4, axis at 10.
    k.home(1);
    let a = k.b.snap().axes[0];
    assert!((a.offset.unwrap() + 103.4).abs() < 1e-9);
    assert!((a.axis.unwrap() - 10.0).abs() < 1e-9);
    assert!(!a.restored);
}

fn invalidation_reason(t: &tempfile::TempDir) -> String {
    let refs = References::new(StateDir::open(&t.path().join("state")).unwrap());
    match refs.load("A") {
        Loaded::Invalidated(r) => r.invalidated.unwrap().reason,
        other => panic!("{other:?}"),
    }
}

/// Homes once, then restarts with `toml2` for 200 cycles.
fn restart_with(t: &tempfile::TempDir, toml2: &str) -> Kb {
    {
        let mut k = Kb::new(&absolute_axis(t.path(), 10.0, 113.4));
        k.run(20);
        k.home(1);
    }
    let mut k = Kb::new(toml2);
    k.run(200);
    k
}

#[test]
fn a_changed_axis_configuration_invalidates_the_stored_reference() {
    let t = state_dir();
    let mut k = restart_with(&t, &absolute_axis(t.path(), 20.0, 113.4));
    assert!(!k.b.snap().axes[0].status.homed);
    assert_eq!(
        invalidation_reason(&t),
        "axis configuration changed: home_position 10 → 20"
    );
    let rec = k.record();
    let last = rec.last().unwrap();
    assert_eq!(last.kind, Some(RecordKind::Invalidated));
    assert_eq!(
        last.reason.as_deref(),
        Some("axis configuration changed: home_position 10 → 20")
    );
    assert_ne!(
        k.keeper.notes()[0].warnings & motion_status::snap::W_REFERENCE_INVALIDATED,
        0
    );
    // Homing stores a fresh one: offset 20 - 113.4 = -93.4.
    k.home(1);
    let refs = References::new(StateDir::open(&t.path().join("state")).unwrap());
    let Loaded::Valid(r) = refs.load("A") else {
        panic!()
    };
    assert!((r.offset + 93.4).abs() < 1e-9);
}

/// The encoder now reads 520 (replaced, or the mechanics moved while the
/// power was off): with the stored offset the axis would be at
/// 520 - 103.4 = 416.6, outside [-50, 400]: refused and invalidated.
#[test]
fn a_restored_position_outside_the_travel_limits_invalidates() {
    let t = state_dir();
    let k = restart_with(&t, &absolute_axis(t.path(), 10.0, 520.0));
    assert!(!k.b.snap().axes[0].status.homed);
    let why = invalidation_reason(&t);
    assert!(
        why.contains("416.6") && why.contains("outside its travel limits"),
        "{why}"
    );
}

#[test]
fn unhome_and_a_position_jump_invalidate() {
    let t = state_dir();
    let mut k = restart_with(&t, &absolute_axis(t.path(), 10.0, 113.4));
    assert!(k.b.snap().axes[0].restored);
    k.keeper
        .unhomed(&k.b.m, 0, "operator unhome (motionctl unhome)");
    assert_eq!(
        invalidation_reason(&t),
        "operator unhome (motionctl unhome)"
    );

    // Homed again, then the encoder jumps 50 units in one cycle (50 000
    // units/s, max_speed is 100): HomedStatus cleared, reference invalidated.
    k.home(1);
    let p = &k.b.plants[0];
    let mut cfg = *p.config();
    cfg.start = p.position() + 50.0;
    k.b.plants[0] = Plant::new(cfg);
    k.run(20);
    assert!(!k.b.snap().axes[0].status.homed);
    let why = invalidation_reason(&t);
    assert!(why.starts_with("position jump"), "{why}");
    // Not re-applied: the axis stays unhomed.
    k.run(500);
    assert!(!k.b.snap().axes[0].status.homed);
}

/// The shipped gantry example, end to end through the cycle: home-all
/// homes Z (order 0), then Y1, Y2 and X together (order 1); W (absolute,
/// no order) is not part of it. The racked gantry (Y2's switch and markers
/// 0.3 further) is squared: each side latches its own marker, Y1 at -7.5,
/// Y2 at -7.2 (latched, exact), skew 0.3 (± the switch edges' sampling,
/// R x T = 0.002). W homed by name stores offset 250 - 37.5 = 212.5 and is
/// homed at the next start without motion.
#[test]
fn the_gantry_example_homes_in_order_and_keeps_its_absolute_axis() {
    let t = state_dir();
    let toml = motion_config::GANTRY_TOML.replacen(
        "[supervisor]\n",
        &format!(
            "[supervisor]\nstate_dir = \"{}\"\n",
            t.path().join("state").display()
        ),
        1,
    );
    let mut k = Kb::new(&toml);
    k.run(10);
    let all = k.b.core.all_mask();
    assert_eq!(all, 0b01111, "W is homed only when named");
    k.b.home(all, false);
    let mut started = [None; 4];
    let mut z_done = None;
    for c in 0..60_000u64 {
        k.cycle();
        let s = k.b.snap();
        for (i, st) in started.iter_mut().enumerate() {
            if st.is_none() && s.axes[i].homes_started > 0 {
                *st = Some(c);
            }
        }
        if z_done.is_none() && s.axes[0].settled() && s.axes[0].homes_started > 0 {
            z_done = Some(c);
        }
        if (0..4)
            .all(|i| s.axes[i].settled() && !s.axes[i].in_sequence && s.axes[i].homes_started > 0)
        {
            break;
        }
    }
    let s = k.b.snap();
    for i in 0..4 {
        assert!(
            s.axes[i].status.pc && s.axes[i].status.homed,
            "axis {i}: {:?}",
            s.axes[i].status
        );
    }
    let (z, y1, y2, x) = (
        z_done.unwrap(),
        started[1].unwrap(),
        started[2].unwrap(),
        started[3].unwrap(),
    );
    assert!(y1 > z && x > z, "order 1 after order 0 ended");
    assert_eq!(y1, y2, "gantry sides start in the same cycle");
    assert_eq!(y1, x, "equal orders start together");
    assert!((s.axes[1].status.event_raw.unwrap() + 7.5).abs() < 1e-9);
    assert!((s.axes[2].status.event_raw.unwrap() + 7.2).abs() < 1e-9);
    let skew = s.axes[1].skew.unwrap();
    assert!((skew - 0.3).abs() <= 0.002, "skew {skew}");
    let rec = k.record();
    let y2 = rec.iter().find(|e| e.axis == "Y2").unwrap();
    assert_eq!(y2.gantry.as_deref(), Some("Y"));
    assert!((y2.skew.unwrap() - 0.3).abs() <= 0.002);

    k.home(1 << 4);
    let w = k.b.snap().axes[4];
    assert!((w.offset.unwrap() - 212.5).abs() < 1e-9);
    assert!((w.axis.unwrap() - 250.0).abs() < 1e-9);
    let mut k = Kb::new(&toml);
    k.run(100);
    let s = k.b.snap();
    assert!(s.axes[4].status.homed && s.axes[4].restored);
    assert!((s.axes[4].axis.unwrap() - 250.0).abs() < 1e-9);
    assert!(
        (0..4).all(|i| !s.axes[i].status.homed),
        "incremental axes need homing"
    );
}

#[test]
fn a_redefine_is_recorded_and_an_absolute_axis_keeps_it_over_a_restart() {
    use motion_homing::{Operation, RedefineSpec};
    let t = state_dir();
    let toml = absolute_axis(t.path(), 10.0, 113.4);
    {
        let mut k = Kb::new(&toml);
        k.run(20);
        k.home(1);
        // Axis 10 → 35: by 25, nothing moves.
        k.b.op(1, Operation::Redefine(RedefineSpec::by(25.0)), 0);
        k.run(5);
        let a = k.b.snap().axes[0];
        assert!(a.status.homed && a.status.pc, "{a:?}");
        assert!((a.axis.unwrap() - 35.0).abs() < 1e-9);
        assert_eq!(a.status.soft_limits, Some((-25.0, 425.0)));
        let last = k.record().pop().unwrap();
        assert_eq!(last.kind, Some(RecordKind::Redefined));
        assert_eq!(last.result, "redefined");
        assert_eq!((last.shift, last.position), (Some(25.0), Some(35.0)));
        assert!((last.offset.unwrap() + 78.4).abs() < 1e-9);
    }
    let refs = References::new(StateDir::open(&t.path().join("state")).unwrap());
    let Loaded::Valid(r) = refs.load("A") else {
        panic!("not stored")
    };
    assert!((r.offset + 78.4).abs() < 1e-9 && r.shift == 25.0, "{r:?}");

    // Restart: the encoder still reads 113.4; the axis reads 35 again and
    // its soft limits are on the same machine places.
    let mut k = Kb::new(&toml);
    k.run(100);
    let a = k.b.snap().axes[0];
    assert!(a.status.homed && a.restored, "{a:?}");
    assert!((a.axis.unwrap() - 35.0).abs() < 1e-9);
    assert_eq!(a.status.soft_limits, Some((-25.0, 425.0)));
    assert_eq!(k.record().last().unwrap().result, "restored");
}
