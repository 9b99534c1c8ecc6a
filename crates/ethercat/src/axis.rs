//! One axis, one bus cycle: the command frame's axis entry and the drive's
//! process data in, the drive's outputs and the feedback frame's axis entry
//! out. Pure (no I/O, no clock, no allocation), so every rule is unit-tested
//! here; the bus thread only moves bytes.
//!
//! Rules:
//!
//! * **Enable** (`CW_ENABLE`) walks the drive to Operation enabled through
//!   [`Cia402`].
//! * **Faults.** A drive fault (CiA 402 Fault) and the backend's own fault
//!   (a bounded stop after the watchdog, a refused set-point, a drive that
//!   was lost) stay reported until a reset: the rising edge of
//!   `CW_FAULT_RESET` (MAFR; CiA 402 controlword bit 7 on the drive). The
//!   rising edge of `CW_ENABLE` does the same — the frames' older handshake,
//!   kept because the `Backend` contract promises it; an engine that
//!   refuses to enable a faulted axis (ERR 20) never raises it on one, so
//!   it never clears a fault behind the operator's back. Nothing is ever
//!   enabled by a reset.
//! * **Set-points**: while the drive is not in Operation enabled the target
//!   follows the actual position (no jump on enabling); in Operation enabled
//!   it is the command's `target_position`. Positions are 64-bit in the
//!   frames and 32-bit on the wire: the actual position is extended with
//!   every cycle's difference (so it never wraps), targets are sent modulo
//!   2³² and must lie within ±2³⁰ counts of the actual position. A target
//!   outside that, the invalid-position sentinel or a NaN torque limit is
//!   refused: the last good target stays, the axis stops (the bounded stop
//!   below), is disabled and reports a fault until a reset.
//! * **Torque limits** (% rated, f32) → per mille (u16), clamped to
//!   0..=65535, where the layout carries a limit.
//! * **Position error tolerance** (counts, 0 = off) → the following error
//!   window 0x6065 wanted (u32::MAX = off); the bus thread writes it over SDO
//!   when it changes.
//! * **Watchdog stop** ([`Mode::WatchdogStop`]) and a refused set-point: the
//!   bounded stop of [`crate::stop`] — quick stop, then disable voltage at
//!   rest, after `quick_stop_timeout_ms`, or at once when the drive ignores
//!   quick stop (a brake gets its delay first); the axis ends in Switch on
//!   disabled and reports a fault. **Emergency stop**: disable voltage at
//!   once and a fault.
//! * **The drive's homing** (`CW_DRIVE_HOME`, [`crate::drive_homing`]): mode
//!   6, started, watched, handed back to cyclic position mode at the actual
//!   position; after the hand-back the command's target is followed again
//!   only once it lies within a few counts of the actual position (the
//!   engine follows the drive; a stale target is never jumped to).
//! * **A lost drive** ([`AxisLogic::lost`]): the backend latches a fault
//!   for an axis that was enabled, so the drive is not re-enabled by itself
//!   when it comes back.
//! * **No data this cycle**: the state machines are not stepped blind and
//!   the feedback is the last good one with `SW_NO_DATA`; a drive that was
//!   following goes on getting the command's target (its outputs may well
//!   arrive: a working counter that cannot be trusted), other outputs stay
//!   what they were — but a stop (watchdog, emergency, disable, the
//!   backend's fault) is sent all the same, on the last state seen and on
//!   time alone (`blind`): whatever the working counter says, the stop
//!   reaches every drive that takes its outputs.
//! * **Data back after a loss** longer than the supervisor's feedback
//!   timeout (its engine aborted the motion meanwhile), the drive still
//!   enabled but its command run away from the last target it got: never
//!   jumped there — its target is its actual position and it gets the
//!   backend's fault, the bounded stop (`after_gap`).
//! * **Objects the layout lacks**: without 0x606C the velocity is the
//!   position's change per cycle; without 0x6077 the torque is 0; without
//!   0x60FD no input is ever reported; without touch probes no latch.

use motion_frames::{
    AxisCommand, AxisFeedback, CW_DRIVE_HOME, CW_ENABLE, CW_FAULT_RESET, DI_HOME_SWITCH,
    DI_MARKER_PULSE, DI_OVERTRAVEL_NEGATIVE, DI_OVERTRAVEL_POSITIVE, EDGE_RISING, INVALID_COUNTS,
    SW_DRIVE_HOMED, SW_DRIVE_HOMING, SW_DRIVE_HOMING_ERROR, SW_ENABLED, SW_FAULT, SW_NO_DATA,
};

use crate::cia402::{Cia402, State, Target};
use crate::drive_homing::{self, DriveHoming};
use crate::objects::{di, MODE_CSP};
use crate::pdo::{DriveInputs, DriveOutputs, PdoLayout};
use crate::probe::{Edge, ProbeInputs, TouchProbes};
use crate::stop::Stopper;

/// Largest distance between target and actual position, counts.
pub const MAX_TARGET_DISTANCE: i64 = 1 << 30;
/// After the drive's homing handed back, the command's target is followed
/// again once it is this close to the actual position (plus four cycles of
/// its velocity), counts.
pub const RESYNC_COUNTS: i64 = 16;

/// The fewest missing cycles after which data that returns is checked for
/// a command that ran away ([`AxisSetup::gap_cycles`]).
pub const GAP_CYCLES: u32 = 3;

/// What the caller wants from all axes this cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Follow the command frame.
    Normal,
    /// Commands stopped: the bounded stop, then disabled with a fault.
    WatchdogStop,
    /// Power off now, fault.
    Emergency,
}

/// Per-axis counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AxisCounters {
    pub rejected_setpoints: u64,
    pub fault_resets: u64,
    /// Returns of its data after a gap over which the command ran away:
    /// the drive was stopped where it stood instead of jumping.
    pub gap_stops: u64,
    /// Cycles a stop was sent to the drive without its data (blind).
    pub blind_stop_cycles: u64,
}

/// How one axis is set up.
#[derive(Clone, Debug)]
pub struct AxisSetup {
    pub layout: PdoLayout,
    pub cycle_s: f64,
    /// Manufacturer bit of 0x60FD that reports the index pulse per cycle.
    pub index_pulse_bit: Option<u8>,
    /// Bit of 0x60FD wired to the home switch (default 2).
    pub home_switch_bit: Option<u8>,
    /// The bounded stop: quick stop at most this long.
    pub quick_stop_ms: u32,
    /// Disable operation this long before disable voltage (0: no brake).
    pub brake_ms: u32,
    /// The drive homes the axis itself when asked.
    pub drive_homing: bool,
    /// Cycles of missing data after which the supervisor's engine has
    /// aborted the motion (its feedback timeout; at least [`GAP_CYCLES`]).
    pub gap_cycles: u32,
}

impl AxisSetup {
    /// An axis on `layout` with the defaults (bit 2 home switch, no index
    /// bit, 500 ms quick stop, no brake, no drive homing).
    pub fn new(layout: PdoLayout, cycle_s: f64) -> AxisSetup {
        AxisSetup {
            layout,
            cycle_s,
            index_pulse_bit: None,
            home_switch_bit: None,
            quick_stop_ms: 500,
            brake_ms: 0,
            drive_homing: false,
            gap_cycles: 10,
        }
    }
}

/// The logic of one axis.
#[derive(Clone, Debug)]
pub struct AxisLogic {
    layout: PdoLayout,
    cia: Cia402,
    probes: TouchProbes,
    stopper: Stopper,
    homing: Option<DriveHoming>,
    /// `CW_ENABLE` / `CW_FAULT_RESET` of the previous command (edges).
    last_enable: bool,
    last_reset: bool,
    /// The backend's own fault (bounded stop, refused set-point, lost
    /// drive), cleared by a reset.
    fault_latch: bool,
    /// The command's target is not followed until it is near the actual
    /// position again (after the drive's homing handed back).
    resync: bool,
    /// Its SubDevice was lost since the last valid inputs.
    was_lost: bool,
    pos64: Option<i64>,
    pos32: i32,
    /// Cycles since the last valid inputs (derived velocity).
    since_inputs: u32,
    state: State,
    /// The state its data showed last (kept through a loss: a stop sent
    /// without data goes on from there).
    seen_state: State,
    outputs: DriveOutputs,
    last_feedback: AxisFeedback,
    kept_error: u16,
    index_pulse_bit: Option<u8>,
    home_switch: u32,
    /// 0x6065 the command asks for.
    window: u32,
    cycle_s: f64,
    /// Counts/s below which an axis counts as at rest (one count per cycle).
    rest_velocity: f64,
    /// Consecutive cycles below `rest_velocity` so far: at rest only after
    /// [`REST_CYCLES`] (one sample of a moving drive can read 0 when a
    /// late master repeated its set-point; disabling voltage on it would
    /// drop a moving axis).
    still: u32,
    /// See [`AxisSetup::gap_cycles`].
    gap_cycles: u32,
    pub counters: AxisCounters,
}

/// Cycles an axis must read below one count per cycle to be at rest.
pub const REST_CYCLES: u32 = 3;

impl AxisLogic {
    pub fn new(setup: AxisSetup) -> AxisLogic {
        let cycle_s = if setup.cycle_s > 0.0 {
            setup.cycle_s
        } else {
            0.001
        };
        let halt_s = f64::from(setup.quick_stop_ms) * 1e-3;
        AxisLogic {
            cia: Cia402::new(),
            probes: TouchProbes::new(),
            stopper: Stopper::new(cycle_s, setup.quick_stop_ms, setup.brake_ms),
            homing: setup
                .drive_homing
                .then(|| DriveHoming::new(cycle_s, halt_s)),
            last_enable: false,
            last_reset: false,
            fault_latch: false,
            resync: false,
            was_lost: false,
            pos64: None,
            pos32: 0,
            since_inputs: 1,
            state: State::NotReadyToSwitchOn,
            seen_state: State::NotReadyToSwitchOn,
            outputs: DriveOutputs {
                mode: MODE_CSP,
                ..DriveOutputs::default()
            },
            last_feedback: AxisFeedback::ZERO,
            kept_error: 0,
            index_pulse_bit: setup.index_pulse_bit,
            home_switch: 1u32 << (setup.home_switch_bit.unwrap_or(2) & 31),
            window: u32::MAX,
            cycle_s,
            rest_velocity: 1.0 / cycle_s,
            still: 0,
            gap_cycles: setup.gap_cycles.max(GAP_CYCLES),
            counters: AxisCounters::default(),
            layout: setup.layout,
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

    /// The stop asked for by [`Mode::WatchdogStop`] is complete: the drive
    /// is in Switch on disabled (or was never enabled).
    pub fn at_rest_and_disabled(&self) -> bool {
        !self.state.is_enabled()
            && !matches!(
                self.state,
                State::QuickStopActive | State::FaultReactionActive | State::SwitchedOn
            )
    }

    /// Its SubDevice is lost this cycle (not answering, out of OP,
    /// power-cycled): the state machines start afresh when it is back, and
    /// a drive that comes back no longer enabled while enable is still
    /// asked for gets the backend's fault — it is never enabled again by
    /// itself (a short loss the drive rode out in Operation enabled just
    /// goes on). A stop in progress goes on, blind, on the last state seen
    /// (its outputs may still arrive): it reaches disable voltage at its
    /// bound.
    pub fn lost(&mut self) {
        self.was_lost = true;
        self.cia = Cia402::new();
        if let Some(h) = &mut self.homing {
            h.forget();
        }
        self.state = State::NotReadyToSwitchOn;
        self.last_feedback.status_word &= !(SW_ENABLED | SW_DRIVE_HOMING | SW_DRIVE_HOMED);
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
            self.resets(cmd, enable);
        }
        let Some(inp) = inputs else {
            self.since_inputs = self.since_inputs.saturating_add(1);
            self.blind(cmd, mode, enable);
            let mut fb = self.last_feedback;
            fb.status_word |= SW_NO_DATA;
            return (self.outputs, fb);
        };
        let gap = self.since_inputs > self.gap_cycles;
        let prev = self.pos64;
        let pos64 = self.extend(inp.position);
        let velocity = if self.layout.present.velocity {
            f64::from(inp.velocity)
        } else {
            let dt = self.cycle_s * f64::from(self.since_inputs.max(1));
            prev.map_or(0.0, |p| (pos64 - p) as f64 / dt)
        };
        self.since_inputs = 1;
        self.state = State::from_statusword(inp.statusword);
        self.seen_state = self.state;
        if std::mem::take(&mut self.was_lost) && enable && !self.state.is_enabled() {
            self.fault_latch = true;
        }
        let set = self.check_setpoint(cmd, mode, enable, pos64);
        self.window = following_error_window(cmd.position_error_tolerance);
        self.still = if velocity.abs() < self.rest_velocity {
            self.still.saturating_add(1)
        } else {
            0
        };
        let at_rest = self.still >= REST_CYCLES;
        if gap && mode == Mode::Normal {
            self.after_gap(cmd);
        }
        let target = self.cia_target(mode, enable, at_rest, true);
        let home = self.drive_homing(cmd, mode, target, inp, at_rest);
        let mut controlword = self.cia.step(inp.statusword, target);
        if self.state.is_enabled() && target == Target::Enabled {
            controlword |= home.controlword;
        }
        let target_position =
            self.target_position(cmd, target, set.target_ok, pos64, inp, home.hold_actual);
        let function = self.probe_function(cmd, inp, pos64);
        self.outputs = DriveOutputs {
            controlword,
            target_position,
            touch_probe_function: function,
            torque_limit_positive: set.tpos.unwrap_or(self.outputs.torque_limit_positive),
            torque_limit_negative: set.tneg.unwrap_or(self.outputs.torque_limit_negative),
            mode: home.mode,
        };
        let mut fb = self.feedback(inp, pos64, velocity);
        for (on, bit) in [
            (home.active, SW_DRIVE_HOMING),
            (home.attained, SW_DRIVE_HOMED),
            (home.error, SW_DRIVE_HOMING_ERROR),
        ] {
            if on {
                fb.status_word |= bit;
            }
        }
        self.last_feedback = fb;
        (self.outputs, fb)
    }

    /// The rising edges of `CW_FAULT_RESET` and `CW_ENABLE` reset the
    /// backend's fault and ask the drive for a fault reset.
    fn resets(&mut self, cmd: &AxisCommand, enable: bool) {
        let reset = cmd.control_word & CW_FAULT_RESET != 0;
        if (enable && !self.last_enable) || (reset && !self.last_reset) {
            self.fault_latch = false;
            // asked for again: a stop in progress is over
            self.stopper.reset();
            self.cia.request_fault_reset();
            self.counters.fault_resets += 1;
        }
        self.last_enable = enable;
        self.last_reset = reset;
    }

    /// No data this cycle (the state machines are not stepped blind).
    ///
    /// * A drive that was following in Operation enabled goes on getting
    ///   the command's target: its data is missing, not necessarily its
    ///   outputs (a working counter that cannot be trusted), and the
    ///   supervisor goes on commanding through a short loss of feedback.
    /// * A stop (the watchdog's, the emergency stop, a disable, the
    ///   backend's own fault) is sent whatever the working counter says:
    ///   stepped on the last state seen and on time alone
    ///   ([`Stopper::step_blind`]) — quick stop until the bound, then (the
    ///   brake's delay and) disable voltage; from Operation enabled a
    ///   disable is "shutdown". Nothing is concluded from it: the axis
    ///   counts as stopped only once its data shows it.
    /// * Otherwise the outputs stay what they were.
    fn blind(&mut self, cmd: &AxisCommand, mode: Mode, enable: bool) {
        if mode == Mode::Normal && enable && !self.fault_latch {
            let following =
                self.state.is_enabled() && !self.resync && self.outputs.mode == MODE_CSP;
            let plausible = self.pos64.is_some_and(|p| {
                cmd.target_position != INVALID_COUNTS
                    && cmd
                        .target_position
                        .checked_sub(p)
                        .is_some_and(|d| d.abs() <= MAX_TARGET_DISTANCE)
            });
            if following && plausible {
                self.outputs.target_position = cmd.target_position as i32;
            }
            return;
        }
        let target = self.cia_target(mode, enable, false, false);
        self.outputs.controlword = self.cia.step(self.seen_state.statusword(), target);
        self.counters.blind_stop_cycles += 1;
    }

    /// The data came back after a loss longer than the supervisor's
    /// feedback timeout ([`AxisSetup::gap_cycles`]: its engine has aborted
    /// the motion and stops it on its own profile) with the drive still in
    /// Operation enabled, and the last target the drive got lies further
    /// from the command's than catching up in one cycle allows
    /// ([`RESYNC_COUNTS`] + four cycles of its velocity): it was lost (its
    /// outputs frozen) while the command ran on — a 30 ms loss at 20
    /// units/s would be 0.6 units in one cycle. It is never jumped there:
    /// its target is its actual position and it gets the backend's fault
    /// (the bounded stop, then disabled); the supervisor enables it again
    /// from where it stands after a reset. A shorter loss, which the engine
    /// rides out, is caught up: at most its feedback timeout's travel. (A
    /// drive that did not ride the loss out in Operation enabled follows
    /// its actual position anyway and gets the fault of a lost drive:
    /// [`AxisLogic::lost`].)
    fn after_gap(&mut self, cmd: &AxisCommand) {
        if !self.state.is_enabled() || self.resync || cmd.target_position == INVALID_COUNTS {
            return;
        }
        // the wire's targets are 32-bit: the step modulo 2^32
        let step = (cmd.target_position as i32).wrapping_sub(self.outputs.target_position);
        if f64::from(step).abs() > self.resync_window(cmd) {
            self.fault_latch = true;
            self.counters.gap_stops += 1;
        }
    }

    /// How near the command's target must be to be followed (again):
    /// [`RESYNC_COUNTS`] plus four cycles of the command's velocity.
    fn resync_window(&self, cmd: &AxisCommand) -> f64 {
        let v = if cmd.target_velocity.is_finite() {
            cmd.target_velocity.abs()
        } else {
            0.0
        };
        RESYNC_COUNTS as f64 + v * 4.0 * self.cycle_s
    }

    /// The set-point this cycle: the command's while following, the last
    /// good one after a refusal, else (and while the drive homes, or until
    /// the command has caught up after it) the actual position.
    fn target_position(
        &mut self,
        cmd: &AxisCommand,
        target: Target,
        target_ok: bool,
        pos64: i64,
        inp: &DriveInputs,
        hold_actual: bool,
    ) -> i32 {
        if hold_actual {
            self.resync = true;
            return inp.position;
        }
        if !(self.state.is_enabled() && target == Target::Enabled) {
            return inp.position;
        }
        if self.resync {
            let window = self.resync_window(cmd);
            let near = ((cmd.target_position - pos64) as f64).abs() <= window;
            if !(target_ok && near) {
                return inp.position;
            }
            self.resync = false;
        }
        if target_ok {
            cmd.target_position as i32 // modulo 2^32, consistent with the extension
        } else {
            self.outputs.target_position // refused: hold the last good one
        }
    }

    /// The drive's homing this cycle (idle, CSP, when not configured).
    fn drive_homing(
        &mut self,
        cmd: &AxisCommand,
        mode: Mode,
        target: Target,
        inp: &DriveInputs,
        at_rest: bool,
    ) -> drive_homing::Out {
        let asked = cmd.control_word & CW_DRIVE_HOME != 0;
        let Some(h) = &mut self.homing else {
            return drive_homing::Out {
                mode: MODE_CSP,
                controlword: 0,
                hold_actual: false,
                active: false,
                attained: false,
                // asked of a drive that cannot: say so
                error: asked && mode == Mode::Normal,
                failed_handback: false,
            };
        };
        let can = mode == Mode::Normal && target == Target::Enabled && self.state.is_enabled();
        if !can {
            h.abort();
        }
        let out = h.step(asked && can, inp.statusword, inp.mode_display, at_rest);
        if out.failed_handback {
            // the drive stays in homing mode: it does not follow set-points
            self.fault_latch = true;
        }
        out
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

    /// Where the CiA 402 machine walks the drive this cycle.
    /// (`seen`: from this cycle's data; else blind, see
    /// [`blind`](Self::blind)).
    fn cia_target(&mut self, mode: Mode, enable: bool, at_rest: bool, seen: bool) -> Target {
        let seen_state = self.seen_state;
        let stop = |s: &mut Stopper, state: State| {
            if seen {
                s.step(state, at_rest)
            } else {
                s.step_blind(seen_state)
            }
        };
        match mode {
            // commands back in the middle of a watchdog stop of an enabled
            // drive, enable still asked for: the stop goes on and the axis
            // is faulted — never enabled again by itself
            Mode::Normal if enable && !self.fault_latch && self.stopper.stopping() => {
                self.fault_latch = true;
                stop(&mut self.stopper, self.state)
            }
            Mode::Normal if enable && !self.fault_latch => {
                self.stopper.reset();
                Target::Enabled
            }
            // a refused set-point (or a drive back after a loss) while
            // enabled: the bounded stop
            Mode::Normal if self.fault_latch => stop(&mut self.stopper, self.state),
            Mode::Normal => {
                self.stopper.reset();
                Target::Disabled
            }
            Mode::WatchdogStop => {
                let t = stop(&mut self.stopper, self.state);
                if t == Target::Off && self.last_enable {
                    self.fault_latch = true;
                }
                t
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

    /// The frame's digital inputs from 0x60FD (none without it).
    fn digital_inputs(&self, raw: u32) -> u32 {
        if !self.layout.present.digital_inputs {
            return 0;
        }
        let mut dio = 0;
        if raw & self.home_switch != 0 {
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
    fn feedback(&mut self, inp: &DriveInputs, pos64: i64, velocity: f64) -> AxisFeedback {
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
            velocity,
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
#[path = "axis_tests.rs"]
mod tests;
