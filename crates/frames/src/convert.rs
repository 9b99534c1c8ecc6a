//! Conversion between the engine's per-axis types (position units, `f64`) and
//! the wire types (drive counts).
//!
//! All functions are pure, allocation-free and never panic, whatever the input.
//!
//! # Rules
//!
//! * **units → counts** (`i64` fields: positions, latch positions):
//!   `round(value · counts_per_unit)` to nearest (half away from zero), saturated
//!   to `[i64::MIN + 1, i64::MAX]` (±∞ saturate too).
//! * **Non-finite values never become a plausible count.** A NaN (or an
//!   unusable `counts_per_unit`: NaN, ±∞, ≤ 0) is encoded as the sentinel
//!   [`INVALID_COUNTS`] = `i64::MIN`, a value that saturation never produces.
//!   Decoding turns the sentinel back into NaN, so the receiver's own finiteness
//!   checks see exactly what the sender had. The engine guarantees finite
//!   commands and the sim produces finite feedback, so in normal operation the
//!   sentinel never appears; this rule only makes a bug loud instead of moving
//!   an axis to count 0.
//! * **`f64` count rates / tolerances** (velocities, error tolerances) are
//!   scaled (`value · counts_per_unit`), not rounded; NaN stays NaN, and an
//!   unusable `counts_per_unit` yields NaN.
//! * **Torques** (% rated, no scaling) narrow `f64 → f32` (out of range → ±∞,
//!   NaN stays NaN) and widen back exactly.
//! * **counts → units** is exact division (`counts as f64 / counts_per_unit`;
//!   exact for |counts| < 2⁵³).
//! * The marker latch has no edge selection on the wire: [`axis_to_command`]
//!   returns `Edge::Rising` (the default) for `marker_arm.edge`.
//! * `switch_arm_edge`: 0 = rising, any other value = falling.
//! * Latched flags: 0 = false, any other value = true.

use motion_homing::{Command, DriveHoming, DriveState, Edge, Feedback, LatchArm, LatchFeedback};

use crate::frame::{
    AxisCommand, AxisFeedback, CW_DRIVE_HOME, CW_ENABLE, CW_FAULT_RESET, DI_HOME_SWITCH,
    DI_MARKER_PULSE, DI_OVERTRAVEL_NEGATIVE, DI_OVERTRAVEL_POSITIVE, EDGE_FALLING, EDGE_RISING,
    SW_DRIVE_HOMED, SW_DRIVE_HOMING, SW_DRIVE_HOMING_ERROR, SW_ENABLED, SW_FAULT,
};

/// Wire value of a position that was not a number (see the module docs).
pub const INVALID_COUNTS: i64 = i64::MIN;

fn cpu_usable(counts_per_unit: f64) -> bool {
    counts_per_unit.is_finite() && counts_per_unit > 0.0
}

/// Position units → counts: round to nearest, saturate, NaN → [`INVALID_COUNTS`].
pub fn units_to_counts(units: f64, counts_per_unit: f64) -> i64 {
    if !cpu_usable(counts_per_unit) {
        return INVALID_COUNTS;
    }
    let v = (units * counts_per_unit).round();
    if v.is_nan() {
        INVALID_COUNTS
    } else if v <= i64::MIN as f64 {
        // -2^63 and below (incl. -inf) saturate one above the sentinel.
        i64::MIN + 1
    } else {
        // `as` saturates at i64::MAX (incl. +inf).
        v as i64
    }
}

/// Counts → position units: exact division; [`INVALID_COUNTS`] → NaN.
pub fn counts_to_units(counts: i64, counts_per_unit: f64) -> f64 {
    if counts == INVALID_COUNTS || !cpu_usable(counts_per_unit) {
        return f64::NAN;
    }
    counts as f64 / counts_per_unit
}

/// units/s (or a tolerance in units) → counts/s, not rounded.
fn rate_to_counts(units: f64, counts_per_unit: f64) -> f64 {
    if cpu_usable(counts_per_unit) {
        // A finite rate that overflows in counts saturates, as positions do
        // in `units_to_counts`: a reading stays a (huge) number, never ±∞.
        // NaN stays NaN (`clamp` keeps it): the receiver refuses it.
        (units * counts_per_unit).clamp(-f64::MAX, f64::MAX)
    } else {
        f64::NAN
    }
}

fn counts_to_rate(counts: f64, counts_per_unit: f64) -> f64 {
    if cpu_usable(counts_per_unit) {
        counts / counts_per_unit
    } else {
        f64::NAN
    }
}

fn edge_to_wire(edge: Edge) -> u8 {
    match edge {
        Edge::Rising => EDGE_RISING,
        Edge::Falling => EDGE_FALLING,
    }
}

fn edge_from_wire(edge: u8) -> Edge {
    if edge == EDGE_RISING {
        Edge::Rising
    } else {
        Edge::Falling
    }
}

/// The control word's bits: [`CW_ENABLE`], [`CW_FAULT_RESET`].
fn control_word(cmd: &Command) -> u16 {
    let mut cw = 0;
    if cmd.enable {
        cw |= CW_ENABLE;
    }
    if cmd.fault_reset {
        cw |= CW_FAULT_RESET;
    }
    if cmd.drive_home {
        cw |= CW_DRIVE_HOME;
    }
    cw
}

/// Engine command (units) → wire command (counts).
pub fn command_to_axis(cmd: &Command, counts_per_unit: f64) -> AxisCommand {
    AxisCommand {
        target_position: units_to_counts(cmd.position, counts_per_unit),
        target_velocity: rate_to_counts(cmd.velocity, counts_per_unit),
        torque_limit_positive: cmd.torque_limit_positive as f32,
        torque_limit_negative: cmd.torque_limit_negative as f32,
        position_error_tolerance: rate_to_counts(cmd.position_error_tolerance, counts_per_unit),
        velocity_error_tolerance: rate_to_counts(cmd.velocity_error_tolerance, counts_per_unit),
        control_word: control_word(cmd),
        marker_arm_id: cmd.marker_arm.id,
        switch_arm_id: cmd.switch_arm.id,
        switch_arm_edge: edge_to_wire(cmd.switch_arm.edge),
        reserved: [0; 3],
    }
}

/// Wire command (counts) → engine command (units). Used by motion-io.
pub fn axis_to_command(ac: &AxisCommand, counts_per_unit: f64) -> Command {
    Command {
        enable: ac.control_word & CW_ENABLE != 0,
        position: counts_to_units(ac.target_position, counts_per_unit),
        velocity: counts_to_rate(ac.target_velocity, counts_per_unit),
        torque_limit_positive: f64::from(ac.torque_limit_positive),
        torque_limit_negative: f64::from(ac.torque_limit_negative),
        position_error_tolerance: counts_to_rate(ac.position_error_tolerance, counts_per_unit),
        velocity_error_tolerance: counts_to_rate(ac.velocity_error_tolerance, counts_per_unit),
        marker_arm: LatchArm {
            id: ac.marker_arm_id,
            edge: Edge::Rising,
        },
        switch_arm: LatchArm {
            id: ac.switch_arm_id,
            edge: edge_from_wire(ac.switch_arm_edge),
        },
        fault_reset: ac.control_word & CW_FAULT_RESET != 0,
        drive_home: ac.control_word & CW_DRIVE_HOME != 0,
    }
}

/// Engine-side feedback (units) → wire feedback (counts). Used by motion-io.
pub fn feedback_to_axis(fb: &Feedback, counts_per_unit: f64) -> AxisFeedback {
    let mut di = 0;
    if fb.home_switch {
        di |= DI_HOME_SWITCH;
    }
    if fb.overtravel_positive {
        di |= DI_OVERTRAVEL_POSITIVE;
    }
    if fb.overtravel_negative {
        di |= DI_OVERTRAVEL_NEGATIVE;
    }
    if fb.marker_pulse {
        di |= DI_MARKER_PULSE;
    }
    let mut sw = 0;
    if fb.drive.enabled {
        sw |= SW_ENABLED;
    }
    if fb.drive.fault {
        sw |= SW_FAULT;
    }
    for (on, bit) in [
        (fb.drive_homing.active, SW_DRIVE_HOMING),
        (fb.drive_homing.attained, SW_DRIVE_HOMED),
        (fb.drive_homing.error, SW_DRIVE_HOMING_ERROR),
    ] {
        if on {
            sw |= bit;
        }
    }
    AxisFeedback {
        position: units_to_counts(fb.position, counts_per_unit),
        velocity: rate_to_counts(fb.velocity, counts_per_unit),
        torque: fb.torque as f32,
        digital_inputs: di,
        status_word: sw,
        marker_latch_id: fb.marker_latch.id,
        marker_latched: u8::from(fb.marker_latch.latched),
        switch_latch_id: fb.switch_latch.id,
        switch_latched: u8::from(fb.switch_latch.latched),
        error_code: 0,
        marker_latch_position: units_to_counts(fb.marker_latch.position, counts_per_unit),
        switch_latch_position: units_to_counts(fb.switch_latch.position, counts_per_unit),
    }
}

/// Wire feedback (counts) → engine feedback (units). Used by the supervisor.
pub fn axis_to_feedback(af: &AxisFeedback, counts_per_unit: f64) -> Feedback {
    Feedback {
        position: counts_to_units(af.position, counts_per_unit),
        velocity: counts_to_rate(af.velocity, counts_per_unit),
        torque: f64::from(af.torque),
        home_switch: af.digital_inputs & DI_HOME_SWITCH != 0,
        overtravel_positive: af.digital_inputs & DI_OVERTRAVEL_POSITIVE != 0,
        overtravel_negative: af.digital_inputs & DI_OVERTRAVEL_NEGATIVE != 0,
        marker_pulse: af.digital_inputs & DI_MARKER_PULSE != 0,
        marker_latch: LatchFeedback {
            id: af.marker_latch_id,
            latched: af.marker_latched != 0,
            position: counts_to_units(af.marker_latch_position, counts_per_unit),
        },
        switch_latch: LatchFeedback {
            id: af.switch_latch_id,
            latched: af.switch_latched != 0,
            position: counts_to_units(af.switch_latch_position, counts_per_unit),
        },
        drive: DriveState {
            enabled: af.status_word & SW_ENABLED != 0,
            fault: af.status_word & SW_FAULT != 0,
        },
        drive_homing: DriveHoming {
            active: af.status_word & SW_DRIVE_HOMING != 0,
            attained: af.status_word & SW_DRIVE_HOMED != 0,
            error: af.status_word & SW_DRIVE_HOMING_ERROR != 0,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CPU: f64 = 1000.0;

    fn sample_command() -> Command {
        Command {
            enable: true,
            position: 12.345,
            velocity: -20.5,
            torque_limit_positive: 150.0,
            torque_limit_negative: 80.25,
            position_error_tolerance: 0.5,
            velocity_error_tolerance: 3.0,
            marker_arm: LatchArm {
                id: 7,
                edge: Edge::Rising,
            },
            switch_arm: LatchArm {
                id: 200,
                edge: Edge::Falling,
            },
            fault_reset: true,
            drive_home: true,
        }
    }

    fn sample_feedback() -> Feedback {
        Feedback {
            position: -49.999,
            velocity: 2.0,
            torque: -12.5,
            home_switch: true,
            overtravel_positive: false,
            overtravel_negative: true,
            marker_latch: LatchFeedback {
                id: 3,
                latched: true,
                position: 2.5,
            },
            switch_latch: LatchFeedback {
                id: 9,
                latched: false,
                position: 0.0,
            },
            marker_pulse: true,
            drive: DriveState {
                enabled: true,
                fault: true,
            },
            drive_homing: DriveHoming {
                active: true,
                attained: true,
                error: false,
            },
        }
    }

    #[test]
    fn rounding_to_nearest() {
        assert_eq!(units_to_counts(1.0004, CPU), 1000);
        assert_eq!(units_to_counts(1.0006, CPU), 1001);
        assert_eq!(units_to_counts(-1.0006, CPU), -1001);
        assert_eq!(units_to_counts(0.0005, CPU), 1); // half away from zero
        assert_eq!(units_to_counts(-0.0005, CPU), -1);
        assert_eq!(units_to_counts(0.0, CPU), 0);
    }

    #[test]
    fn saturation_and_non_finite() {
        assert_eq!(units_to_counts(1e300, CPU), i64::MAX);
        assert_eq!(units_to_counts(f64::INFINITY, CPU), i64::MAX);
        assert_eq!(units_to_counts(-1e300, CPU), i64::MIN + 1);
        assert_eq!(units_to_counts(f64::NEG_INFINITY, CPU), i64::MIN + 1);
        assert_eq!(units_to_counts(f64::NAN, CPU), INVALID_COUNTS);
        // an unusable conversion constant never yields a plausible count
        for cpu in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(units_to_counts(1.0, cpu), INVALID_COUNTS);
            assert!(counts_to_units(1000, cpu).is_nan());
        }
        assert!(counts_to_units(INVALID_COUNTS, CPU).is_nan());
        assert_eq!(
            counts_to_units(i64::MIN + 1, CPU),
            (i64::MIN + 1) as f64 / CPU
        );
        // A finite rate that overflows in counts saturates like a position
        // (found by motion-io's command-frame fuzz test: a watchdog stop
        // of a huge time step after a garbage command).
        assert_eq!(rate_to_counts(f64::MAX, CPU), f64::MAX);
        assert_eq!(rate_to_counts(-f64::MAX, CPU), -f64::MAX);
        assert!(rate_to_counts(f64::NAN, CPU).is_nan());
    }

    #[test]
    fn nan_survives_the_round_trip() {
        let mut c = sample_command();
        c.position = f64::NAN;
        c.velocity = f64::NAN;
        let back = axis_to_command(&command_to_axis(&c, CPU), CPU);
        assert!(back.position.is_nan());
        assert!(back.velocity.is_nan());

        let mut f = sample_feedback();
        f.position = f64::NAN;
        f.marker_latch.position = f64::INFINITY;
        let w = feedback_to_axis(&f, CPU);
        assert_eq!(w.position, INVALID_COUNTS);
        assert_eq!(w.marker_latch_position, i64::MAX);
        let back = axis_to_feedback(&w, CPU);
        assert!(back.position.is_nan());
        assert!(back.marker_latch.position > 9e15);
    }

    #[test]
    fn counts_to_units_is_exact_division() {
        assert_eq!(counts_to_units(12345, CPU), 12.345);
        assert_eq!(counts_to_units(-1, 4.0), -0.25);
        assert_eq!(counts_to_units(7, 3.0), 7.0 / 3.0);
    }

    #[test]
    fn command_fields() {
        let w = command_to_axis(&sample_command(), CPU);
        assert_eq!(w.target_position, 12345);
        assert_eq!(w.target_velocity, -20500.0);
        assert_eq!(w.torque_limit_positive, 150.0);
        assert_eq!(w.torque_limit_negative, 80.25);
        assert_eq!(w.position_error_tolerance, 500.0);
        assert_eq!(w.velocity_error_tolerance, 3000.0);
        assert_eq!(w.control_word, CW_ENABLE | CW_FAULT_RESET | CW_DRIVE_HOME);
        assert_eq!(w.marker_arm_id, 7);
        assert_eq!(w.switch_arm_id, 200);
        assert_eq!(w.switch_arm_edge, EDGE_FALLING);
        assert_eq!(w.reserved, [0; 3]);

        let off = command_to_axis(&Command::default(), CPU);
        assert_eq!(off, AxisCommand::ZERO);
    }

    #[test]
    fn command_round_trip() {
        let c = sample_command();
        assert_eq!(axis_to_command(&command_to_axis(&c, CPU), CPU), c);
        let d = Command::default();
        assert_eq!(axis_to_command(&command_to_axis(&d, CPU), CPU), d);
        // the marker edge is not on the wire
        let mut m = c;
        m.marker_arm.edge = Edge::Falling;
        assert_eq!(
            axis_to_command(&command_to_axis(&m, CPU), CPU)
                .marker_arm
                .edge,
            Edge::Rising
        );
    }

    #[test]
    fn command_round_trip_on_count_grid() {
        // any position on the count grid survives exactly
        for counts in [-1_000_000_007i64, -1, 0, 1, 3, 999_999_999_999] {
            let c = Command {
                position: counts as f64 / 3.0,
                ..Command::default()
            };
            let w = command_to_axis(&c, 3.0);
            assert_eq!(w.target_position, counts);
            assert_eq!(axis_to_command(&w, 3.0).position, counts as f64 / 3.0);
        }
    }

    #[test]
    fn feedback_fields() {
        let w = feedback_to_axis(&sample_feedback(), CPU);
        assert_eq!(w.position, -49999);
        assert_eq!(w.velocity, 2000.0);
        assert_eq!(w.torque, -12.5);
        assert_eq!(
            w.digital_inputs,
            DI_HOME_SWITCH | DI_OVERTRAVEL_NEGATIVE | DI_MARKER_PULSE
        );
        assert_eq!(
            w.status_word,
            SW_ENABLED | SW_FAULT | SW_DRIVE_HOMING | SW_DRIVE_HOMED
        );
        assert_eq!((w.marker_latch_id, w.marker_latched), (3, 1));
        assert_eq!((w.switch_latch_id, w.switch_latched), (9, 0));
        assert_eq!(w.marker_latch_position, 2500);
        assert_eq!(w.switch_latch_position, 0);
        assert_eq!(w.error_code, 0);
    }

    #[test]
    fn feedback_round_trip() {
        let f = sample_feedback();
        assert_eq!(axis_to_feedback(&feedback_to_axis(&f, CPU), CPU), f);
        let d = Feedback::default();
        assert_eq!(axis_to_feedback(&feedback_to_axis(&d, CPU), CPU), d);
        // all input/status bit combinations
        for bits in 0u8..32 {
            let g = Feedback {
                home_switch: bits & 1 != 0,
                overtravel_positive: bits & 2 != 0,
                overtravel_negative: bits & 4 != 0,
                drive: DriveState {
                    enabled: bits & 8 != 0,
                    fault: bits & 16 != 0,
                },
                ..Feedback::default()
            };
            assert_eq!(axis_to_feedback(&feedback_to_axis(&g, CPU), CPU), g);
        }
    }

    #[test]
    fn wire_round_trip() {
        let w = AxisFeedback {
            position: -123_456_789,
            velocity: 42.0,
            torque: 3.5,
            digital_inputs: DI_OVERTRAVEL_POSITIVE,
            status_word: SW_ENABLED,
            marker_latch_id: 1,
            marker_latched: 1,
            switch_latch_id: 2,
            switch_latched: 1,
            error_code: 0,
            marker_latch_position: 77,
            switch_latch_position: -77,
        };
        assert_eq!(feedback_to_axis(&axis_to_feedback(&w, 1.0), 1.0), w);
        assert_eq!(feedback_to_axis(&axis_to_feedback(&w, 4096.0), 4096.0), w);

        let c = AxisCommand {
            target_position: 987_654_321,
            target_velocity: -1.0,
            torque_limit_positive: 100.0,
            torque_limit_negative: 100.0,
            position_error_tolerance: 1000.0,
            velocity_error_tolerance: 0.0,
            control_word: CW_ENABLE,
            marker_arm_id: 4,
            switch_arm_id: 5,
            switch_arm_edge: EDGE_RISING,
            reserved: [0; 3],
        };
        assert_eq!(command_to_axis(&axis_to_command(&c, 1000.0), 1000.0), c);
        // The fault reset both ways, alone and with the enable.
        for cw in [0, CW_ENABLE, CW_FAULT_RESET, CW_ENABLE | CW_FAULT_RESET] {
            let c = AxisCommand {
                control_word: cw,
                ..c
            };
            let e = axis_to_command(&c, 1000.0);
            assert_eq!(
                (e.enable, e.fault_reset),
                (cw & CW_ENABLE != 0, cw & CW_FAULT_RESET != 0)
            );
            assert_eq!(command_to_axis(&e, 1000.0), c);
        }
    }

    #[test]
    fn odd_wire_values_do_not_panic() {
        let w = AxisCommand {
            switch_arm_edge: 7,
            control_word: 0xFFFE,
            ..AxisCommand::ZERO
        };
        let c = axis_to_command(&w, CPU);
        assert_eq!(c.switch_arm.edge, Edge::Falling);
        assert!(!c.enable && c.fault_reset, "0xFFFE: bit 1 set, bit 0 clear");
        let f = AxisFeedback {
            marker_latched: 0xFF,
            digital_inputs: u32::MAX,
            status_word: u16::MAX,
            position: i64::MAX,
            ..AxisFeedback::ZERO
        };
        let fb = axis_to_feedback(&f, CPU);
        assert!(fb.marker_latch.latched && fb.home_switch && fb.drive.fault);
        assert!(fb.position.is_finite());
    }
}
