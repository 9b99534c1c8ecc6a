//! The plant: one axis of drive + mechanics + sensors, stepped once per cycle.

use motion_homing::{Command, Feedback};

use crate::config::{PlantConfig, RegistrationInput};
use crate::drive::Drive;
use crate::latch::Latch;
use crate::limits::LimitSwitches;
use crate::num::saturate;
use crate::sensors::{Markers, Switch};
use crate::torque::{torque, TorqueInputs};

/// A command the drive can execute: position finite, no NaN anywhere. Infinite
/// limits and tolerances are accepted (a limit never reached); NaN in any
/// field means a corrupted set-point, which a real drive rejects by faulting.
fn command_ok(cmd: &Command) -> bool {
    cmd.position.is_finite()
        && !cmd.velocity.is_nan()
        && !cmd.torque_limit_positive.is_nan()
        && !cmd.torque_limit_negative.is_nan()
        && !cmd.position_error_tolerance.is_nan()
        && !cmd.velocity_error_tolerance.is_nan()
}

/// One simulated axis. Deterministic, allocation-free, panic-free: the same
/// config and command sequence always give the same feedback bits.
#[derive(Clone, Debug)]
pub struct Plant {
    cfg: PlantConfig,
    markers: Markers,
    switch: Option<Switch>,
    limits: LimitSwitches,
    drive: Drive,
    position: f64,
    velocity: f64,
    torque: f64,
    /// The two previous command positions (most recent first), for the
    /// commanded acceleration. While the drive is not enabled they track the
    /// actual position, so taking over at standstill shows no acceleration.
    history: [f64; 2],
    marker_latch: Latch,
    /// A marker was passed in the last step (index pulse, no position).
    marker_pulse: bool,
    switch_latch: Latch,
}

impl Plant {
    /// A plant at rest at `cfg.start`, drive disabled, latches disarmed.
    /// The config is [sanitized](PlantConfig::sanitized) first.
    pub fn new(cfg: PlantConfig) -> Plant {
        let cfg = cfg.sanitized();
        Plant {
            markers: Markers::new(cfg.marker_at, cfg.marker_every),
            switch: cfg
                .switch
                .map(|(lo, hi)| Switch::new(lo, hi, cfg.switch_normally_closed)),
            limits: LimitSwitches::new(cfg.overtravel, cfg.limit_switches_normally_closed),
            drive: Drive::default(),
            position: cfg.start,
            velocity: 0.0,
            torque: 0.0,
            history: [cfg.start; 2],
            marker_latch: Latch::default(),
            marker_pulse: false,
            switch_latch: Latch::default(),
            cfg,
        }
    }

    /// Apply `cmd` over one cycle of `dt` seconds and return the feedback
    /// sampled at the end of the cycle.
    ///
    /// Order within the step: latch arming, enable/fault handling, motion
    /// (a straight segment from the old to the new position), crossings on
    /// that segment (latches), torque, following-error check, sensors.
    /// A `dt` that is not finite and positive counts as 0: no external
    /// motion, velocity and acceleration 0.
    pub fn step(&mut self, cmd: &Command, dt: f64) -> Feedback {
        let dt = if dt.is_finite() && dt > 0.0 { dt } else { 0.0 };

        self.marker_latch.arm(cmd.marker_arm);
        self.switch_latch.arm(cmd.switch_arm);
        self.drive.begin_step(
            cmd.enable,
            cmd.fault_reset,
            self.cfg.enable_delay_cycles,
            command_ok(cmd),
        );

        let old = self.position;
        let following = self.drive.enabled();
        let new = if following {
            // The loop closes within the cycle: the drive reaches the command
            // (one-cycle transport delay as seen by the engine), the stops
            // permitting. No takeover smoothing: commanding the actual
            // position on enable is the engine's job.
            self.cfg.clamp_to_stops(cmd.position)
        } else {
            self.cfg
                .clamp_to_stops(saturate(old + self.cfg.external_speed * dt))
        };
        self.position = new;
        self.velocity = if dt > 0.0 {
            saturate((new - old) / dt)
        } else {
            0.0
        };

        self.capture(old, new);
        if self.limits.wire_break(new) {
            // NC limit switches both open: the drive's wire-break fault.
            self.trip();
        }

        // (a wire-break fault of this step leaves no torque either)
        if following && self.drive.enabled() {
            let acceleration = if dt > 0.0 {
                // Second difference as two first differences, each saturated,
                // so huge commands cannot produce ∞ − ∞.
                let d1 = saturate(cmd.position - self.history[0]);
                let d0 = saturate(self.history[0] - self.history[1]);
                saturate(saturate(d1 - d0) / (dt * dt))
            } else {
                0.0
            };
            self.history = [cmd.position, self.history[0]];
            self.torque = torque(
                &self.cfg,
                &TorqueInputs {
                    command: cmd.position,
                    position: new,
                    acceleration,
                    velocity: self.velocity,
                    limit_positive: cmd.torque_limit_positive,
                    limit_negative: cmd.torque_limit_negative,
                },
            );
            let tolerance = cmd.position_error_tolerance;
            if tolerance > 0.0 && (cmd.position - new).abs() > tolerance {
                self.trip();
            }
        } else {
            self.history = [new; 2];
            self.torque = 0.0;
        }

        self.feedback()
    }

    /// Latch the first marker and the first switch edge of the armed sense
    /// passed on `old → new`.
    fn capture(&mut self, old: f64, new: f64) {
        self.marker_pulse = self.markers.first_passed(old, new).is_some();
        if self.marker_latch.waiting() {
            self.marker_latch
                .capture(self.markers.first_passed(old, new));
        }
        if self.switch_latch.waiting() {
            let probe = match self.cfg.registration_input {
                RegistrationInput::HomeSwitch => self.switch,
                RegistrationInput::NegativeLimit => self.limits.negative(),
                RegistrationInput::PositiveLimit => self.limits.positive(),
            };
            if let Some(sw) = probe {
                self.switch_latch
                    .capture(sw.first_edge(old, new, self.switch_latch.edge()));
            }
        }
    }

    fn trip(&mut self) {
        self.drive.trip();
        self.torque = 0.0;
    }

    /// Current feedback without stepping (after [`new`](Self::new): the start
    /// position, its inputs, a disabled drive).
    pub fn feedback(&self) -> Feedback {
        let x = self.position;
        let (overtravel_negative, overtravel_positive) = self.limits.states(x);
        Feedback {
            position: x,
            velocity: self.velocity,
            torque: self.torque,
            home_switch: self.switch.is_some_and(|s| s.level(x)),
            overtravel_positive,
            overtravel_negative,
            marker_latch: self.marker_latch.feedback(),
            switch_latch: self.switch_latch.feedback(),
            marker_pulse: self.marker_pulse,
            drive: self.drive.state(),
            drive_homing: Default::default(),
        }
    }

    /// Exact raw position.
    pub fn position(&self) -> f64 {
        self.position
    }

    /// Tests: the drive faults now (power stage off, torque 0); cleared by a
    /// rising edge of `Command::fault_reset`, or the enable false → true
    /// handshake.
    pub fn inject_fault(&mut self) {
        self.trip();
    }

    /// The drive's fault reset, as the rising edge of
    /// `Command::fault_reset` does it: the fault clears, the power stage
    /// stays off until a new rising edge of `enable`.
    pub fn reset_fault(&mut self) {
        self.drive.reset_fault();
    }

    /// Tests: the common wire of the limit switches is cut. With NC wiring
    /// both read actuated and the drive faults (while the wire stays cut);
    /// with NO wiring both read released: the limits are silently gone.
    pub fn break_limit_wire(&mut self) {
        self.limits.break_wire();
    }

    /// Both NC limit inputs read actuated now: the wire-break fault's cause
    /// (a drive model names it in its error code).
    pub fn limit_wire_break(&self) -> bool {
        self.limits.wire_break(self.position)
    }

    /// Tests: the home switch is moved by `shift` along the axis (a worn
    /// switch, a loose bracket) while everything else stays as it is; a
    /// non-finite shift changes nothing.
    pub fn move_switch(&mut self, shift: f64) {
        if !shift.is_finite() {
            return;
        }
        if let Some((lo, hi)) = self.cfg.switch {
            let moved = (lo + shift, hi + shift);
            self.cfg.switch = Some(moved);
            self.switch = Some(Switch::new(
                moved.0,
                moved.1,
                self.cfg.switch_normally_closed,
            ));
        }
    }

    /// The (sanitized) configuration in use.
    pub fn config(&self) -> &PlantConfig {
        &self.cfg
    }

    /// The marker track, e.g. to compute where the next marker is in a test.
    pub fn markers(&self) -> Markers {
        self.markers
    }

    /// The home switch, if configured.
    pub fn switch(&self) -> Option<Switch> {
        self.switch
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::TorqueSpike;
    use motion_homing::{Edge, LatchArm, LatchFeedback};

    const DT: f64 = 0.001;

    /// An enabled-drive command at `position` with generous limits.
    fn cmd(position: f64) -> Command {
        Command {
            enable: true,
            position,
            torque_limit_positive: 50.0,
            torque_limit_negative: 20.0,
            ..Command::default()
        }
    }

    fn off() -> Command {
        Command::default()
    }

    fn marker_arm(mut c: Command, id: u8) -> Command {
        c.marker_arm = LatchArm {
            id,
            edge: Edge::Rising,
        };
        c
    }

    fn switch_arm(mut c: Command, id: u8, edge: Edge) -> Command {
        c.switch_arm = LatchArm { id, edge };
        c
    }

    /// A plant with no enable delay, enabled at `at` by one step.
    fn enabled(cfg: PlantConfig, at: f64) -> Plant {
        let mut p = Plant::new(PlantConfig {
            start: at,
            enable_delay_cycles: 0,
            ..cfg
        });
        let fb = p.step(&cmd(at), DT);
        assert!(fb.drive.enabled);
        p
    }

    fn assert_finite(fb: &Feedback) {
        let numbers = crate::feedback_numbers(fb);
        assert!(numbers.iter().all(|v| v.is_finite()), "{fb:?}");
    }

    fn latched(id: u8, position: f64) -> LatchFeedback {
        LatchFeedback {
            id,
            latched: true,
            position,
        }
    }

    #[test]
    fn feedback_after_new_reflects_the_start() {
        let p = Plant::new(PlantConfig {
            start: 2.0,
            switch: Some((0.0, 5.0)),
            overtravel: Some((3.0, 10.0)),
            ..PlantConfig::default()
        });
        let fb = p.feedback();
        assert_eq!(fb.position, 2.0);
        assert_eq!(fb.velocity, 0.0);
        assert_eq!(fb.torque, 0.0);
        assert!(fb.home_switch);
        assert!(fb.overtravel_negative && !fb.overtravel_positive);
        assert_eq!(fb.drive, Default::default());
        assert_eq!(fb.marker_latch, LatchFeedback::default());
        assert_eq!(p.position(), 2.0);
        assert_eq!(p.config().start, 2.0);
    }

    #[test]
    fn follows_the_command_with_one_cycle_delay() {
        let mut p = enabled(PlantConfig::default(), 0.0);
        for (i, x) in [0.25, 0.75, 1.25, 1.5].into_iter().enumerate() {
            let before = p.feedback().position;
            let fb = p.step(&cmd(x), 0.5);
            // The engine reads this at the start of the next cycle.
            assert_eq!(fb.position, x, "step {i}");
            assert_eq!(p.position(), x);
            assert_eq!(fb.velocity, (x - before) / 0.5);
            assert_eq!(p.feedback(), fb);
        }
    }

    #[test]
    fn takeover_follows_without_smoothing() {
        let mut p = Plant::new(PlantConfig {
            start: 3.0,
            enable_delay_cycles: 0,
            ..PlantConfig::default()
        });
        let fb = p.step(&cmd(7.0), 1.0);
        assert_eq!(fb.position, 7.0);
        assert_eq!(fb.velocity, 4.0);
    }

    #[test]
    fn non_positive_dt_gives_zero_velocity() {
        let mut p = enabled(PlantConfig::default(), 0.0);
        for dt in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let fb = p.step(&cmd(p.position() + 1.0), dt);
            assert_eq!(fb.velocity, 0.0);
            assert_finite(&fb);
        }
        assert_eq!(p.position(), 4.0);
    }

    #[test]
    fn inertia_torque_from_the_last_three_commands() {
        let mut p = enabled(
            PlantConfig {
                inertia_gain: 0.5,
                friction: 1.0,
                ..PlantConfig::default()
            },
            0.0,
        );
        // (command, expected torque) with dt = 1: a = c - 2 c1 + c2.
        for (c, t) in [(1.0, 1.5), (3.0, 1.5), (4.0, 0.5), (4.0, -0.5), (4.0, 0.0)] {
            assert_eq!(p.step(&cmd(c), 1.0).torque, t, "command {c}");
        }
    }

    #[test]
    fn hard_stop_clamps_and_torque_rises_to_the_limit() {
        let mut p = enabled(
            PlantConfig {
                hard_stop: Some((-10.0, 10.0)),
                ..PlantConfig::default()
            },
            9.0,
        );
        let fb = p.step(&cmd(10.0), DT);
        assert_eq!(fb.position, 10.0);
        for (c, t) in [(10.125, 12.5), (10.25, 25.0), (10.5, 50.0), (11.0, 50.0)] {
            let fb = p.step(&cmd(c), DT);
            assert_eq!(fb.position, 10.0, "clamped at {c}");
            assert_eq!(fb.velocity, 0.0);
            assert_eq!(fb.torque, t, "command {c}");
            assert!(fb.drive.enabled);
        }
        // Back off: free motion again.
        let fb = p.step(&cmd(10.0), DT);
        assert_eq!(fb.position, 10.0);
        assert!(fb.torque.abs() <= 50.0);
        // Negative stop, negative limit.
        let mut p = enabled(
            PlantConfig {
                hard_stop: Some((-10.0, 10.0)),
                ..PlantConfig::default()
            },
            -10.0,
        );
        assert_eq!(p.step(&cmd(-10.125), DT).torque, -12.5);
        assert_eq!(p.step(&cmd(-10.5), DT).torque, -20.0);
        assert_eq!(p.position(), -10.0);
    }

    #[test]
    fn following_error_faults_only_with_a_tolerance() {
        let cfg = PlantConfig {
            hard_stop: Some((-10.0, 10.0)),
            ..PlantConfig::default()
        };
        // Tolerance 0 (torque homing): pushing does not fault.
        let mut p = enabled(cfg, 10.0);
        let fb = p.step(&cmd(12.0), DT);
        assert!(fb.drive.enabled && !fb.drive.fault);
        assert_eq!(fb.torque, 50.0);

        // Tolerance set: free motion is fine, pushing beyond it faults.
        let mut p = enabled(cfg, 9.0);
        let tol = |x| Command {
            position_error_tolerance: 0.5,
            ..cmd(x)
        };
        assert!(!p.step(&tol(10.0), DT).drive.fault);
        assert!(!p.step(&tol(10.5), DT).drive.fault, "exactly at tolerance");
        let fb = p.step(&tol(10.75), DT);
        assert!(fb.drive.fault && !fb.drive.enabled);
        assert_eq!(fb.torque, 0.0);
        assert_eq!(fb.position, 10.0);
        // Faulted: no longer follows.
        let fb = p.step(&tol(0.0), DT);
        assert_eq!(fb.position, 10.0);
        assert!(fb.drive.fault);
    }

    #[test]
    fn fault_reset_handshake() {
        let mut p = Plant::new(PlantConfig {
            enable_delay_cycles: 1,
            ..PlantConfig::default()
        });
        p.step(&cmd(0.0), DT);
        assert!(p.step(&cmd(0.0), DT).drive.enabled);
        p.inject_fault();
        assert!(p.feedback().drive.fault && !p.feedback().drive.enabled);
        // Enable held: the fault stays.
        assert!(p.step(&cmd(1.0), DT).drive.fault);
        assert_eq!(p.position(), 0.0);
        // Enable dropped: still reported, drive off.
        let fb = p.step(&off(), DT);
        assert!(fb.drive.fault && !fb.drive.enabled);
        // Rising edge: reset, then the normal enable delay.
        let fb = p.step(&cmd(0.0), DT);
        assert!(!fb.drive.fault && !fb.drive.enabled);
        let fb = p.step(&cmd(0.0), DT);
        assert!(!fb.drive.fault && fb.drive.enabled);
    }

    #[test]
    fn enable_delay_and_immediate_disable() {
        let mut p = Plant::new(PlantConfig::default()); // 2 cycles
        assert!(!p.step(&cmd(0.0), DT).drive.enabled);
        assert!(!p.step(&cmd(0.0), DT).drive.enabled);
        let fb = p.step(&cmd(0.0), DT);
        assert!(fb.drive.enabled && !fb.drive.fault);
        let fb = p.step(&off(), DT);
        assert!(!fb.drive.enabled);
        assert_eq!(fb.torque, 0.0);

        let mut p = Plant::new(PlantConfig {
            enable_delay_cycles: 0,
            ..PlantConfig::default()
        });
        let fb = p.step(&cmd(1.0), DT);
        assert!(fb.drive.enabled, "delay 0: same step");
        assert_eq!(fb.position, 1.0, "and follows in that step");
    }

    #[test]
    fn not_enabled_ignores_the_command() {
        let mut p = Plant::new(PlantConfig::default());
        // Enable requested but the delay has not elapsed: no motion, no torque.
        let fb = p.step(&cmd(5.0), DT);
        assert_eq!(fb.position, 0.0);
        assert_eq!(fb.torque, 0.0);
    }

    #[test]
    fn external_motion_when_not_enabled() {
        let mut p = Plant::new(PlantConfig {
            external_speed: -2.0,
            hard_stop: Some((-1.5, 10.0)),
            enable_delay_cycles: 1,
            ..PlantConfig::default()
        });
        let fb = p.step(&off(), 0.5);
        assert_eq!(fb.position, -1.0);
        assert_eq!(fb.velocity, -2.0);
        assert_eq!(fb.torque, 0.0);
        // Enable requested, delay running: still moved by the outside.
        let fb = p.step(&cmd(-1.0), 0.5);
        assert!(!fb.drive.enabled);
        assert_eq!(fb.position, -1.5, "clamped at the stop");
        assert_eq!(fb.velocity, -1.0);
        let fb = p.step(&cmd(-1.5), 0.5);
        assert_eq!(fb.position, -1.5);
        assert_eq!(fb.velocity, 0.0);
        // Enabled: the drive holds against the outside.
        let fb = p.step(&cmd(0.0), 0.5);
        assert!(fb.drive.enabled);
        assert_eq!(fb.position, 0.0);
    }

    #[test]
    fn switch_levels_no_and_nc() {
        for nc in [false, true] {
            let mut p = Plant::new(PlantConfig {
                start: -1.0,
                switch: Some((0.0, 5.0)),
                switch_normally_closed: nc,
                enable_delay_cycles: 0,
                ..PlantConfig::default()
            });
            assert_eq!(p.feedback().home_switch, nc, "at rest");
            for (x, actuated) in [(0.0, true), (2.5, true), (5.0, true), (5.5, false)] {
                assert_eq!(
                    p.step(&cmd(x), DT).home_switch,
                    actuated != nc,
                    "x {x} nc {nc}"
                );
            }
        }
        // No switch configured: the input reads open.
        assert!(!Plant::new(PlantConfig::default()).feedback().home_switch);
    }

    #[test]
    fn overtravel_inputs() {
        let mut p = enabled(
            PlantConfig {
                overtravel: Some((-5.0, 5.0)),
                ..PlantConfig::default()
            },
            0.0,
        );
        let fb = p.step(&cmd(5.5), DT);
        assert!(fb.overtravel_positive && !fb.overtravel_negative);
        let fb = p.step(&cmd(-5.5), DT);
        assert!(!fb.overtravel_positive && fb.overtravel_negative);
        // Actuated at the end itself (`limit_switches`; `overtravel` tripped
        // only strictly beyond it).
        let fb = p.step(&cmd(-5.0), DT);
        assert!(!fb.overtravel_positive && fb.overtravel_negative);
        let fb = p.step(&cmd(-4.999), DT);
        assert!(!fb.overtravel_positive && !fb.overtravel_negative);
    }

    #[test]
    fn nc_limit_wire_break_faults_the_drive_while_it_lasts() {
        for nc in [false, true] {
            let mut p = enabled(
                PlantConfig {
                    overtravel: Some((-5.0, 5.0)),
                    limit_switches_normally_closed: nc,
                    ..PlantConfig::default()
                },
                0.0,
            );
            let fb = p.step(&cmd(1.0), DT);
            assert!(fb.drive.enabled && !fb.overtravel_negative && !fb.overtravel_positive);
            p.break_limit_wire();
            let fb = p.step(&cmd(1.0), DT);
            // NC: both read actuated, a wire break: fault. NO: both read
            // released, nothing to see.
            assert_eq!(fb.overtravel_negative && fb.overtravel_positive, nc);
            assert_eq!(fb.drive.fault, nc, "NC {nc}");
            assert_eq!(fb.drive.enabled, !nc);
            // The reset handshake does not clear it while the wire is cut.
            p.step(&off(), DT);
            let fb = p.step(&cmd(1.0), DT);
            assert_eq!(fb.drive.fault, nc);
        }
    }

    #[test]
    fn registration_on_the_limit_switch_latches_its_edges_as_states() {
        let cfg = PlantConfig {
            switch: Some((0.0, 5.0)),
            overtravel: Some((-5.0, 20.0)),
            limit_switches_normally_closed: true,
            registration_input: RegistrationInput::NegativeLimit,
            ..PlantConfig::default()
        };
        let mut p = enabled(cfg, -3.0);
        // Onto the negative limit: the rising (actuated) edge at -5 exactly,
        // whatever the NC wiring; the home switch is not the probe's input.
        let fb = p.step(&switch_arm(cmd(-6.0), 1, Edge::Rising), DT);
        assert_eq!(fb.switch_latch, latched(1, -5.0));
        let fb = p.step(&switch_arm(cmd(-5.5), 2, Edge::Falling), DT);
        assert!(!fb.switch_latch.latched);
        let fb = p.step(&switch_arm(cmd(2.0), 2, Edge::Falling), DT);
        assert_eq!(
            fb.switch_latch,
            latched(2, -5.0),
            "released strictly past -5"
        );
        let mut p = enabled(
            PlantConfig {
                registration_input: RegistrationInput::PositiveLimit,
                ..cfg
            },
            18.0,
        );
        let fb = p.step(&switch_arm(cmd(21.0), 3, Edge::Rising), DT);
        assert_eq!(fb.switch_latch, latched(3, 20.0));
    }

    fn marker_cfg() -> PlantConfig {
        PlantConfig {
            marker_at: 2.5,
            marker_every: 10.0,
            ..PlantConfig::default()
        }
    }

    #[test]
    fn marker_latch_exact_forward_and_backward() {
        let mut p = enabled(marker_cfg(), 0.0);
        let fb = p.step(&marker_arm(cmd(1.0), 1), DT);
        assert_eq!(
            fb.marker_latch,
            LatchFeedback {
                id: 1,
                latched: false,
                position: 0.0
            }
        );
        let fb = p.step(&marker_arm(cmd(3.1), 1), DT);
        assert_eq!(fb.marker_latch, latched(1, 2.5));
        assert_eq!(fb.marker_latch.position.to_bits(), 2.5f64.to_bits());

        // Backward, several markers in one step: the first in the direction
        // of motion, armed in the same step.
        let mut p = enabled(marker_cfg(), 30.0);
        let fb = p.step(&marker_arm(cmd(0.0), 9), DT);
        assert_eq!(fb.marker_latch, latched(9, 22.5));
        // Forward across several: the first one.
        let mut p = enabled(marker_cfg(), -30.0);
        let fb = p.step(&marker_arm(cmd(30.0), 9), DT);
        assert_eq!(fb.marker_latch, latched(9, -27.5));
    }

    #[test]
    fn marker_latch_holds_until_rearmed() {
        let mut p = enabled(marker_cfg(), 0.0);
        p.step(&marker_arm(cmd(5.0), 1), DT);
        let fb = p.step(&marker_arm(cmd(15.0), 1), DT);
        assert_eq!(fb.marker_latch, latched(1, 2.5), "no second capture");
        let fb = p.step(&marker_arm(cmd(15.0), 2), DT);
        assert_eq!(fb.marker_latch.id, 2);
        assert!(!fb.marker_latch.latched);
        let fb = p.step(&marker_arm(cmd(25.0), 2), DT);
        assert_eq!(fb.marker_latch, latched(2, 22.5));
        let fb = p.step(&marker_arm(cmd(35.0), 0), DT);
        assert_eq!(fb.marker_latch, LatchFeedback::default(), "disarmed");
    }

    #[test]
    fn marker_latch_by_external_motion() {
        let mut p = Plant::new(PlantConfig {
            external_speed: 10.0,
            ..marker_cfg()
        });
        let fb = p.step(&marker_arm(off(), 4), 0.2);
        assert_eq!(fb.position, 2.0);
        assert!(!fb.marker_latch.latched);
        let fb = p.step(&marker_arm(off(), 4), 0.2);
        assert_eq!(fb.marker_latch, latched(4, 2.5));
    }

    #[test]
    fn stop_on_a_marker_then_reverse_counts_once() {
        let mut p = enabled(marker_cfg(), 0.0);
        // Arrive exactly on the marker: that is the passage.
        let fb = p.step(&marker_arm(cmd(2.5), 1), DT);
        assert_eq!(fb.marker_latch, latched(1, 2.5));
        // Re-arm while standing on it and reverse: not passed again.
        let fb = p.step(&marker_arm(cmd(2.5), 2), DT);
        assert!(!fb.marker_latch.latched);
        let fb = p.step(&marker_arm(cmd(0.0), 2), DT);
        assert!(!fb.marker_latch.latched, "leaving the marker is no passage");
        // Coming back over it is a new passage.
        let fb = p.step(&marker_arm(cmd(5.0), 2), DT);
        assert_eq!(fb.marker_latch, latched(2, 2.5));
        // Same from the other side: arrive backward, continue backward.
        let fb = p.step(&marker_arm(cmd(2.5), 3), DT);
        assert_eq!(fb.marker_latch, latched(3, 2.5));
        let fb = p.step(&marker_arm(cmd(1.0), 4), DT);
        assert!(!fb.marker_latch.latched, "continuing off it: no passage");
    }

    fn switch_cfg(nc: bool) -> PlantConfig {
        PlantConfig {
            switch: Some((0.0, 5.0)),
            switch_normally_closed: nc,
            ..PlantConfig::default()
        }
    }

    /// Move `from → to` in one step with the switch latch armed for `edge`.
    fn switch_latch(nc: bool, from: f64, to: f64, edge: Edge) -> LatchFeedback {
        let mut p = enabled(switch_cfg(nc), from);
        p.step(&switch_arm(cmd(to), 1, edge), DT).switch_latch
    }

    #[test]
    fn switch_latch_on_each_electrical_edge() {
        use Edge::{Falling, Rising};
        // (nc, from, to, edge, boundary latched)
        let cases = [
            (false, -1.0, 6.0, Rising, 0.0),
            (false, -1.0, 6.0, Falling, 5.0),
            (false, 6.0, -1.0, Rising, 5.0),
            (false, 6.0, -1.0, Falling, 0.0),
            (true, -1.0, 6.0, Falling, 0.0),
            (true, -1.0, 6.0, Rising, 5.0),
            (true, 6.0, -1.0, Falling, 5.0),
            (true, 6.0, -1.0, Rising, 0.0),
        ];
        for (nc, from, to, edge, at) in cases {
            assert_eq!(
                switch_latch(nc, from, to, edge),
                latched(1, at),
                "nc {nc} {from} -> {to} {edge:?}"
            );
        }
        // Only an edge of the armed sense counts.
        assert!(!switch_latch(false, -1.0, 2.0, Falling).latched);
        assert!(!switch_latch(true, -1.0, 2.0, Rising).latched);
    }

    #[test]
    fn switch_latch_at_a_boundary_stop_matches_the_inclusive_interval() {
        let mut p = enabled(switch_cfg(false), -1.0);
        // Stop exactly on lo: actuated (inclusive), rising edge at lo.
        let fb = p.step(&switch_arm(cmd(0.0), 1, Edge::Rising), DT);
        assert!(fb.home_switch);
        assert_eq!(fb.switch_latch, latched(1, 0.0));
        // Arm for the falling edge while standing there, then reverse: the
        // edge shows (at lo) in the cycle the level drops.
        let fb = p.step(&switch_arm(cmd(0.0), 2, Edge::Falling), DT);
        assert!(fb.home_switch && !fb.switch_latch.latched);
        let fb = p.step(&switch_arm(cmd(-0.5), 2, Edge::Falling), DT);
        assert!(!fb.home_switch);
        assert_eq!(fb.switch_latch, latched(2, 0.0));

        // Stop exactly on hi from inside: still actuated, no falling edge yet.
        let mut p = enabled(switch_cfg(false), 4.0);
        let fb = p.step(&switch_arm(cmd(5.0), 1, Edge::Falling), DT);
        assert!(fb.home_switch && !fb.switch_latch.latched);
        let fb = p.step(&switch_arm(cmd(5.5), 1, Edge::Falling), DT);
        assert!(!fb.home_switch);
        assert_eq!(fb.switch_latch, latched(1, 5.0));
        // Back onto hi: rising at hi, once.
        let fb = p.step(&switch_arm(cmd(5.0), 2, Edge::Rising), DT);
        assert!(fb.home_switch);
        assert_eq!(fb.switch_latch, latched(2, 5.0));
        let fb = p.step(&switch_arm(cmd(4.0), 3, Edge::Rising), DT);
        assert!(!fb.switch_latch.latched, "continuing inside: no new edge");

        // NC, same stops: the levels and edges are the inverse.
        let mut p = enabled(switch_cfg(true), -1.0);
        let fb = p.step(&switch_arm(cmd(0.0), 1, Edge::Falling), DT);
        assert!(!fb.home_switch);
        assert_eq!(fb.switch_latch, latched(1, 0.0));
    }

    #[test]
    fn non_finite_commands_fault_with_finite_feedback() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut p = enabled(
                PlantConfig {
                    switch: Some((0.0, 5.0)),
                    ..marker_cfg()
                },
                1.0,
            );
            let fb = p.step(&marker_arm(cmd(bad), 1), DT);
            assert!(fb.drive.fault && !fb.drive.enabled, "{bad}");
            assert_eq!(fb.position, 1.0);
            assert_finite(&fb);
            // Still faulted with good commands until the handshake.
            assert!(p.step(&cmd(1.0), DT).drive.fault);
        }
        let mut p = enabled(PlantConfig::default(), 0.0);
        let fb = p.step(
            &Command {
                torque_limit_positive: f64::NAN,
                ..cmd(1.0)
            },
            DT,
        );
        assert!(fb.drive.fault);
        assert_finite(&fb);
        // Infinite limits are accepted: "no limit".
        let mut p = enabled(PlantConfig::default(), 0.0);
        let fb = p.step(
            &Command {
                torque_limit_positive: f64::INFINITY,
                position_error_tolerance: f64::INFINITY,
                ..cmd(1.0)
            },
            DT,
        );
        assert!(fb.drive.enabled && !fb.drive.fault);
    }

    #[test]
    fn huge_positions_do_not_panic() {
        let cfg = PlantConfig {
            switch: Some((0.0, 5.0)),
            hard_stop: Some((f64::NEG_INFINITY, f64::INFINITY)),
            overtravel: Some((-1e300, 1e300)),
            torque_spike: Some(TorqueSpike {
                at: 0.0,
                width: f64::MAX,
                level: 10.0,
            }),
            ..marker_cfg()
        };
        let mut p = enabled(cfg, 0.0);
        for (i, x) in [
            1e300,
            -1e300,
            f64::MAX,
            -f64::MAX,
            f64::MAX,
            0.0,
            1e-300,
            -f64::MIN_POSITIVE,
        ]
        .into_iter()
        .enumerate()
        {
            let c = Command {
                torque_limit_positive: f64::INFINITY,
                torque_limit_negative: f64::INFINITY,
                position_error_tolerance: 1.0,
                ..marker_arm(switch_arm(cmd(x), i as u8 + 1, Edge::Rising), i as u8 + 1)
            };
            let fb = p.step(&c, DT);
            assert_finite(&fb);
            assert!(!fb.drive.fault, "{x}");
        }
        // External motion at the edge of the range saturates.
        let mut p = Plant::new(PlantConfig {
            start: f64::MAX,
            external_speed: 1e300,
            ..marker_cfg()
        });
        for _ in 0..3 {
            assert_finite(&p.step(&marker_arm(off(), 1), 1e10));
        }
    }

    #[test]
    fn torque_spike_in_the_direction_of_motion() {
        let cfg = PlantConfig {
            inertia_gain: 0.0,
            friction: 1.0,
            torque_spike: Some(TorqueSpike {
                at: 5.0,
                width: 1.0,
                level: 30.0,
            }),
            ..PlantConfig::default()
        };
        let mut p = enabled(cfg, 3.5);
        let torques: Vec<f64> = (1..=8)
            .map(|i| p.step(&cmd(3.5 + 0.5 * f64::from(i)), DT).torque)
            .collect();
        // Positions 4.0, 4.5, 5.0, 5.5, 6.0, 6.5, 7.0, 7.5.
        assert_eq!(torques, [1.0, 1.0, 31.0, 31.0, 31.0, 1.0, 1.0, 1.0]);
        let fb = p.step(&cmd(5.5), DT);
        assert_eq!(fb.torque, -20.0, "backward, limited to the negative limit");
    }
}
