//! One axis, one bus cycle: the command frame's axis entry and the drive's
//! process data in, the drive's outputs and the feedback frame's axis entry
//! out. Pure (no I/O, no clock, no allocation), so every rule is unit-tested
//! here; the bus thread only moves bytes.
//!
//! Rules:
//!
//! * **Enable** (`CW_ENABLE`) walks the drive to Operation enabled through
//!   [`Cia402`]; a rising edge of the request also asks for a fault reset
//!   (the frames' handshake: a fault stays reported, also while disabled,
//!   until enable goes false → true).
//! * **Set-points**: while the drive is not in Operation enabled the target
//!   follows the actual position (no jump on enabling); in Operation enabled
//!   it is the command's `target_position`. Positions are 64-bit in the
//!   frames and 32-bit on the wire: the actual position is extended with
//!   every cycle's difference (so it never wraps), targets are sent modulo
//!   2³² and must lie within ±2³⁰ counts of the actual position. A target
//!   outside that, the invalid-position sentinel or a NaN torque limit is
//!   refused: the last good target stays, the axis quick-stops on the
//!   drive's ramp, is disabled and reports a fault until the enable handshake
//!   (a real drive faults on a bad set-point).
//! * **Torque limits** (% rated, f32) → per mille (u16), clamped to
//!   0..=65535.
//! * **Position error tolerance** (counts, 0 = off) → the following error
//!   window 0x6065 wanted (u32::MAX = off); the bus thread writes it over SDO
//!   when it changes. The velocity error tolerance has no CiA 402 object in
//!   CSP and is not applied.
//! * **Watchdog stop**: an enabled axis gets a quick stop (the drive's own
//!   ramp, 0x6085); at rest (|v| below one count per cycle, or the drive has
//!   left Quick stop active by itself) it is disabled and reports a
//!   communication fault. **Emergency stop**: "disable voltage" at once and a
//!   fault. Both faults clear with the enable handshake.
//! * **No data this cycle**: the outputs stay what they were (the state
//!   machines are not stepped blind) and the feedback is the last good one
//!   with `SW_NO_DATA`.

use motion_frames::{
    AxisCommand, AxisFeedback, CW_ENABLE, DI_HOME_SWITCH, DI_MARKER_PULSE, DI_OVERTRAVEL_NEGATIVE,
    DI_OVERTRAVEL_POSITIVE, EDGE_RISING, INVALID_COUNTS, SW_ENABLED, SW_FAULT, SW_NO_DATA,
};

use crate::cia402::{Cia402, State, Target};
use crate::pdo::{di, DriveInputs, DriveOutputs, PdoLayout, MODE_CSP};
use crate::probe::{Edge, ProbeInputs, TouchProbes};

/// Largest distance between target and actual position, counts.
pub const MAX_TARGET_DISTANCE: i64 = 1 << 30;

/// What the caller wants from all axes this cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Follow the command frame.
    Normal,
    /// Commands stopped: controlled stop, then disable with a fault.
    WatchdogStop,
    /// Power off now, fault.
    Emergency,
}

/// Per-axis counters of refused set-points.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AxisCounters {
    pub rejected_setpoints: u64,
    pub fault_resets: u64,
}

/// The logic of one axis.
#[derive(Clone, Debug)]
pub struct AxisLogic {
    layout: PdoLayout,
    cia: Cia402,
    probes: TouchProbes,
    /// `CW_ENABLE` of the previous command (edge detection).
    last_enable: bool,
    /// The backend's own fault (watchdog / emergency stop, refused
    /// set-point), cleared by the enable handshake.
    fault_latch: bool,
    pos64: Option<i64>,
    pos32: i32,
    state: State,
    outputs: DriveOutputs,
    last_feedback: AxisFeedback,
    kept_error: u16,
    /// Digital-input bit that carries the index pulse (manufacturer range).
    index_pulse_bit: Option<u8>,
    /// 0x6065 the command asks for.
    window: u32,
    /// Counts/s below which an axis counts as at rest (one count per cycle).
    rest_velocity: f64,
    pub counters: AxisCounters,
}

impl AxisLogic {
    pub fn new(layout: PdoLayout, cycle_s: f64, index_pulse_bit: Option<u8>) -> AxisLogic {
        AxisLogic {
            layout,
            cia: Cia402::new(),
            probes: TouchProbes::new(),
            last_enable: false,
            fault_latch: false,
            pos64: None,
            pos32: 0,
            state: State::NotReadyToSwitchOn,
            outputs: DriveOutputs {
                mode: MODE_CSP,
                ..DriveOutputs::default()
            },
            last_feedback: AxisFeedback::ZERO,
            kept_error: 0,
            index_pulse_bit,
            window: u32::MAX,
            rest_velocity: if cycle_s > 0.0 { 1.0 / cycle_s } else { 1000.0 },
            counters: AxisCounters::default(),
        }
    }

    pub fn layout(&self) -> &PdoLayout {
        &self.layout
    }

    /// The drive state decoded last.
    pub fn state(&self) -> State {
        self.state
    }

    /// 0x6065 the command asks for (u32::MAX = off).
    pub fn following_error_window(&self) -> u32 {
        self.window
    }

    /// The outputs of the last cycle.
    pub fn outputs(&self) -> DriveOutputs {
        self.outputs
    }

    /// The last good feedback (no `SW_NO_DATA`).
    pub fn last_feedback(&self) -> AxisFeedback {
        self.last_feedback
    }

    /// A controlled stop asked for by [`Mode::WatchdogStop`] is complete:
    /// the drive is not enabled.
    pub fn at_rest_and_disabled(&self) -> bool {
        !self.state.is_enabled() && self.state != State::QuickStopActive
    }

    /// One cycle. `inputs`: this cycle's process data, `None` if it did not
    /// arrive (or is not valid). Runs on the bus thread: no allocation.
    pub fn step(
        &mut self,
        cmd: &AxisCommand,
        mode: Mode,
        inputs: Option<&DriveInputs>,
    ) -> (DriveOutputs, AxisFeedback) {
        let enable = cmd.control_word & CW_ENABLE != 0;
        if mode == Mode::Normal {
            if enable && !self.last_enable {
                self.fault_latch = false;
                self.cia.request_fault_reset();
                self.counters.fault_resets += 1;
            }
            self.last_enable = enable;
        }
        let Some(inp) = inputs else {
            let mut fb = self.last_feedback;
            fb.status_word |= SW_NO_DATA;
            return (self.outputs, fb);
        };
        let pos64 = self.extend(inp.position);
        self.state = State::from_statusword(inp.statusword);
        let set = self.check_setpoint(cmd, mode, enable, pos64);
        self.window = following_error_window(cmd.position_error_tolerance);
        let target = self.cia_target(mode, enable, inp.velocity);
        let controlword = self.cia.step(inp.statusword, target);

        let following = self.state.is_enabled() && target == Target::Enabled;
        let target_position = if following && set.target_ok {
            cmd.target_position as i32 // modulo 2^32, consistent with the extension
        } else if following {
            self.outputs.target_position // refused: hold the last good one
        } else {
            inp.position
        };
        let function = self.probe_function(cmd, inp, pos64);
        self.outputs = DriveOutputs {
            controlword,
            target_position,
            touch_probe_function: function,
            torque_limit_positive: set.tpos.unwrap_or(self.outputs.torque_limit_positive),
            torque_limit_negative: set.tneg.unwrap_or(self.outputs.torque_limit_negative),
            mode: MODE_CSP,
        };
        let fb = self.feedback(inp, pos64);
        self.last_feedback = fb;
        (self.outputs, fb)
    }

    /// The drive's 32-bit position extended to 64 bits by every cycle's
    /// difference (it never wraps).
    fn extend(&mut self, position32: i32) -> i64 {
        let pos64 = match self.pos64 {
            None => i64::from(position32),
            Some(p) => p.wrapping_add(i64::from(position32.wrapping_sub(self.pos32))),
        };
        self.pos64 = Some(pos64);
        self.pos32 = position32;
        pos64
    }

    /// Checks the command's set-points against the actual position
    /// `pos64`; a bad one while enabled latches the backend's fault.
    fn check_setpoint(
        &mut self,
        cmd: &AxisCommand,
        mode: Mode,
        enable: bool,
        pos64: i64,
    ) -> Setpoint {
        let target = cmd.target_position;
        let set = Setpoint {
            target_ok: target != INVALID_COUNTS
                && target
                    .checked_sub(pos64)
                    .is_some_and(|d| d.abs() <= MAX_TARGET_DISTANCE),
            tpos: per_mille(cmd.torque_limit_positive),
            tneg: per_mille(cmd.torque_limit_negative),
        };
        let bad = !set.target_ok || set.tpos.is_none() || set.tneg.is_none();
        if mode == Mode::Normal && enable && self.state.is_enabled() && bad {
            self.fault_latch = true;
            self.counters.rejected_setpoints += 1;
        }
        set
    }

    /// Where the CiA 402 machine walks the drive this cycle (`velocity`:
    /// the drive's, counts/s).
    fn cia_target(&mut self, mode: Mode, enable: bool, velocity: i32) -> Target {
        let moving_in_qs =
            self.state == State::QuickStopActive && f64::from(velocity).abs() >= self.rest_velocity;
        match mode {
            Mode::Normal if enable && !self.fault_latch => Target::Enabled,
            // a refused set-point while enabled: stop on the drive's ramp
            // first, then disable
            Mode::Normal if self.fault_latch && (self.state.is_enabled() || moving_in_qs) => {
                Target::QuickStop
            }
            Mode::Normal => Target::Disabled,
            Mode::WatchdogStop => {
                if self.state.is_enabled() || moving_in_qs {
                    Target::QuickStop
                } else {
                    if self.last_enable {
                        self.fault_latch = true;
                    }
                    Target::Disabled
                }
            }
            Mode::Emergency => {
                if self.last_enable || self.state.is_enabled() {
                    self.fault_latch = true;
                }
                Target::Off
            }
        }
    }

    /// The touch probe function (0x60B8) for the command's arm ids.
    fn probe_function(&mut self, cmd: &AxisCommand, inp: &DriveInputs, pos64: i64) -> u16 {
        let probe_inputs = ProbeInputs {
            status: inp.touch_probe_status,
            probe1_positive: inp.probe1_positive,
            probe1_negative: inp.probe1_negative,
            probe2_positive: inp.probe2_positive,
            probe2_negative: inp.probe2_negative,
            position32: inp.position,
            position64: pos64,
        };
        let edge = if cmd.switch_arm_edge == EDGE_RISING {
            Edge::Rising
        } else {
            Edge::Falling
        };
        self.probes
            .step(cmd.marker_arm_id, cmd.switch_arm_id, edge, &probe_inputs)
    }

    /// The frame's digital inputs from 0x60FD.
    fn digital_inputs(&self, raw: u32) -> u32 {
        let mut dio = 0;
        if raw & di::HOME_SWITCH != 0 {
            dio |= DI_HOME_SWITCH;
        }
        if raw & di::POSITIVE_LIMIT_SWITCH != 0 {
            dio |= DI_OVERTRAVEL_POSITIVE;
        }
        if raw & di::NEGATIVE_LIMIT_SWITCH != 0 {
            dio |= DI_OVERTRAVEL_NEGATIVE;
        }
        if let Some(bit) = self.index_pulse_bit {
            if raw & (1u32 << (bit & 31)) != 0 {
                dio |= DI_MARKER_PULSE;
            }
        }
        dio
    }

    /// This cycle's feedback: the drive's values, its state and fault (or
    /// the backend's), the latches.
    fn feedback(&mut self, inp: &DriveInputs, pos64: i64) -> AxisFeedback {
        let drive_fault = self.state.is_fault();
        let mut status = 0;
        if self.state.is_enabled() {
            status |= SW_ENABLED;
        }
        if drive_fault || self.fault_latch {
            status |= SW_FAULT;
        }
        if drive_fault && inp.error_code != 0 {
            self.kept_error = inp.error_code;
        } else if !drive_fault && !self.fault_latch {
            self.kept_error = 0;
        }
        let m = self.probes.marker();
        let s = self.probes.switch();
        AxisFeedback {
            position: pos64,
            velocity: f64::from(inp.velocity),
            torque: f32::from(inp.torque) / 10.0,
            digital_inputs: self.digital_inputs(inp.digital_inputs),
            status_word: status,
            marker_latch_id: m.id,
            marker_latched: u8::from(m.latched),
            switch_latch_id: s.id,
            switch_latched: u8::from(s.latched),
            error_code: if status & SW_FAULT != 0 {
                self.kept_error
            } else {
                0
            },
            marker_latch_position: m.position,
            switch_latch_position: s.position,
        }
    }
}

/// The command's set-points as checked: the target within reach, the
/// torque limits in per mille (`None`: NaN, refused).
struct Setpoint {
    target_ok: bool,
    tpos: Option<u16>,
    tneg: Option<u16>,
}

/// % rated → per mille, clamped to 0..=65535; `None` for NaN.
fn per_mille(pct: f32) -> Option<u16> {
    if pct.is_nan() {
        None
    } else {
        Some((f64::from(pct) * 10.0).round().clamp(0.0, 65535.0) as u16)
    }
}

/// 0x6065 for a position error tolerance in counts (0, NaN: off = u32::MAX).
fn following_error_window(tol: f64) -> u32 {
    if tol.is_finite() && tol > 0.0 {
        tol.round().min(f64::from(u32::MAX - 1)).max(1.0) as u32
    } else {
        u32::MAX
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pdo::TorqueLimits;

    fn logic() -> AxisLogic {
        AxisLogic::new(
            PdoLayout::new(TorqueLimits::PerDirection, false),
            0.001,
            Some(16),
        )
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
        let (o, fb) = a.step(
            &cmd(true, 500),
            Mode::Normal,
            Some(&inputs(State::SwitchOnDisabled, 123)),
        );
        assert_eq!(o.controlword, 0x0006);
        assert_eq!(o.target_position, 123, "not enabled: follows actual");
        assert_eq!(o.torque_limit_positive, 1000);
        assert_eq!(o.torque_limit_negative, 500);
        assert_eq!(o.mode, 8);
        assert_eq!(fb.status_word, 0);
        assert_eq!(fb.position, 123);
        let (o, _) = a.step(
            &cmd(true, 500),
            Mode::Normal,
            Some(&inputs(State::ReadyToSwitchOn, 123)),
        );
        assert_eq!(o.controlword, 0x0007);
        let (o, _) = a.step(
            &cmd(true, 500),
            Mode::Normal,
            Some(&inputs(State::SwitchedOn, 123)),
        );
        assert_eq!(o.controlword, 0x000F);
        assert_eq!(o.target_position, 123);
        let (o, fb) = a.step(
            &cmd(true, 500),
            Mode::Normal,
            Some(&inputs(State::OperationEnabled, 124)),
        );
        assert_eq!(o.target_position, 500);
        assert_eq!(fb.status_word, SW_ENABLED);
        // disable
        let (o, fb) = a.step(
            &cmd(false, 500),
            Mode::Normal,
            Some(&inputs(State::OperationEnabled, 500)),
        );
        assert_eq!(o.controlword, 0x0006);
        assert_eq!(o.target_position, 500);
        assert_eq!(fb.status_word, SW_ENABLED, "reports the drive's state");
    }

    #[test]
    fn positions_extend_over_the_32_bit_wrap() {
        let mut a = logic();
        let mut p = i32::MAX - 5;
        let (_, fb) = a.step(
            &cmd(false, 0),
            Mode::Normal,
            Some(&inputs(State::SwitchOnDisabled, p)),
        );
        assert_eq!(fb.position, i64::from(i32::MAX) - 5);
        for _ in 0..10 {
            p = p.wrapping_add(3);
            a.step(
                &cmd(false, 0),
                Mode::Normal,
                Some(&inputs(State::SwitchOnDisabled, p)),
            );
        }
        assert_eq!(a.last_feedback().position, i64::from(i32::MAX) + 25);
        // a target beyond 2^31 goes out modulo 2^32
        let t = i64::from(i32::MAX) + 30;
        for s in [State::OperationEnabled, State::OperationEnabled] {
            let (o, _) = a.step(&cmd(true, t), Mode::Normal, Some(&inputs(s, p)));
            assert_eq!(o.target_position, t as i32);
        }
    }

    #[test]
    fn bad_setpoints_are_refused_with_a_fault_until_the_handshake() {
        let mut a = logic();
        a.step(
            &cmd(true, 0),
            Mode::Normal,
            Some(&inputs(State::OperationEnabled, 0)),
        );
        let (o, _) = a.step(
            &cmd(true, 10),
            Mode::Normal,
            Some(&inputs(State::OperationEnabled, 0)),
        );
        assert_eq!(o.target_position, 10);
        let (o, fb) = a.step(
            &cmd(true, INVALID_COUNTS),
            Mode::Normal,
            Some(&inputs(State::OperationEnabled, 10)),
        );
        assert_eq!(o.target_position, 10, "last good target held");
        assert_eq!(o.controlword, 0x0002, "quick stop on the drive's ramp");
        assert_eq!(fb.status_word & SW_FAULT, SW_FAULT);
        assert_eq!(a.counters.rejected_setpoints, 1);
        // too far away
        let mut b = logic();
        b.step(
            &cmd(true, 0),
            Mode::Normal,
            Some(&inputs(State::OperationEnabled, 0)),
        );
        b.step(
            &cmd(true, MAX_TARGET_DISTANCE + 1),
            Mode::Normal,
            Some(&inputs(State::OperationEnabled, 0)),
        );
        assert_eq!(b.counters.rejected_setpoints, 1);
        // NaN torque limit
        let mut c = logic();
        let mut n = cmd(true, 0);
        n.torque_limit_positive = f32::NAN;
        c.step(
            &cmd(true, 0),
            Mode::Normal,
            Some(&inputs(State::OperationEnabled, 0)),
        );
        c.step(&n, Mode::Normal, Some(&inputs(State::OperationEnabled, 0)));
        assert_eq!(c.counters.rejected_setpoints, 1);
        // fault stays while enable stays; drive now disabled
        let (o, fb) = a.step(
            &cmd(true, 10),
            Mode::Normal,
            Some(&inputs(State::ReadyToSwitchOn, 10)),
        );
        assert_eq!(o.controlword, 0x0006);
        assert_eq!(fb.status_word, SW_FAULT);
        // handshake
        a.step(
            &cmd(false, 10),
            Mode::Normal,
            Some(&inputs(State::ReadyToSwitchOn, 10)),
        );
        let (o, fb) = a.step(
            &cmd(true, 10),
            Mode::Normal,
            Some(&inputs(State::ReadyToSwitchOn, 10)),
        );
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
        let (_, fb) = a.step(
            &cmd(true, 0),
            Mode::Normal,
            Some(&inputs(State::SwitchOnDisabled, 0)),
        );
        assert_eq!((fb.status_word, fb.error_code), (0, 0));
    }

    #[test]
    fn watchdog_stop_quick_stops_then_disables_with_a_fault() {
        let mut a = logic();
        a.step(
            &cmd(true, 0),
            Mode::Normal,
            Some(&inputs(State::OperationEnabled, 0)),
        );
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
        let (o, fb) = a.step(&cmd(true, 0), Mode::WatchdogStop, Some(&qs));
        assert_eq!(o.controlword, 0x0000, "quick stop active → disable voltage");
        assert_eq!(fb.status_word & SW_FAULT, SW_FAULT);
        let (_, fb) = a.step(
            &cmd(true, 0),
            Mode::WatchdogStop,
            Some(&inputs(State::SwitchOnDisabled, 210)),
        );
        assert!(a.at_rest_and_disabled());
        assert_eq!(fb.status_word, SW_FAULT);
        // commands again: enable still true → no edge → fault stays
        let (o, fb) = a.step(
            &cmd(true, 210),
            Mode::Normal,
            Some(&inputs(State::SwitchOnDisabled, 210)),
        );
        assert_eq!(o.controlword, 0x0006);
        assert_eq!(fb.status_word, SW_FAULT);
        a.step(
            &cmd(false, 210),
            Mode::Normal,
            Some(&inputs(State::SwitchOnDisabled, 210)),
        );
        let (_, fb) = a.step(
            &cmd(true, 210),
            Mode::Normal,
            Some(&inputs(State::SwitchOnDisabled, 210)),
        );
        assert_eq!(fb.status_word, 0);

        // an axis that never asked to be enabled: no fault
        let mut b = logic();
        let (_, fb) = b.step(
            &cmd(false, 0),
            Mode::WatchdogStop,
            Some(&inputs(State::SwitchOnDisabled, 0)),
        );
        assert_eq!(fb.status_word, 0);
        assert!(b.at_rest_and_disabled());
    }

    #[test]
    fn emergency_is_disable_voltage_and_a_fault() {
        let mut a = logic();
        a.step(
            &cmd(true, 0),
            Mode::Normal,
            Some(&inputs(State::OperationEnabled, 0)),
        );
        let (o, fb) = a.step(
            &cmd(true, 0),
            Mode::Emergency,
            Some(&inputs(State::OperationEnabled, 0)),
        );
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
        let (o2, fb2) = a.step(&cmd(true, 99), Mode::Normal, None);
        assert_eq!(o2, o1);
        assert_eq!(fb2.status_word, fb1.status_word | SW_NO_DATA);
        assert_eq!(fb2.position, 42);
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
}
