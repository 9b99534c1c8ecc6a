//! Fuzzed: any bytes a peer may put in a feedback or command frame
//! go through the decoding the receiver uses (header check, active axes,
//! `axis_to_feedback` / `axis_to_command`) without a panic, and a value
//! that was not a number never decodes into a plausible one. (What the
//! engine then makes of any decoded value: motion-supervisor's core fuzz
//! test and motion-homing's properties.)

use motion_frames::*;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

fn runner(cases: u32) -> TestRunner {
    TestRunner::new(Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    })
}

/// A frame holding `bytes` (zero beyond them).
///
/// Both frame types are `repr(C)` structs of integers and floats only, as
/// on the wire: every bit pattern is a value, which is what a peer can send.
fn from_bytes<T: Copy>(zero: T, bytes: &[u8]) -> T {
    let mut f = zero;
    let n = bytes.len().min(std::mem::size_of::<T>());
    // SAFETY: `T` is one of the frame types (plain old data, see above); at
    // most `size_of::<T>()` bytes are written into it.
    unsafe {
        std::ptr::copy_nonoverlapping(bytes.as_ptr(), (&mut f as *mut T).cast::<u8>(), n);
    }
    f
}

/// A conversion constant as the config could give (positive, finite), or
/// one it never gives.
fn counts_per_unit() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => 1e-3..1e9f64,
        1 => Just(1.0),
        1 => any::<f64>(),
        1 => Just(0.0),
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
    ]
}

fn bytes(len: usize) -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        // Anything.
        prop::collection::vec(any::<u8>(), 0..=len),
        // Mostly 0x00 / 0xff runs: sentinels, NaNs, extremes.
        prop::collection::vec(prop::sample::select(&[0u8, 0xff, 0x7f, 0x80][..]), 0..=len),
    ]
}

#[test]
fn any_feedback_frame_decodes_without_panic_and_nan_stays_nan() {
    let len = std::mem::size_of::<FeedbackFrame>();
    runner(200)
        .run(&(bytes(len), counts_per_unit()), |(b, cpu)| {
            let f = from_bytes(FeedbackFrame::ZERO, &b);
            let checked = f.header.check();
            if checked.is_ok() {
                prop_assert!(f.header.axis_count as usize <= MAX_AXES);
            }
            let _ = checked.map_err(|e| e.to_string());
            prop_assert_eq!(
                f.active_axes().len(),
                (f.header.axis_count as usize).min(MAX_AXES)
            );
            let usable = cpu.is_finite() && cpu > 0.0;
            // Every slot, not only the active ones: a forger picks the count.
            for a in &f.axes {
                let d = axis_to_feedback(a, cpu);
                for (wire, x) in [
                    (a.position, d.position),
                    (a.marker_latch_position, d.marker_latch.position),
                    (a.switch_latch_position, d.switch_latch.position),
                ] {
                    if wire == INVALID_COUNTS || !usable {
                        prop_assert!(x.is_nan(), "{wire} → {x}");
                    } else {
                        prop_assert_eq!(x, wire as f64 / cpu);
                    }
                }
                if a.velocity.is_nan() || !usable {
                    prop_assert!(d.velocity.is_nan());
                }
                prop_assert_eq!(d.torque.to_bits(), f64::from(a.torque).to_bits());
                prop_assert_eq!(d.drive.enabled, a.status_word & SW_ENABLED != 0);
                prop_assert_eq!(d.drive.fault, a.status_word & SW_FAULT != 0);
                prop_assert_eq!(d.home_switch, a.digital_inputs & DI_HOME_SWITCH != 0);
            }
            Ok(())
        })
        .unwrap();
}

#[test]
fn any_command_frame_decodes_without_panic_and_nan_stays_nan() {
    let len = std::mem::size_of::<CommandFrame>();
    runner(200)
        .run(&(bytes(len), counts_per_unit()), |(b, cpu)| {
            let f = from_bytes(CommandFrame::ZERO, &b);
            let _ = f.header.check().map_err(|e| e.to_string());
            prop_assert_eq!(
                f.active_axes().len(),
                (f.header.axis_count as usize).min(MAX_AXES)
            );
            let usable = cpu.is_finite() && cpu > 0.0;
            for a in &f.axes {
                let c = axis_to_command(a, cpu);
                prop_assert_eq!(c.enable, a.control_word & CW_ENABLE != 0);
                if a.target_position == INVALID_COUNTS || !usable {
                    prop_assert!(c.position.is_nan());
                } else {
                    prop_assert_eq!(c.position, a.target_position as f64 / cpu);
                }
                for (wire, x) in [
                    (a.target_velocity, c.velocity),
                    (a.position_error_tolerance, c.position_error_tolerance),
                    (a.velocity_error_tolerance, c.velocity_error_tolerance),
                ] {
                    if wire.is_nan() || !usable {
                        prop_assert!(x.is_nan());
                    }
                }
                // A round trip back to the wire never invents a position.
                let back = command_to_axis(&c, cpu);
                if c.position.is_nan() {
                    prop_assert_eq!(back.target_position, INVALID_COUNTS);
                }
            }
            Ok(())
        })
        .unwrap();
}
