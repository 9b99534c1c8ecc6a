//! The operations where they meet the cycle's own rules, through frames and
//! plants: a stream whose program goes silent, is released or dies (its
//! owner gone), and a gantry whose side faults during a reset — each
//! stopped within its bound, every side with it.

use super::testbench::{Bench, MS};
use super::tests::switch_axis;
use crate::shared::Ask;
use motion_homing::{JogSpec, Operation};

/// One axis X: immediate homing at 0, max_speed 20, stream_acceleration
/// 1000 (home_acceleration 100 × 10), max_deceleration 100, travel limits
/// ±20, the default stream_timeout_ms 50; a 1 ms cycle.
pub(super) const ONE_AXIS: &str = r#"
[supervisor]
cycle_us = 1000
cpu = 0

[[axis]]
name = "X"
counts_per_unit = 1000.0
home_sequence = "immediate"
home_speed = 10.0
home_acceleration = 100.0
home_deceleration = 100.0
max_speed = 20.0
travel_limits = [-20.0, 20.0]
"#;

pub(super) const TOKEN: u64 = 0x0bad_cafe;

/// X homed (by [`ONE_AXIS`]'s sequence), then enabled, at rest at 0.
fn homed_and_enabled() -> Bench {
    let mut b = Bench::new(ONE_AXIS);
    b.run(5);
    b.home(1, false);
    b.run(5);
    b.op(1, Operation::Enable, 0);
    b.run(20);
    b
}

/// X homed, enabled, and streamed by [`TOKEN`], at rest at 0.
pub(super) fn streaming() -> Bench {
    let mut b = homed_and_enabled();
    let s = b.snap().axes[0];
    assert!(s.status.homed && s.status.servo_action, "{:?}", s.status);
    b.ask(
        3,
        Ask::StreamAcquire {
            mask: 1,
            token: TOKEN,
        },
    );
    b.run(2);
    let s = b.snap().axes[0];
    assert!(s.status.streaming && s.owner == TOKEN, "{s:?}");
    b
}

/// X's commanded position now.
pub(super) fn cmd(b: &Bench) -> f64 {
    b.snap().axes[0].cmd_position
}

/// A program asks for 9 units 10 s ahead (0.9 u/s): the first setpoint at
/// 0, the far one 20 cycles later.
fn far_ahead(b: &mut Bench) {
    b.setpoint(TOKEN, 1, 0, 0, 0.0);
    b.run(20);
    b.setpoint(TOKEN, 2, 10_000 * MS, 0, 9.0);
    b.run(1);
}

#[test]
fn a_released_or_dead_owners_stream_stops_at_once_however_far_its_setpoint() {
    // Released by the program, or by the control thread when the owner's
    // node is found dead (the same request): the axis stops now, from where
    // its command is, at the stream's deceleration (1000: 0.9² / 2000).
    let mut b = streaming();
    far_ahead(&mut b);
    b.run(30);
    let at = cmd(&b);
    b.ask(4, Ask::StreamRelease { token: TOKEN });
    for _ in 0..20 {
        b.cycle();
    }
    let s = b.snap().axes[0];
    assert!(!s.status.streaming && !s.status.stopping, "{:?}", s.status);
    assert_eq!(s.owner, 0, "the ownership ended");
    assert_eq!(s.status.last_stop, motion_homing::StopCause::Released);
    let went = cmd(&b) - at;
    assert!(went <= 0.9 * 0.002 + 0.81 / 2000.0 + 1e-9, "went {went}");
    assert!(!s.status.er);
}

#[test]
fn a_hung_program_has_its_axis_stopped_from_its_last_setpoints_arrival() {
    // Alive (it still owns the axis) but silent: 50 ms after its last
    // setpoint arrived the stream stops with 1019 / 5 — not 10 s later at
    // the end of that setpoint's segment.
    let mut b = streaming();
    far_ahead(&mut b);
    let arrived = b.k - 1;
    let at = cmd(&b);
    let mut stopped = None;
    for _ in 0..1000 {
        b.cycle();
        if stopped.is_none() && b.snap().axes[0].status.faulted {
            stopped = Some(b.k - 1);
        }
    }
    let s = b.snap().axes[0];
    assert_eq!(stopped, Some(arrived + 51), "{:?}", s.status);
    assert_eq!((s.status.err, s.status.exerr), (1019, 5));
    assert_eq!(s.owner, 0, "a stream that stopped is no longer owned");
    // 0.9 u/s for 51 ms, then its stop.
    let went = cmd(&b) - at;
    assert!(went <= 0.9 * 0.051 + 0.81 / 2000.0 + 1e-9, "went {went}");
}

/// Gantry G (sides G1, G2: switch homing), unhomed: jogged at up to
/// home_speed 20.
fn gantry() -> String {
    format!(
        "[supervisor]\ncycle_us = 1000\ncpu = 0\n{}{}\n[[gantry]]\nname = \"G\"\naxes = [\"G1\", \"G2\"]\nmax_skew = 1.0\n",
        switch_axis("G1", "counts_per_unit = 1000.0"),
        switch_axis("G2", "counts_per_unit = 1000.0")
    )
}

#[test]
fn a_gantry_side_faulting_during_a_reset_stops_the_other_side() {
    // Both sides jog; a reset is accepted on both (nothing to clear); G1's
    // drive faults in the next cycle. G1's fault is judged at once — a
    // reset excuses only a fault it was asked to clear — and G2 stops in
    // the cycle after, instead of jogging on for enable_timeout while G1
    // stands switched off (the gantry racked by the jog's travel).
    for late in [0u64, 2] {
        let mut b = Bench::new(&gantry());
        b.run(5);
        b.op(0b11, Operation::Enable, 0);
        b.run(20);
        let jog = Operation::Jog(JogSpec {
            speed: 5.0,
            lease: Some(0.5),
            accel: Some(100.0),
            decel: Some(100.0),
            jerk: None,
        });
        b.op(0b11, jog, 42);
        b.run(100);
        assert!(b.snap().axes[1].status.jogging);
        b.op(0b11, Operation::Reset, 0);
        b.run(1 + late);
        b.plants[0].inject_fault();
        // Its next answer shows it; the cycle after sees it.
        b.run(2);
        let s = b.snap();
        assert!(s.axes[0].status.faulted, "{late}: {:?}", s.axes[0].status);
        assert!(!s.axes[0].enable, "{late}: G1 requested off");
        b.run(2);
        let s = b.snap();
        let g2 = s.axes[1].status;
        assert!(!g2.jogging && (g2.stopping || g2.op.pc), "{late}: {g2:?}");
        // Apart by no more than what G2 covers while it stops (10 ms at
        // most at 5 u/s, then 5² / 200).
        b.run(200);
        let apart = (b.plants[1].position() - b.plants[0].position()).abs();
        assert!(apart <= 5.0 * 0.01 + 25.0 / 200.0, "{late}: racked {apart}");
    }
}

#[test]
fn a_restarted_io_process_gets_no_enable_it_did_not_ask_for() {
    // X enabled and at rest; its I/O process restarts (a new origin): the
    // new process's drives start off, and the cycle must not switch them
    // on by a request left standing. From the restart on, every command
    // asks for the power stage off, until someone enables it again.
    let mut b = Bench::new(ONE_AXIS);
    b.run(5);
    b.op(1, Operation::Enable, 0);
    b.run(20);
    assert!(b.snap().axes[0].enable && b.snap().axes[0].status.servo_action);
    b.origin[0] = 4321;
    b.run(2);
    for _ in 0..50 {
        b.cycle();
        assert!(!b.snap().axes[0].enable, "{:?}", b.snap().axes[0].status);
    }
    b.op(1, Operation::Enable, 0);
    b.run(20);
    assert!(
        b.snap().axes[0].status.servo_action,
        "enabled again on request"
    );
}

#[test]
fn a_gantry_is_redefined_whole_or_not_at_all() {
    use crate::shared::{AxisAck, Refusal};
    use motion_homing::codes::{ERR_AXIS_FAULTED, EX_REDEFINE};
    use motion_homing::RedefineSpec;
    let mut b = Bench::new(&gantry());
    b.run(5);
    b.home(0b11, true);
    for _ in 0..20_000 {
        b.cycle();
        let s = b.snap();
        if s.axes[..2].iter().all(|a| a.status.pc && a.settled()) {
            break;
        }
    }
    b.run(5);
    let before = b.snap();
    assert!(
        before.axes[..2].iter().all(|a| a.status.homed),
        "{before:?}"
    );
    let raw = [before.axes[0].cmd_position, before.axes[1].cmd_position];
    let skew = before.axes[1].cmd_axis.unwrap() - before.axes[0].cmd_axis.unwrap();
    // --position 7 on the gantry: both sides by the shift that makes G1 read 7.
    b.op(0b11, Operation::Redefine(RedefineSpec::to(7.0)), 0);
    b.run(3);
    let ack = b.acks.pop().unwrap();
    assert!(
        ack.axes[..2].iter().all(|a| *a == AxisAck::Accepted),
        "{ack:?}"
    );
    let s = b.snap();
    assert!((s.axes[0].cmd_axis.unwrap() - 7.0).abs() < 1e-9);
    let now_skew = s.axes[1].cmd_axis.unwrap() - s.axes[0].cmd_axis.unwrap();
    assert!((now_skew - skew).abs() < 1e-9, "{skew} → {now_skew}");
    assert_eq!([s.axes[0].cmd_position, s.axes[1].cmd_position], raw);
    // G2 faulted: G1 would accept, G2 refuses: neither is redefined.
    b.plants[1].inject_fault();
    b.run(3);
    assert!(b.snap().axes[1].status.faulted);
    b.op(0b11, Operation::Redefine(RedefineSpec::by(5.0)), 0);
    b.run(3);
    let ack = b.acks.pop().unwrap();
    assert_eq!(ack.axes[0], AxisAck::Refused(Refusal::NotStarted));
    assert_eq!(
        ack.axes[1],
        AxisAck::Refused(Refusal::Operation {
            err: ERR_AXIS_FAULTED,
            exerr: EX_REDEFINE
        })
    );
    let s = b.snap();
    assert!((s.axes[0].cmd_axis.unwrap() - 7.0).abs() < 1e-9);
    assert_eq!(
        s.axes[0].status.shift,
        7.0 - before.axes[0].cmd_axis.unwrap()
    );
    assert_eq!(s.axes[0].status.redefines, 1);
}

#[test]
fn after_a_redefine_the_monitor_keeps_the_soft_limits_on_the_machine() {
    use motion_homing::{MoveSpec, RedefineSpec};
    // X homed at raw 0 (position 0), limits [-20, 20]; by 5: the limits
    // read [-15, 25], the same raw places. A move to 25 ends on raw 20
    // and the cycle monitor, which checks every command against the soft
    // limits on its own, sees nothing wrong.
    let mut b = homed_and_enabled();
    b.op(1, Operation::Redefine(RedefineSpec::by(5.0)), 0);
    b.run(2);
    assert_eq!(b.snap().axes[0].status.soft_limits, Some((-15.0, 25.0)));
    b.op(1, Operation::Move(MoveSpec::to(25.0)), 0);
    b.run(2);
    for _ in 0..5000 {
        b.cycle();
        if b.snap().axes[0].status.op.pc {
            break;
        }
    }
    let s = b.snap().axes[0];
    assert!(s.status.op.pc && !s.status.er, "{:?}", s.status);
    assert!(s.monitor.is_none(), "{:?}", s.monitor);
    assert!((cmd(&b) - 20.0).abs() < 1e-9, "{}", cmd(&b));
}
