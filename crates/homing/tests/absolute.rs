//! Absolute encoders: MAH's Absolute home mode and the stored reference.
//!
//! Hand-worked numbers: the encoder reads raw 123.4; Home Position 10, Home
//! Offset 5 (ignored: Absolute, like Immediate, takes no offset). Homing
//! makes the raw -> axis offset 10 - 123.4 = -113.4, and the axis reads 10.

use motion_homing::codes::*;
use motion_homing::*;

const MS: u64 = 1_000_000;
const RAW: f64 = 123.4;

fn absolute_axis() -> AxisConfig {
    AxisConfig {
        counts_per_unit: 1000.0,
        absolute: true,
        home_mode: HomeMode::Absolute,
        home_sequence: HomeSequence::Immediate,
        home_position: 10.0,
        home_offset: 5.0,
        travel_limits: Some((-50.0, 150.0)),
        ..AxisConfig::default()
    }
}

fn at(raw: f64) -> Feedback {
    Feedback {
        position: raw,
        ..Feedback::default()
    }
}

fn home() -> Request {
    Request {
        home: true,
        ..Request::default()
    }
}

/// Steps `axis` at `k` ms with the encoder at `raw`; the command must never
/// move the axis (it holds the raw position, drive not enabled).
fn step(axis: &mut Axis, k: u64, raw: f64, req: &Request) {
    let cmd = axis.step(k * MS, Some(&at(raw)), req);
    assert_eq!((cmd.position, cmd.velocity, cmd.enable), (raw, 0.0, false));
}

#[test]
fn absolute_mode_is_validated() {
    let codes = |c: AxisConfig| -> Vec<(&str, u16, u16)> {
        validate(&c)
            .iter()
            .map(|e| (e.attribute, e.err, e.exerr))
            .collect()
    };
    assert!(codes(absolute_axis()).is_empty());
    assert_eq!(
        codes(AxisConfig {
            home_sequence: HomeSequence::Switch,
            home_speed: 1.0,
            ..absolute_axis()
        }),
        [("home_sequence", 41, EX_SEQUENCE_INCOMPATIBLE)]
    );
    assert_eq!(
        codes(AxisConfig {
            absolute: false,
            ..absolute_axis()
        }),
        [("home_mode", 41, EX_ABSOLUTE_NOT_ABSOLUTE)]
    );
    // A feedback-only axis may home absolute (CIP: passive or absolute).
    assert!(codes(AxisConfig {
        configuration: AxisConfiguration::FeedbackOnly,
        ..absolute_axis()
    })
    .is_empty());
    // Refused by the instruction at start, as every configuration error.
    let mut axis = Axis::new(AxisConfig {
        absolute: false,
        ..absolute_axis()
    });
    axis.step(0, Some(&at(RAW)), &home());
    let s = axis.status();
    assert!(s.er && !s.homed);
    assert_eq!((s.err, s.exerr), (41, EX_ABSOLUTE_NOT_ABSOLUTE));
}

#[test]
fn home_absolute_then_restart_and_restore_without_motion() {
    let mut axis = Axis::new(absolute_axis());
    step(&mut axis, 0, RAW, &home());
    let s = *axis.status();
    assert!(s.pc && s.dn && s.homed && !s.er, "{s:?}");
    assert!((axis.axis_position().unwrap() - 10.0).abs() < 1e-9);
    let stored = axis.reference_offset().unwrap();
    assert!((stored - -113.4).abs() < 1e-9, "{stored}");

    // A restart: a new engine, same config, encoder still at 123.4.
    let mut axis = Axis::new(absolute_axis());
    assert_eq!(axis.reference_offset(), None);
    step(&mut axis, 0, RAW, &Request::default());
    assert!(!axis.status().homed);
    axis.restore_reference(0, stored, 0.0).unwrap();
    let s = *axis.status();
    assert!(
        s.homed && !s.pc && !s.dn && !s.ip,
        "homed, no instruction ran: {s:?}"
    );
    assert!((axis.axis_position().unwrap() - 10.0).abs() < 1e-9);
    assert_eq!(axis.reference_offset(), Some(stored));
    for k in 1..100 {
        step(&mut axis, k, RAW, &Request::default());
    }
    assert!(axis.status().homed);

    // Restoring again applies the same offset, not twice: still 10.
    axis.restore_reference(100 * MS, stored, 0.0).unwrap();
    assert!((axis.axis_position().unwrap() - 10.0).abs() < 1e-9);
}

#[test]
fn homing_again_never_applies_the_offset_twice() {
    // LinuxCNC #3717: re-homing an absolute axis added the offset again
    // because it started from the joint (axis) position. Here the offset is
    // recomputed from the raw position: 10 after every homing.
    let mut axis = Axis::new(absolute_axis());
    step(&mut axis, 0, RAW, &Request::default());
    axis.restore_reference(0, -113.4, 0.0).unwrap();
    let mut k = 1;
    for _ in 0..3 {
        step(&mut axis, k, RAW, &Request::default());
        step(&mut axis, k + 1, RAW, &home());
        k += 2;
        assert!(axis.status().pc);
        assert!((axis.axis_position().unwrap() - 10.0).abs() < 1e-9);
        assert!((axis.reference_offset().unwrap() - -113.4).abs() < 1e-9);
    }
    // The encoder moved (by hand) to 130: the same reference reads 16.6.
    step(&mut axis, k, 130.0, &Request::default());
    assert!((axis.axis_position().unwrap() - 16.6).abs() < 1e-9);
}

#[test]
fn restore_refusals() {
    use RestoreRefusal::*;
    // No feedback yet.
    let mut axis = Axis::new(absolute_axis());
    assert_eq!(axis.restore_reference(0, -113.4, 0.0), Err(NoFeedback));
    // Feedback, then a missing frame: not fresh.
    step(&mut axis, 0, RAW, &Request::default());
    axis.step(MS, None, &Request::default());
    assert_eq!(axis.restore_reference(MS, -113.4, 0.0), Err(NoFeedback));
    // Fresh again, but the reference would put the axis at 123.4 + 30 =
    // 153.4, beyond the travel limit 150.
    step(&mut axis, 2, RAW, &Request::default());
    assert_eq!(
        axis.restore_reference(2 * MS, 30.0, 0.0),
        Err(OutsideTravelLimits {
            position: RAW + 30.0
        })
    );
    assert!(!axis.status().homed, "refused: nothing applied");
    assert_eq!(
        axis.restore_reference(2 * MS, f64::NAN, 0.0),
        Err(InvalidOffset)
    );
    // A sample seen long ago is not fresh, even without a later step.
    assert_eq!(
        axis.restore_reference(100 * MS, -113.4, 0.0),
        Err(NoFeedback)
    );
    // Drive fault.
    let faulted = Feedback {
        drive: DriveState {
            enabled: false,
            fault: true,
        },
        ..at(RAW)
    };
    axis.step(3 * MS, Some(&faulted), &Request::default());
    assert_eq!(axis.restore_reference(3 * MS, -113.4, 0.0), Err(DriveFault));
    // Not an absolute device.
    let mut inc = Axis::new(AxisConfig {
        absolute: false,
        home_mode: HomeMode::Active,
        ..absolute_axis()
    });
    inc.step(0, Some(&at(RAW)), &Request::default());
    assert_eq!(inc.restore_reference(0, -113.4, 0.0), Err(NotAbsolute));
    // Homing in process (an absolute axis homed by a switch sequence).
    let mut active = Axis::new(AxisConfig {
        home_mode: HomeMode::Active,
        home_sequence: HomeSequence::Switch,
        home_speed: 10.0,
        home_return_speed: 1.0,
        home_acceleration: 100.0,
        home_deceleration: 100.0,
        home_position: 0.0,
        ..absolute_axis()
    });
    active.step(0, Some(&at(RAW)), &home());
    assert!(active.status().ip);
    assert_eq!(
        active.restore_reference(0, -113.4, 0.0),
        Err(HomingInProcess)
    );
    // Refusals read as sentences.
    assert_eq!(
        OutsideTravelLimits { position: 153.4 }.to_string(),
        "the stored reference puts the axis at 153.4, outside its travel limits"
    );
    assert_eq!(NoFeedback.to_string(), "no fresh valid feedback");
}
