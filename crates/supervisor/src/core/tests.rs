//! The cycle's logic through frames and plants, no threads or IPC: what the
//! real-time thread does, cycle by cycle, with I/O processes simulated in
//! place (and made to fall silent or restart at will).

use super::*;
use crate::shared::{Ask, AxisAck, Control, Refusal};
use motion_homing::{MoveSpec, Operation};

use super::testbench::{Bench, MS};

/// The demo machine homes through frames, one axis after the other.
#[test]
fn demo_homes_through_frames_in_config_order() {
    let mut b = Bench::new(motion_config::DEMO_TOML);
    b.run(10);
    let all = b.core.all_mask();
    assert_eq!(all, 0b1111);
    let ack = b.home(all, false);
    assert!(ack.axes[..4].iter().all(|a| a.accepted()), "{ack:?}");
    let mut first_start = [None; 4];
    for _ in 0..20_000 {
        b.cycle();
        let s = b.snap();
        for (i, f) in first_start.iter_mut().enumerate() {
            if f.is_none() && s.axes[i].status.ip {
                *f = Some(b.k);
            }
        }
        if (0..4).all(|i| s.axes[i].settled()) && !s.axes[3].in_sequence {
            break;
        }
    }
    let s = b.snap();
    for (i, a) in b.m.axes.iter().enumerate() {
        assert!(s.axes[i].status.pc, "{}: {:?}", a.name, s.axes[i].status);
        assert_eq!(s.axes[i].homes_started, 1);
    }
    // One at a time: each starts after the one before has finished.
    let starts: Vec<u64> = first_start.iter().map(|x| x.unwrap()).collect();
    assert!(starts.windows(2).all(|w| w[0] < w[1]), "{starts:?}");
    for (i, start) in starts.iter().enumerate().skip(1) {
        let prev_done = s.axes[i - 1].status.finished_ns.unwrap() / MS;
        assert!(
            *start > prev_done,
            "axis {i} started before the one before ended"
        );
    }
    // Exit: stop, then disable every drive.
    b.ask(0, Ask::Exit);
    b.run(10);
    assert!(b.core.exit_done());
}

/// A switch-homing axis (`extra`: its I/O process or home order): seek at
/// 20 from -10 onto the switch [0, 5], return at 2 until it clears.
pub(super) fn switch_axis(name: &str, extra: &str) -> String {
    format!(
        r#"
[[axis]]
name = "{name}"
{extra}
home_sequence = "switch"
home_speed = 20.0
home_return_speed = 2.0
home_acceleration = 500.0
home_deceleration = 500.0
[axis.sim]
start = -10.0
switch = [0.0, 5.0]
"#
    )
}

/// Two I/O processes, one switch axis each: A on bus0, B on bus1.
fn two_io() -> String {
    format!(
        "[supervisor]\ncycle_us = 1000\ncpu = 0\n\n[[io]]\nname = \"bus0\"\n[[io]]\nname = \"bus1\"\n{}{}",
        switch_axis("A", "io = \"bus0\""),
        switch_axis("B", "io = \"bus1\"")
    )
}

/// Losing one I/O process aborts homing only on its axes (12/40);
/// the other axes carry on. Its return clears HomedStatus and is counted.
#[test]
fn losing_one_io_process_aborts_only_its_axes() {
    let mut b = Bench::new(&two_io());
    b.run(5);
    assert!(b.core.all_attached());
    let ack = b.home(0b11, true);
    assert!(ack.axes[0].accepted() && ack.axes[1].accepted());
    b.run(300); // both seeking
    b.alive[1] = false;
    b.run(3000);
    let s = b.snap();
    assert!(
        s.axes[0].status.pc && s.axes[0].status.homed,
        "{:?}",
        s.axes[0].status
    );
    let sb = s.axes[1].status;
    assert!(sb.er && !sb.homed, "{sb:?}");
    assert_eq!((sb.err, sb.exerr), (ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST));
    assert!(!s.ios[1].attached && s.ios[0].attached);
    // A home request on B is refused while bus1 is gone.
    let ack = b.home(0b10, false);
    assert_eq!(ack.axes[1], AxisAck::Refused(Refusal::IoNotAttached));
    // bus1 comes back as a new process: attached again, counted.
    b.origin[1] = 99;
    b.alive[1] = true;
    b.run(5);
    let s = b.snap();
    assert!(s.ios[1].attached);
    assert_eq!(s.ios[1].counters.attachments, 2);
    assert!(s.axes[0].status.homed, "bus0's axis keeps its reference");
    assert!(s.ios[1].counters.gaps.over_ten == 1);
}

/// A restarted I/O process (new origin, no gap long enough to detach)
/// clears HomedStatus of its axes.
#[test]
fn a_restarted_io_process_unhomes_its_axes() {
    let mut b = Bench::new(&two_io());
    b.run(5);
    b.home(0b11, true);
    b.run(4000);
    let s = b.snap();
    assert!(s.axes[0].status.homed && s.axes[1].status.homed);
    b.origin[0] = 1234;
    b.run(2);
    let s = b.snap();
    assert!(!s.axes[0].status.homed, "reconnection clears HomedStatus");
    assert!(s.axes[1].status.homed);
    assert_eq!(s.ios[0].counters.incarnations, 1);
    assert!(s.axes[0].lost_homed_ns.is_some());
}

#[test]
fn stop_and_unhome() {
    let mut b = Bench::new(&two_io());
    b.run(5);
    b.home(0b01, false);
    b.run(100);
    b.ask(1, Ask::Stop { mask: 0b01 });
    b.run(200);
    let s = b.snap().axes[0].status;
    assert!(s.er && (s.err, s.exerr) == (ERR_SERVO_MESSAGE, EX_TERMINATED_ON_REQUEST));
    b.home(0b10, false);
    b.run(4000);
    assert!(b.snap().axes[1].status.homed);
    b.ask(2, Ask::Unhome { mask: 0b10 });
    assert!(b.acks.pop().unwrap().axes[1].accepted());
    b.run(1);
    assert!(!b.snap().axes[1].status.homed);
}

#[test]
fn a_second_home_request_on_a_homing_axis_is_refused() {
    let mut b = Bench::new(&two_io());
    b.run(5);
    b.home(0b01, false);
    b.run(3);
    let ack = b.home(0b11, false);
    assert_eq!(ack.axes[0], AxisAck::Refused(Refusal::AlreadyHoming));
    assert!(
        !ack.axes[1].accepted(),
        "nothing starts when one named axis is refused"
    );
}

#[test]
fn trace_records_one_homing() {
    let mut b = Bench::new(&two_io());
    b.run(5);
    b.ask(3, Ask::Trace { axis: 1 });
    b.home(0b10, false);
    let mut recs = Vec::new();
    for _ in 0..5000 {
        b.cycle();
        if let Some(r) = b.core.trace_record() {
            recs.push(r);
            if r.end {
                break;
            }
        }
    }
    assert!(recs.len() > 100);
    assert_eq!(recs[0].t_ns, 0);
    assert_eq!(recs.iter().filter(|r| r.event).count(), 1);
    assert!(recs.last().unwrap().end);
    b.run(10);
    assert!(b.core.trace_record().is_none(), "disarmed after one homing");
}

/// A racked gantry: Y1's switch at 0, Y2's 0.3 further (`rack`); markers
/// 0.3 apart too; each side with its own offset. Switch then marker,
/// bidirectional forward, V = 20, R = 2, acceleration = deceleration = 500.
/// Expected, worked out by hand: Y1 detects its switch at 0, Y2 at 0.3, then
/// each returns to its first marker beyond its switch edge: Y1 -7.5, Y2 -7.2
/// (latched: exact); skew in the seek (switch) leg = 0.3, in the return
/// (marker) leg = 0.3 too; final raw positions -7.5 + 1.0 = -6.5 and
/// -7.2 + 1.5 = -5.7. X (home_order 1) homes after the gantry (order 0).
fn gantry_toml(rack: f64, max_skew: f64, fault_y2: bool) -> String {
    let side = |name: &str, offset: f64, at: f64| {
        format!(
            r#"
[[axis]]
name = "{name}"
home_order = 0
counts_per_unit = 1000.0
marker = true
home_sequence = "switch_then_marker"
home_speed = 20.0
home_return_speed = 2.0
home_acceleration = 500.0
home_deceleration = 500.0
home_offset = {offset}
travel_limits = [-100.0, 100.0]
[axis.sim]
start = -20.0
switch = [{at}, {sw_hi}]
marker_every = 10.0
marker_at = {marker}
hard_stop = [-110.0, 110.0]
"#,
            sw_hi = at + 5.0,
            marker = 2.5 + at
        )
    };
    let _ = fault_y2;
    format!(
        "[supervisor]\ncycle_us = 1000\ncpu = 0\n{}{}{}\n[[gantry]]\nname = \"Y\"\naxes = [\"Y1\", \"Y2\"]\nmax_skew = {max_skew}\n",
        side("Y1", 1.0, 0.0),
        side("Y2", 1.5, rack),
        switch_axis("X", "home_order = 1")
    )
}

#[test]
fn a_racked_gantry_is_squared_by_its_own_switches_and_markers() {
    let mut b = Bench::new(&gantry_toml(0.3, 1.0, false));
    b.run(5);
    let ack = b.home(b.core.all_mask(), false);
    assert!(ack.axes[..3].iter().all(|a| a.accepted()));
    let mut started = [None; 3];
    for _ in 0..20_000 {
        b.cycle();
        let s = b.snap();
        for (i, st) in started.iter_mut().enumerate() {
            if st.is_none() && s.axes[i].status.phase == motion_homing::Phase::Seek {
                *st = Some(b.k);
            }
        }
        if (0..3).all(|i| s.axes[i].settled()) && !s.axes[2].in_sequence {
            break;
        }
    }
    let s = b.snap();
    let (y1, y2, x) = (s.axes[0], s.axes[1], s.axes[2]);
    assert!(
        y1.status.pc && y2.status.pc && x.status.pc,
        "{y1:?}\n{y2:?}\n{x:?}"
    );
    // Each side's own marker, exactly.
    assert!((y1.status.event_raw.unwrap() + 7.5).abs() < 1e-9);
    assert!((y2.status.event_raw.unwrap() + 7.2).abs() < 1e-9);
    // Each side's own offset applied: both at Home Position 0.
    assert!(
        (b.plants[0].position() + 6.5).abs() < 1e-9,
        "{}",
        b.plants[0].position()
    );
    assert!(
        (b.plants[1].position() + 5.7).abs() < 1e-9,
        "{}",
        b.plants[1].position()
    );
    // The seek leg started in the same cycle on both sides.
    assert_eq!(started[0], started[1]);
    // Skew measured: the sides found their events 0.3 apart (± two cycles
    // of travel at the leg's speed: 2 × 0.02).
    let skew = y1.skew.unwrap();
    assert!((skew - 0.3).abs() <= 0.04 + 1e-9, "skew {skew}");
    assert_eq!(y2.skew, y1.skew);
    // X (order 1) started only after the gantry had finished.
    assert!(started[2].unwrap() > y1.status.finished_ns.unwrap() / MS);
}

#[test]
fn a_gantry_racked_beyond_max_skew_fails_on_both_sides_before_squaring() {
    // Racked 2.0 with max_skew 0.5: Y1 finds its switch; Y2 may travel 0.5
    // further, then both stop with ERR 1017.
    let mut b = Bench::new(&gantry_toml(2.0, 0.5, false));
    b.run(5);
    b.home(b.core.all_mask(), false);
    let mut y1_switch_at_stop = None;
    for _ in 0..20_000 {
        b.cycle();
        let s = b.snap();
        if y1_switch_at_stop.is_none() && s.axes[0].status.er {
            y1_switch_at_stop = Some(b.plants[1].position());
        }
        if (0..3).all(|i| !s.axes[i].status.ip && !s.axes[i].in_sequence) && b.k > 100 {
            break;
        }
    }
    let s = b.snap();
    for i in 0..2 {
        let st = s.axes[i].status;
        assert!(st.er && !st.homed, "{st:?}");
        assert_eq!(
            (st.err, st.exerr),
            (motion_homing::codes::ERR_GANTRY_SKEW, 0)
        );
    }
    // Y2 never reached its switch (at 2.0): it came to rest within max_skew
    // + the stopping distance (20²/1000 = 0.4) + four cycles of travel at
    // 20 (0.08: Y1's detection lag of up to two cycles, the decision's
    // cycle, the stop's first cycle) past Y1's event at 0.
    let y2 = b.plants[1].position();
    assert!(y2 <= 0.5 + 0.4 + 0.08 + 1e-9, "{y2}");
    assert!(y2 < 2.0, "never reached its own switch");
    assert!(s.axes[0].skew.unwrap() >= 0.5);
    // X of the later order was never started: the sequence failed.
    assert_eq!(s.axes[2].homes_started, 0);
    assert_eq!(s.axes[2].aborted_by, Some(0));
}

#[test]
fn a_side_faulting_mid_phase_stops_every_side() {
    let mut b = Bench::new(&gantry_toml(0.3, 1.0, false));
    b.run(5);
    b.home(0b011, false);
    b.run(300); // both seeking
    b.plants[1].inject_fault();
    b.run(2000);
    let s = b.snap();
    let (y1, y2) = (s.axes[0].status, s.axes[1].status);
    assert_eq!((y2.err, y2.exerr), (12, 16), "{y2:?}");
    assert_eq!((y1.err, y1.exerr), (12, 1), "{y1:?}");
    assert_eq!(
        s.axes[0].aborted_by,
        Some(1),
        "Y1 names the side that failed"
    );
    assert!(!y1.homed && !y2.homed);
}

/// A move by 2 of axis 0, asked as request `id` with deadline `deadline_ns`.
fn move_by_2(id: u32, deadline_ns: u64) -> Control {
    Control {
        id,
        deadline_ns,
        ask: Ask::Op {
            mask: 0b1,
            op: Operation::Move(MoveSpec {
                relative: true,
                ..MoveSpec::to(2.0)
            }),
            token: 0,
        },
    }
}

/// The cycle stalled with a move queued: the control thread gave up on it
/// at its deadline and told its client nothing was applied. When the
/// cycle catches up, the move is refused without any effect (a client
/// retrying `move --by` moves once) — and a move in time is made.
#[test]
fn a_request_the_cycle_reaches_after_its_deadline_is_never_applied() {
    let mut b = Bench::new(&two_io());
    b.run(5);
    b.ask(
        1,
        Ask::Op {
            mask: 0b1,
            op: Operation::Enable,
            token: 0,
        },
    );
    b.run(1500);
    let before = b.snap().axes[0];
    assert!(before.status.servo_action, "{:?}", before.status);
    b.acks.clear();
    // Queued 1.3 s ago with a 1 s deadline: the core steps only now.
    let now = b.k * MS;
    b.control(move_by_2(2, now - 300 * MS));
    let ack = b.acks.pop().expect("answered at once");
    assert!(ack.expired && ack.id == 2, "{ack:?}");
    assert!(ack.axes.iter().all(|a| *a == AxisAck::NotNamed));
    b.run(1000);
    let after = b.snap().axes[0];
    assert_eq!(
        after.status.op, before.status.op,
        "never reached the engine"
    );
    assert!(!after.status.moving);
    assert_eq!(after.cmd_position, before.cmd_position);
    // The same request within its deadline moves the axis by 2.
    b.control(move_by_2(3, b.k * MS + 1000 * MS));
    assert!(b.acks.is_empty(), "an operation is answered after the step");
    b.cycle();
    let ack = b.acks.pop().unwrap();
    assert!(!ack.expired && ack.axes[0].accepted(), "{ack:?}");
    b.run(1500);
    let moved = b.snap().axes[0];
    assert!(moved.status.op.pc, "{:?}", moved.status);
    assert!((moved.cmd_position - before.cmd_position - 2.0).abs() < 1e-9);
}
