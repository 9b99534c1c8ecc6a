//! `AxisLogic`, cycle by cycle: the CiA 402 walk, set-points, faults, the
//! bounded stop, the drive's homing, a lost drive.
use super::*;
use crate::pdo::TorqueLimits;

fn logic() -> AxisLogic {
    AxisLogic::new(AxisSetup {
        index_pulse_bit: Some(16),
        ..AxisSetup::new(
            PdoLayout::standard(TorqueLimits::PerDirection, false),
            0.001,
        )
    })
}

fn cmd(enable: bool, target: i64) -> AxisCommand {
    AxisCommand {
        target_position: target,
        torque_limit_positive: 100.0,
        torque_limit_negative: 50.0,
        control_word: if enable { CW_ENABLE } else { 0 },
        ..AxisCommand::ZERO
    }
}

/// One cycle of `a`: the command [`cmd`]`(enable, target)` in `mode`, the
/// drive reporting [`inputs`]`(state, pos)`.
fn cycle(
    a: &mut AxisLogic,
    enable: bool,
    target: i64,
    mode: Mode,
    state: State,
    pos: i32,
) -> (DriveOutputs, AxisFeedback) {
    a.step(&cmd(enable, target), mode, Some(&inputs(state, pos)))
}

fn inputs(state: State, pos: i32) -> DriveInputs {
    DriveInputs {
        statusword: state.statusword() | 0x0200,
        position: pos,
        ..DriveInputs::default()
    }
}

#[test]
fn enabling_walks_the_state_machine_and_target_tracks_actual() {
    let mut a = logic();
    let (o, fb) = cycle(
        &mut a,
        true,
        500,
        Mode::Normal,
        State::SwitchOnDisabled,
        123,
    );
    assert_eq!(o.controlword, 0x0006);
    assert_eq!(o.target_position, 123, "not enabled: follows actual");
    assert_eq!(o.torque_limit_positive, 1000);
    assert_eq!(o.torque_limit_negative, 500);
    assert_eq!(o.mode, 8);
    assert_eq!(fb.status_word, 0);
    assert_eq!(fb.position, 123);
    let (o, _) = cycle(&mut a, true, 500, Mode::Normal, State::ReadyToSwitchOn, 123);
    assert_eq!(o.controlword, 0x0007);
    let (o, _) = cycle(&mut a, true, 500, Mode::Normal, State::SwitchedOn, 123);
    assert_eq!(o.controlword, 0x000F);
    assert_eq!(o.target_position, 123);
    let (o, fb) = cycle(
        &mut a,
        true,
        500,
        Mode::Normal,
        State::OperationEnabled,
        124,
    );
    assert_eq!(o.target_position, 500);
    assert_eq!(fb.status_word, SW_ENABLED);
    // disable
    let (o, fb) = cycle(
        &mut a,
        false,
        500,
        Mode::Normal,
        State::OperationEnabled,
        500,
    );
    assert_eq!(o.controlword, 0x0006);
    assert_eq!(o.target_position, 500);
    assert_eq!(fb.status_word, SW_ENABLED, "reports the drive's state");
}

#[test]
fn positions_extend_over_the_32_bit_wrap() {
    let mut a = logic();
    let mut p = i32::MAX - 5;
    let (_, fb) = cycle(&mut a, false, 0, Mode::Normal, State::SwitchOnDisabled, p);
    assert_eq!(fb.position, i64::from(i32::MAX) - 5);
    for _ in 0..10 {
        p = p.wrapping_add(3);
        cycle(&mut a, false, 0, Mode::Normal, State::SwitchOnDisabled, p);
    }
    assert_eq!(a.last_feedback().position, i64::from(i32::MAX) + 25);
    // a target beyond 2^31 goes out modulo 2^32
    let t = i64::from(i32::MAX) + 30;
    for s in [State::OperationEnabled, State::OperationEnabled] {
        let (o, _) = cycle(&mut a, true, t, Mode::Normal, s, p);
        assert_eq!(o.target_position, t as i32);
    }
}

#[test]
fn bad_setpoints_are_refused_with_a_fault_until_the_handshake() {
    let mut a = logic();
    cycle(&mut a, true, 0, Mode::Normal, State::OperationEnabled, 0);
    let (o, _) = cycle(&mut a, true, 10, Mode::Normal, State::OperationEnabled, 0);
    assert_eq!(o.target_position, 10);
    let (o, fb) = cycle(
        &mut a,
        true,
        INVALID_COUNTS,
        Mode::Normal,
        State::OperationEnabled,
        10,
    );
    assert_eq!(o.target_position, 10, "last good target held");
    assert_eq!(o.controlword, 0x0002, "quick stop on the drive's ramp");
    assert_eq!(fb.status_word & SW_FAULT, SW_FAULT);
    assert_eq!(a.counters.rejected_setpoints, 1);
    // too far away
    let mut b = logic();
    cycle(&mut b, true, 0, Mode::Normal, State::OperationEnabled, 0);
    cycle(
        &mut b,
        true,
        MAX_TARGET_DISTANCE + 1,
        Mode::Normal,
        State::OperationEnabled,
        0,
    );
    assert_eq!(b.counters.rejected_setpoints, 1);
    // NaN torque limit
    let mut c = logic();
    let mut n = cmd(true, 0);
    n.torque_limit_positive = f32::NAN;
    cycle(&mut c, true, 0, Mode::Normal, State::OperationEnabled, 0);
    c.step(&n, Mode::Normal, Some(&inputs(State::OperationEnabled, 0)));
    assert_eq!(c.counters.rejected_setpoints, 1);
    // fault stays while enable stays; drive now disabled
    let (o, fb) = cycle(&mut a, true, 10, Mode::Normal, State::ReadyToSwitchOn, 10);
    assert_eq!(
        o.controlword, 0x0000,
        "held in Switch on disabled until a reset"
    );
    assert_eq!(fb.status_word, SW_FAULT);
    // handshake
    cycle(&mut a, false, 10, Mode::Normal, State::ReadyToSwitchOn, 10);
    let (o, fb) = cycle(&mut a, true, 10, Mode::Normal, State::ReadyToSwitchOn, 10);
    assert_eq!(o.controlword, 0x0007);
    assert_eq!(fb.status_word, 0);
}

#[test]
fn drive_fault_code_kept_and_reset_on_the_edge() {
    let mut a = logic();
    let mut f = inputs(State::Fault, 0);
    f.error_code = 0x2310;
    let (o, fb) = a.step(&cmd(true, 0), Mode::Normal, Some(&f));
    // the first command's rising edge asks for a reset at once
    assert_eq!(o.controlword, 0x0080);
    assert_eq!(fb.status_word, SW_FAULT);
    assert_eq!(fb.error_code, 0x2310);
    // the drive stays in fault (cause persists), the code is kept even if
    // the drive clears 0x603F early
    f.error_code = 0;
    let (_, fb) = a.step(&cmd(true, 0), Mode::Normal, Some(&f));
    assert_eq!(fb.error_code, 0x2310);
    // out of fault: code 0
    let (_, fb) = cycle(&mut a, true, 0, Mode::Normal, State::SwitchOnDisabled, 0);
    assert_eq!((fb.status_word, fb.error_code), (0, 0));
}

#[test]
fn watchdog_stop_quick_stops_then_disables_with_a_fault() {
    let mut a = logic();
    cycle(&mut a, true, 0, Mode::Normal, State::OperationEnabled, 0);
    let mut moving = inputs(State::OperationEnabled, 100);
    moving.velocity = 50_000;
    let (o, _) = a.step(&cmd(true, 0), Mode::WatchdogStop, Some(&moving));
    assert_eq!(o.controlword, 0x0002);
    assert_eq!(o.target_position, 100);
    let mut qs = inputs(State::QuickStopActive, 200);
    qs.velocity = 20_000;
    let (o, fb) = a.step(&cmd(true, 0), Mode::WatchdogStop, Some(&qs));
    assert_eq!(o.controlword, 0x0002);
    assert_eq!(fb.status_word & SW_FAULT, 0, "no fault while stopping");
    assert!(!a.at_rest_and_disabled());
    qs.velocity = 0;
    // at rest only after REST_CYCLES still samples: one may be a repeated
    // set-point of a moving axis
    for _ in 1..crate::axis::REST_CYCLES {
        let (o, _) = a.step(&cmd(true, 0), Mode::WatchdogStop, Some(&qs));
        assert_eq!(o.controlword, 0x0002, "not yet at rest");
    }
    let (o, fb) = a.step(&cmd(true, 0), Mode::WatchdogStop, Some(&qs));
    assert_eq!(o.controlword, 0x0000, "quick stop active → disable voltage");
    assert_eq!(fb.status_word & SW_FAULT, SW_FAULT);
    let (_, fb) = cycle(
        &mut a,
        true,
        0,
        Mode::WatchdogStop,
        State::SwitchOnDisabled,
        210,
    );
    assert!(a.at_rest_and_disabled());
    assert_eq!(fb.status_word, SW_FAULT);
    // commands again: enable still true → no edge → fault stays
    let (o, fb) = cycle(
        &mut a,
        true,
        210,
        Mode::Normal,
        State::SwitchOnDisabled,
        210,
    );
    assert_eq!(
        o.controlword, 0x0000,
        "held in Switch on disabled until a reset"
    );
    assert_eq!(fb.status_word, SW_FAULT);
    cycle(
        &mut a,
        false,
        210,
        Mode::Normal,
        State::SwitchOnDisabled,
        210,
    );
    let (_, fb) = cycle(
        &mut a,
        true,
        210,
        Mode::Normal,
        State::SwitchOnDisabled,
        210,
    );
    assert_eq!(fb.status_word, 0);

    // an axis that never asked to be enabled: no fault
    let mut b = logic();
    let (_, fb) = cycle(
        &mut b,
        false,
        0,
        Mode::WatchdogStop,
        State::SwitchOnDisabled,
        0,
    );
    assert_eq!(fb.status_word, 0);
    assert!(b.at_rest_and_disabled());
}

#[test]
fn commands_back_in_the_middle_of_a_watchdog_stop_never_enable_again() {
    let mut a = logic();
    cycle(&mut a, true, 0, Mode::Normal, State::OperationEnabled, 0);
    let (o, _) = cycle(
        &mut a,
        true,
        0,
        Mode::WatchdogStop,
        State::OperationEnabled,
        0,
    );
    assert_eq!(o.controlword, 0x0002);
    // the drive ended its quick stop by itself; the commands come back
    // before the stop saw it: enable still asked for, no edge
    for _ in 0..5 {
        let (o, fb) = cycle(&mut a, true, 0, Mode::Normal, State::SwitchOnDisabled, 0);
        assert_eq!(o.controlword, 0x0000, "never walked to enabled");
        assert_eq!(fb.status_word, SW_FAULT);
    }
    // a reset (the enable edge) and it enables
    cycle(&mut a, false, 0, Mode::Normal, State::SwitchOnDisabled, 0);
    let (o, fb) = cycle(&mut a, true, 0, Mode::Normal, State::SwitchOnDisabled, 0);
    assert_eq!((o.controlword, fb.status_word), (0x0006, 0));
}

#[test]
fn emergency_is_disable_voltage_and_a_fault() {
    let mut a = logic();
    cycle(&mut a, true, 0, Mode::Normal, State::OperationEnabled, 0);
    let (o, fb) = cycle(&mut a, true, 0, Mode::Emergency, State::OperationEnabled, 0);
    assert_eq!(o.controlword, 0x0000);
    assert_eq!(fb.status_word & SW_FAULT, SW_FAULT);
}

#[test]
fn no_data_keeps_outputs_and_reports_last_values() {
    let mut a = logic();
    let mut i = inputs(State::OperationEnabled, 42);
    i.digital_inputs = di::HOME_SWITCH | (1 << 16);
    i.torque = -125;
    let (o1, fb1) = a.step(&cmd(true, 42), Mode::Normal, Some(&i));
    assert_eq!(fb1.digital_inputs, DI_HOME_SWITCH | DI_MARKER_PULSE);
    assert_eq!(fb1.torque, -12.5);
    // enabled and following: the target goes on, the rest stays
    let (o2, fb2) = a.step(&cmd(true, 99), Mode::Normal, None);
    assert_eq!(
        o2,
        DriveOutputs {
            target_position: 99,
            ..o1
        }
    );
    assert_eq!(fb2.status_word, fb1.status_word | SW_NO_DATA);
    assert_eq!(fb2.position, 42);
}

#[test]
fn a_stop_without_data_is_sent_blind_on_time_alone() {
    // quick stop bound 20 ms at 1 ms: enabled and moving, then no data
    let mut a = AxisLogic::new(AxisSetup {
        quick_stop_ms: 20,
        ..AxisSetup::new(
            PdoLayout::standard(TorqueLimits::PerDirection, false),
            0.001,
        )
    });
    let (o, _) = cycle(&mut a, true, 100, Mode::Normal, State::OperationEnabled, 90);
    assert_eq!(o.controlword, 0x000F);
    // enabled and following: the target goes on, the state machine is not
    // stepped blind
    let (o, _) = a.step(&cmd(true, 120), Mode::Normal, None);
    assert_eq!((o.controlword, o.target_position), (0x000F, 120));
    // the watchdog stop: quick stop until the bound (never judged ignored
    // without data), then disable voltage, the target held
    let words: Vec<u16> = (0..22)
        .map(|_| a.step(&cmd(true, 140), Mode::WatchdogStop, None).0)
        .map(|o| {
            assert_eq!(o.target_position, 120);
            o.controlword
        })
        .collect();
    assert!(words[..20].iter().all(|w| *w == 0x0002), "{words:?}");
    assert_eq!(&words[20..], &[0x0000, 0x0000]);
    assert_eq!(a.counters.blind_stop_cycles, 22);
    // not counted as stopped: its state was not seen
    assert!(!a.at_rest_and_disabled());
    // data again: Switch on disabled seen, the stop complete, a fault
    let (o, fb) = cycle(
        &mut a,
        true,
        120,
        Mode::WatchdogStop,
        State::SwitchOnDisabled,
        95,
    );
    assert_eq!(o.controlword, 0x0000);
    assert!(a.at_rest_and_disabled());
    assert_eq!(fb.status_word & (SW_ENABLED | SW_FAULT), SW_FAULT);

    // lost (not answering) in the middle of a watchdog stop: the stop goes
    // on from the last state seen — quick stop until the bound, not
    // disable voltage at once
    let mut a = AxisLogic::new(AxisSetup {
        quick_stop_ms: 20,
        ..AxisSetup::new(
            PdoLayout::standard(TorqueLimits::PerDirection, false),
            0.001,
        )
    });
    cycle(
        &mut a,
        true,
        100,
        Mode::Normal,
        State::OperationEnabled,
        100,
    );
    let words: Vec<u16> = (0..22)
        .map(|_| {
            a.lost();
            a.step(&cmd(true, 100), Mode::WatchdogStop, None)
                .0
                .controlword
        })
        .collect();
    assert!(words[..20].iter().all(|w| *w == 0x0002), "{words:?}");
    assert_eq!(&words[20..], &[0x0000, 0x0000]);

    // a disable without data: "shutdown" at once; the emergency stop:
    // disable voltage at once
    for (mode, enable, word) in [
        (Mode::Normal, false, 0x0006),
        (Mode::Emergency, true, 0x0000),
    ] {
        let mut a = logic();
        cycle(&mut a, true, 0, Mode::Normal, State::OperationEnabled, 0);
        let (o, _) = a.step(&cmd(enable, 0), mode, None);
        assert_eq!(o.controlword, word, "{mode:?}");
    }
}

#[test]
fn without_data_a_following_drive_gets_the_command_and_after_a_loss_never_a_jump() {
    let mut a = logic();
    let fast = |t: i64| AxisCommand {
        target_velocity: 20_000.0, // 20 counts per cycle
        ..cmd(true, t)
    };
    for k in 0..5 {
        let (o, _) = a.step(
            &fast(1000 + 20 * k),
            Mode::Normal,
            Some(&inputs(State::OperationEnabled, (980 + 20 * k) as i32)),
        );
        assert_eq!(o.target_position, (1000 + 20 * k) as i32);
    }
    // no data (a working counter not to be trusted): the command's target
    // goes on out, the controlword stays
    for k in 5..35 {
        let (o, fb) = a.step(&fast(1000 + 20 * k), Mode::Normal, None);
        assert_eq!(
            (o.target_position, o.controlword),
            ((1000 + 20 * k) as i32, 0x000F)
        );
        assert_ne!(fb.status_word & SW_NO_DATA, 0);
    }
    let (o, fb) = a.step(
        &fast(1700),
        Mode::Normal,
        Some(&inputs(State::OperationEnabled, 1660)),
    );
    assert_eq!(o.target_position, 1700);
    assert_eq!(fb.status_word & SW_FAULT, 0);
    // lost for 30 cycles (its outputs frozen) while the command ran on,
    // back still in Operation enabled: not 600 counts in one cycle — its
    // actual position, the backend's fault, the bounded stop
    for k in 1..=30 {
        a.lost();
        let (o, _) = a.step(&fast(1700 + 20 * k), Mode::Normal, None);
        assert_eq!(o.target_position, 1700, "frozen while lost");
    }
    let (o, fb) = a.step(
        &fast(2320),
        Mode::Normal,
        Some(&inputs(State::OperationEnabled, 1700)),
    );
    assert_eq!(o.target_position, 1700, "never 620 counts in one cycle");
    assert_eq!(o.controlword, 0x0002, "quick stop");
    assert_eq!(fb.status_word & SW_FAULT, SW_FAULT);
    assert_eq!(a.counters.gap_stops, 1);
    // a loss the engine rides out (up to its feedback timeout, 10 cycles
    // here) is caught up: no fault
    let mut a = logic();
    a.step(
        &fast(1000),
        Mode::Normal,
        Some(&inputs(State::OperationEnabled, 1000)),
    );
    for k in 1..=9 {
        a.lost();
        a.step(&fast(1000 + 20 * k), Mode::Normal, None);
    }
    let (o, fb) = a.step(
        &fast(1200),
        Mode::Normal,
        Some(&inputs(State::OperationEnabled, 1000)),
    );
    assert_eq!((o.target_position, fb.status_word & SW_FAULT), (1200, 0));
}

#[test]
fn tolerance_becomes_the_following_error_window() {
    let mut a = logic();
    let mut c = cmd(true, 0);
    a.step(&c, Mode::Normal, Some(&inputs(State::OperationEnabled, 0)));
    assert_eq!(a.following_error_window(), u32::MAX);
    c.position_error_tolerance = 1234.4;
    a.step(&c, Mode::Normal, Some(&inputs(State::OperationEnabled, 0)));
    assert_eq!(a.following_error_window(), 1234);
    c.position_error_tolerance = f64::NAN;
    a.step(&c, Mode::Normal, Some(&inputs(State::OperationEnabled, 0)));
    assert_eq!(a.following_error_window(), u32::MAX);
}

/// A drive that ignores quick stop stays in Operation enabled: after
/// `QS_ACK_CYCLES` the stop sends disable voltage, and the stop completes
/// once the drive reports Switch on disabled.
#[test]
fn a_drive_ignoring_quick_stop_is_switched_off_within_the_bound() {
    let mut a = logic();
    let on = inputs(State::OperationEnabled, 0);
    a.step(&cmd(true, 0), Mode::Normal, Some(&on));
    let mut words = Vec::new();
    for _ in 0..crate::stop::QS_ACK_CYCLES + 2 {
        let (o, _) = a.step(&cmd(true, 0), Mode::WatchdogStop, Some(&on));
        words.push(o.controlword);
        assert!(!a.at_rest_and_disabled());
    }
    let k = crate::stop::QS_ACK_CYCLES as usize;
    assert!(words[..k].iter().all(|w| *w == 0x0002), "{words:x?}");
    assert_eq!(words[k], 0x0000, "disable voltage: {words:x?}");
    let (_, fb) = cycle(
        &mut a,
        true,
        0,
        Mode::WatchdogStop,
        State::SwitchOnDisabled,
        0,
    );
    assert!(a.at_rest_and_disabled());
    assert_eq!(fb.status_word & SW_FAULT, SW_FAULT);
}

/// `CW_FAULT_RESET`'s rising edge resets a drive fault (bit 7) and the
/// backend's own fault, and enables nothing.
#[test]
fn the_fault_reset_request_is_controlword_bit_7_and_enables_nothing() {
    let mut a = logic();
    let mut f = inputs(State::Fault, 0);
    f.error_code = 0x7500;
    let reset = |on: bool| AxisCommand {
        control_word: if on { CW_FAULT_RESET } else { 0 },
        ..cmd(false, 0)
    };
    let (o, fb) = a.step(&reset(false), Mode::Normal, Some(&f));
    assert_eq!(o.controlword, 0x0000, "no request: stays in fault");
    assert_eq!(fb.error_code, 0x7500);
    let (o, _) = a.step(&reset(true), Mode::Normal, Some(&f));
    assert_eq!(o.controlword, 0x0080, "bit 7 rises");
    let (o, fb) = a.step(
        &reset(true),
        Mode::Normal,
        Some(&inputs(State::SwitchOnDisabled, 0)),
    );
    assert_eq!(o.controlword, 0x0006, "disabled: shutdown, never enabled");
    assert_eq!(fb.status_word, 0);
    // the backend's own fault (a watchdog stop) too
    let mut b = logic();
    let on = inputs(State::OperationEnabled, 0);
    b.step(&cmd(true, 0), Mode::Normal, Some(&on));
    b.step(&cmd(true, 0), Mode::Emergency, Some(&on));
    let off = inputs(State::SwitchOnDisabled, 0);
    let (_, fb) = b.step(&cmd(true, 0), Mode::Normal, Some(&off));
    assert_eq!(fb.status_word, SW_FAULT);
    let mut c = cmd(true, 0);
    c.control_word |= CW_FAULT_RESET;
    let (o, fb) = b.step(&c, Mode::Normal, Some(&off));
    assert_eq!(fb.status_word, 0);
    assert_eq!(
        o.controlword, 0x0006,
        "enable was requested all along: walks up"
    );
}

/// A lost drive that was enabled comes back faulted: not enabled by itself.
/// One that rode the loss out still enabled goes on.
#[test]
fn a_lost_drive_is_not_enabled_again_by_itself() {
    let mut a = logic();
    let on = inputs(State::OperationEnabled, 0);
    a.step(&cmd(true, 0), Mode::Normal, Some(&on));
    a.lost();
    let (_, fb) = a.step(&cmd(true, 0), Mode::Normal, None);
    assert_eq!(fb.status_word & SW_ENABLED, 0, "not reported enabled");
    let mut b = logic();
    b.step(&cmd(true, 0), Mode::Normal, Some(&on));
    b.lost();
    let (o, fb) = b.step(&cmd(true, 0), Mode::Normal, Some(&on));
    assert_eq!((o.controlword, fb.status_word), (0x000F, SW_ENABLED));
    // back, power-cycled: Switch on disabled
    let back = inputs(State::SwitchOnDisabled, 5);
    for _ in 0..5 {
        let (o, fb) = a.step(&cmd(true, 0), Mode::Normal, Some(&back));
        assert_eq!(o.controlword, 0x0000);
        assert_eq!(fb.status_word, SW_FAULT);
    }
    // the handshake (or a reset) lets it be enabled again
    a.step(&cmd(false, 5), Mode::Normal, Some(&back));
    let (o, _) = a.step(&cmd(true, 5), Mode::Normal, Some(&back));
    assert_eq!(o.controlword, 0x0006);
}

/// Without 0x606C the velocity is the position's change per cycle; without
/// 0x60FD no input is reported; the home switch may sit in a manufacturer
/// bit.
#[test]
fn objects_the_layout_lacks_and_a_home_switch_bit() {
    use crate::objects::*;
    let minimal = PdoLayout::from_entries(
        &[CONTROLWORD, TARGET_POSITION],
        &[STATUSWORD, POSITION_ACTUAL],
        &[0x1600],
        &[0x1A00],
    )
    .unwrap();
    let mut a = AxisLogic::new(AxisSetup::new(minimal, 0.001));
    let mut i = inputs(State::OperationEnabled, 100);
    i.digital_inputs = 0xFFFF_FFFF;
    a.step(&cmd(true, 100), Mode::Normal, Some(&i));
    i.position = 103;
    let (_, fb) = a.step(&cmd(true, 103), Mode::Normal, Some(&i));
    assert_eq!(fb.velocity, 3000.0, "3 counts in 1 ms");
    assert_eq!(fb.digital_inputs, 0);
    a.step(&cmd(true, 103), Mode::Normal, None);
    i.position = 109;
    let (_, fb) = a.step(&cmd(true, 109), Mode::Normal, Some(&i));
    assert_eq!(fb.velocity, 3000.0, "6 counts in 2 ms (one without data)");

    let mut b = AxisLogic::new(AxisSetup {
        home_switch_bit: Some(20),
        ..AxisSetup::new(
            PdoLayout::standard(TorqueLimits::PerDirection, false),
            0.001,
        )
    });
    let mut i = inputs(State::OperationEnabled, 0);
    i.digital_inputs = crate::objects::di::HOME_SWITCH;
    let (_, fb) = b.step(&cmd(true, 0), Mode::Normal, Some(&i));
    assert_eq!(fb.digital_inputs, 0, "bit 2 is not the switch here");
    i.digital_inputs = 1 << 20;
    let (_, fb) = b.step(&cmd(true, 0), Mode::Normal, Some(&i));
    assert_eq!(fb.digital_inputs, DI_HOME_SWITCH);
}

/// `CW_DRIVE_HOME` through the axis: mode 6, bit 4, the set-point on the
/// actual position, attained, back to 8 and the command followed again only
/// once it is near the actual position.
#[test]
fn the_drive_homes_in_mode_6_and_hands_back_without_a_jump() {
    let mut a = AxisLogic::new(AxisSetup {
        drive_homing: true,
        ..AxisSetup::new(PdoLayout::standard(TorqueLimits::PerDirection, true), 0.001)
    });
    let home = |t: i64| AxisCommand {
        control_word: CW_ENABLE | CW_DRIVE_HOME,
        ..cmd(true, t)
    };
    let mut i = inputs(State::OperationEnabled, 1000);
    i.mode_display = 8;
    a.step(&cmd(true, 1000), Mode::Normal, Some(&i));
    let (o, fb) = a.step(&home(1000), Mode::Normal, Some(&i));
    assert_eq!((o.mode, o.controlword & 0x10), (6, 0));
    assert_eq!(fb.status_word & SW_DRIVE_HOMING, 0, "not confirmed yet");
    i.mode_display = 6;
    i.position = 1500;
    let (o, fb) = a.step(&home(1000), Mode::Normal, Some(&i));
    assert_eq!(o.controlword, 0x001F, "enable operation + start homing");
    assert_eq!(
        o.target_position, 1500,
        "the actual position, not the command"
    );
    assert_ne!(fb.status_word & SW_DRIVE_HOMING, 0);
    i.statusword |= 0x1400; // attained + target reached
    i.position = 7; // redefined
    let (_, fb) = a.step(&home(1000), Mode::Normal, Some(&i));
    assert_ne!(fb.status_word & SW_DRIVE_HOMED, 0);
    let (o, fb) = a.step(&cmd(true, 1000), Mode::Normal, Some(&i));
    assert_eq!((o.mode, o.target_position), (8, 7));
    assert_ne!(fb.status_word & SW_DRIVE_HOMING, 0, "still handing back");
    i.mode_display = 8;
    i.statusword = State::OperationEnabled.statusword();
    let (o, fb) = a.step(&cmd(true, 1000), Mode::Normal, Some(&i));
    assert_eq!(fb.status_word & SW_DRIVE_HOMING, 0);
    assert_eq!(
        o.target_position, 7,
        "a stale target far away is not followed"
    );
    let (o, _) = a.step(&cmd(true, 9), Mode::Normal, Some(&i));
    assert_eq!(o.target_position, 9, "near the actual position: followed");
    // asked of an axis whose drive does not home: an error
    let mut b = logic();
    let (_, fb) = b.step(
        &home(0),
        Mode::Normal,
        Some(&inputs(State::OperationEnabled, 0)),
    );
    assert_ne!(fb.status_word & SW_DRIVE_HOMING_ERROR, 0);
}
