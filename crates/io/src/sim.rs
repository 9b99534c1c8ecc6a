//! Backend `sim`: one deterministic [`motion_plant::Plant`] per configured
//! axis.
//!
//! The simulation is driven by the commands: every command frame advances
//! every plant by exactly one cycle (`cycle_us`), like a drive synchronised to
//! the bus cycle. Without commands simulated time stands still (also for an
//! axis moved externally, e.g. a passive measuring wheel), except for the
//! watchdog stop, which advances the stopping axes one cycle per call.

use motion_config::MachineConfig;
use motion_frames::backend::{Backend, ExchangeError};
use motion_frames::{axis_to_command, feedback_to_axis, CommandFrame, FeedbackFrame};
use motion_homing::Command;
use motion_plant::Plant;

/// Deceleration used by the watchdog stop when the axis has no
/// `home_deceleration` configured, units/s².
pub const FALLBACK_DECELERATION: f64 = 1000.0;

/// Where an axis is in the watchdog stop.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Stop {
    /// Commands are flowing (or no stop was asked for yet).
    None,
    /// Decelerating: the generated set-point.
    Ramping { position: f64, velocity: f64 },
    /// At rest; disabled with a fault if it was under command.
    Done,
}

struct SimAxis {
    name: String,
    plant: Plant,
    counts_per_unit: f64,
    deceleration: f64,
    /// Last command applied, units (the start of a watchdog stop).
    last: Command,
    stop: Stop,
}

impl SimAxis {
    /// One watchdog-stop cycle; true once at rest.
    fn stop_step(&mut self, dt: f64) -> bool {
        // An invalid dt would never finish the ramp: stop within one call.
        let dv = if dt.is_finite() && dt > 0.0 {
            self.deceleration * dt
        } else {
            f64::INFINITY
        };
        loop {
            match self.stop {
                Stop::Done => return true,
                Stop::None => {
                    if self.plant.feedback().drive.enabled {
                        let position = if self.last.position.is_finite() {
                            self.last.position
                        } else {
                            self.plant.position()
                        };
                        let velocity = if self.last.velocity.is_finite() {
                            self.last.velocity
                        } else {
                            0.0
                        };
                        self.stop = Stop::Ramping { position, velocity };
                    } else {
                        // Not following anything: no stop needed. A step of
                        // zero length (same command, so no enable edge) shows
                        // the frozen axis with velocity 0; a drive that was
                        // asked to enable reports the communication loss.
                        self.plant.step(&self.last, 0.0);
                        if self.last.enable {
                            self.plant.inject_fault();
                        }
                        self.stop = Stop::Done;
                    }
                }
                Stop::Ramping { position, velocity } => {
                    if !self.plant.feedback().drive.enabled {
                        // Dropped out during the ramp (e.g. following error).
                        if !self.plant.feedback().drive.fault {
                            self.plant.inject_fault();
                        }
                        self.stop = Stop::Done;
                        return true;
                    }
                    let v = if velocity.abs() <= dv {
                        0.0
                    } else {
                        velocity - dv.copysign(velocity)
                    };
                    let p = position + v * dt;
                    let cmd = Command {
                        enable: true,
                        position: p,
                        velocity: v,
                        ..self.last
                    };
                    self.plant.step(&cmd, dt);
                    if v == 0.0 {
                        // At rest: the drive's communication watchdog disables
                        // it and reports the fault.
                        self.plant.inject_fault();
                        self.stop = Stop::Done;
                        return true;
                    }
                    self.stop = Stop::Ramping {
                        position: p,
                        velocity: v,
                    };
                    return false;
                }
            }
        }
    }
}

/// The `sim` backend.
pub struct SimBackend {
    axes: Vec<SimAxis>,
    dt: f64,
}

impl SimBackend {
    /// One plant per axis of `cfg`, in config order; one frame = `cycle_us`.
    pub fn new(cfg: &MachineConfig) -> Self {
        let axes = cfg
            .axes
            .iter()
            .map(|a| SimAxis {
                name: a.name.clone(),
                plant: Plant::new(a.sim),
                counts_per_unit: a.engine.counts_per_unit,
                deceleration: if a.engine.home_deceleration.is_finite()
                    && a.engine.home_deceleration > 0.0
                {
                    a.engine.home_deceleration
                } else {
                    FALLBACK_DECELERATION
                },
                last: Command::default(),
                stop: Stop::None,
            })
            .collect();
        Self {
            axes,
            dt: f64::from(cfg.supervisor.cycle_us) * 1e-6,
        }
    }

    /// Exact raw position of axis `i` (tests).
    #[cfg(test)]
    fn position(&self, i: usize) -> f64 {
        self.axes[i].plant.position()
    }
}

impl Backend for SimBackend {
    fn name(&self) -> &str {
        "sim"
    }

    fn axis_count(&self) -> usize {
        self.axes.len()
    }

    fn axis_names(&self) -> Vec<String> {
        self.axes.iter().map(|a| a.name.clone()).collect()
    }

    fn apply(&mut self, cmd: &CommandFrame, fb: &mut FeedbackFrame) -> Result<(), ExchangeError> {
        let n = self.axes.len();
        for ((axis, wire), out) in self.axes.iter_mut().zip(&cmd.axes).zip(&mut fb.axes) {
            let c = axis_to_command(wire, axis.counts_per_unit);
            let f = axis.plant.step(&c, self.dt);
            *out = feedback_to_axis(&f, axis.counts_per_unit);
            axis.last = c;
            axis.stop = Stop::None;
        }
        fb.header.axis_count = n as u32;
        Ok(())
    }

    fn watchdog_stop(&mut self, dt_s: f64, fb: &mut FeedbackFrame) -> bool {
        let mut all = true;
        for axis in &mut self.axes {
            all &= axis.stop_step(dt_s);
        }
        self.status(fb);
        all
    }

    fn status(&self, fb: &mut FeedbackFrame) {
        for (axis, out) in self.axes.iter().zip(&mut fb.axes) {
            *out = feedback_to_axis(&axis.plant.feedback(), axis.counts_per_unit);
        }
        fb.header.axis_count = self.axes.len() as u32;
    }

    fn emergency_stop(&mut self, fb: &mut FeedbackFrame) {
        for axis in &mut self.axes {
            let fbk = axis.plant.feedback();
            if fbk.drive.enabled || axis.last.enable {
                axis.plant.inject_fault();
            }
            // zero-length step: velocity 0, faulted drive stays off (no edge)
            axis.plant.step(&axis.last, 0.0);
            axis.stop = Stop::Done;
        }
        self.status(fb);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion_frames::{command_to_axis, AxisCommand, SW_ENABLED, SW_FAULT};

    const TOML: &str = r#"
[supervisor]
cycle_us = 1000
service_prefix = "simtest"

[[axis]]
name = "X"
counts_per_unit = 1000.0
marker = true
home_sequence = "marker"
home_speed = 30.0
home_return_speed = 3.0
home_acceleration = 500.0
home_deceleration = 500.0

[axis.sim]
start = 0.0
marker_every = 10.0
marker_at = 2.5
enable_delay_cycles = 0

[[axis]]
name = "Y"
counts_per_unit = 100.0
home_sequence = "immediate"

[axis.sim]
start = 1.0
"#;

    fn backend() -> SimBackend {
        let cfg = motion_config::parse(TOML).unwrap();
        SimBackend::new(&cfg)
    }

    fn frame(axes: &[Command], cpu: &[f64]) -> CommandFrame {
        let mut f = CommandFrame::ZERO;
        f.header.axis_count = axes.len() as u32;
        for (i, (c, k)) in axes.iter().zip(cpu).enumerate() {
            f.axes[i] = command_to_axis(c, *k);
        }
        f
    }

    fn on(position: f64, velocity: f64) -> Command {
        Command {
            enable: true,
            position,
            velocity,
            torque_limit_positive: 100.0,
            torque_limit_negative: 100.0,
            ..Command::default()
        }
    }

    #[test]
    fn follows_in_counts_and_latches_exactly() {
        let mut b = backend();
        assert_eq!(b.axis_count(), 2);
        assert_eq!(b.axis_names(), ["X", "Y"]);
        let mut fb = FeedbackFrame::ZERO;
        for k in 0..100 {
            let mut x = on(k as f64 * 0.03, 30.0);
            x.marker_arm.id = 1;
            let f = frame(&[x, Command::default()], &[1000.0, 100.0]);
            b.exchange(&f, &mut fb).unwrap();
            assert_eq!(fb.header.axis_count, 2);
            assert_eq!(fb.axes[0].position, f.axes[0].target_position);
            assert_eq!(fb.axes[0].status_word, SW_ENABLED);
            assert_eq!(fb.axes[1].position, 100); // Y at rest at 1.0, 100 counts/unit
            assert_eq!(fb.axes[0].marker_latch_id, 1);
            let crossed = f.axes[0].target_position >= 2500;
            assert_eq!(fb.axes[0].marker_latched != 0, crossed, "k {k}");
            if crossed {
                assert_eq!(fb.axes[0].marker_latch_position, 2500);
            }
        }
    }

    #[test]
    fn axis_count_mismatch_is_not_applied() {
        let mut b = backend();
        let mut fb = FeedbackFrame::ZERO;
        let f = frame(&[on(5.0, 0.0)], &[1000.0]);
        let e = b.exchange(&f, &mut fb).unwrap_err();
        assert_eq!(e, ExchangeError::AxisCountMismatch { frame: 1, ours: 2 });
        assert!(e.to_string().starts_with(
            "command frame has 1 axes, config has 2: ignoring commands (are both processes"
        ));
        assert_eq!(fb.header.axis_count, 2);
        assert_eq!(b.position(0), 0.0);
        assert_eq!(fb.axes[1].position, 100);
    }

    #[test]
    fn watchdog_ramps_down_then_faults_and_resume_needs_the_handshake() {
        let mut b = backend();
        let mut fb = FeedbackFrame::ZERO;
        let mut p = 0.0;
        for _ in 0..50 {
            p += 0.03;
            b.exchange(
                &frame(&[on(p, 30.0), Command::default()], &[1000.0, 100.0]),
                &mut fb,
            )
            .unwrap();
        }
        let start = b.position(0);
        let mut cycles = 0;
        let mut last_v = 30.0 * 1000.0;
        while !b.watchdog_stop(0.001, &mut fb) {
            cycles += 1;
            assert!(cycles < 1000);
            // monotonic deceleration, still enabled
            assert!(fb.axes[0].velocity <= last_v + 1e-6);
            assert_eq!(fb.axes[0].status_word, SW_ENABLED);
            last_v = fb.axes[0].velocity;
        }
        // 30 units/s at 500 units/s²: 60 cycles of 0.5 units/s each
        assert_eq!(cycles, 59);
        let travelled = b.position(0) - start;
        let ideal = 30.0 * 30.0 / (2.0 * 500.0);
        assert!((travelled - ideal).abs() < 0.03 + 1e-9, "{travelled}");
        assert_eq!(fb.axes[0].velocity, 0.0);
        assert_eq!(fb.axes[0].status_word, SW_FAULT);
        // the axis never asked to be enabled: untouched
        assert_eq!(fb.axes[1].status_word, 0);
        // stays put
        let at = b.position(0);
        assert!(b.watchdog_stop(0.001, &mut fb));
        assert_eq!(b.position(0), at);
        assert_eq!(fb.axes[0].status_word, SW_FAULT);

        // resume: enable still true -> no edge -> fault stays
        let cpu = [1000.0, 100.0];
        b.exchange(&frame(&[on(at, 0.0), Command::default()], &cpu), &mut fb)
            .unwrap();
        assert_eq!(fb.axes[0].status_word, SW_FAULT);
        // false -> true resets
        let off = Command {
            position: at,
            ..Command::default()
        };
        b.exchange(&frame(&[off, Command::default()], &cpu), &mut fb)
            .unwrap();
        b.exchange(&frame(&[on(at, 0.0), Command::default()], &cpu), &mut fb)
            .unwrap();
        assert_eq!(fb.axes[0].status_word, SW_ENABLED);
    }

    /// MAFR: the rising edge of `CW_FAULT_RESET` clears the
    /// plant's fault and enables nothing; the enable needs its own rising
    /// edge after that.
    #[test]
    fn a_fault_reset_in_the_control_word_clears_the_fault_and_enables_nothing() {
        let mut b = backend();
        let mut fb = FeedbackFrame::ZERO;
        let cpu = [1000.0, 100.0];
        b.exchange(&frame(&[on(1.0, 0.0), Command::default()], &cpu), &mut fb)
            .unwrap();
        assert!(b.watchdog_stop(0.001, &mut fb));
        assert_eq!(fb.axes[0].status_word, SW_FAULT);
        let reset = Command {
            position: 1.0,
            fault_reset: true,
            ..Command::default()
        };
        let off = Command {
            position: 1.0,
            ..Command::default()
        };
        let f = frame(&[reset, Command::default()], &cpu);
        assert_eq!(f.axes[0].control_word, motion_frames::CW_FAULT_RESET);
        b.exchange(&f, &mut fb).unwrap();
        assert_eq!(fb.axes[0].status_word, 0, "no fault, not enabled");
        b.exchange(&frame(&[off, Command::default()], &cpu), &mut fb)
            .unwrap();
        assert_eq!(fb.axes[0].status_word, 0);
        b.exchange(&frame(&[on(1.0, 0.0), Command::default()], &cpu), &mut fb)
            .unwrap();
        assert_eq!(fb.axes[0].status_word, SW_ENABLED);
        assert_eq!(b.position(0), 1.0, "nothing moved");
    }

    #[test]
    fn standstill_stops_in_one_cycle_and_garbage_is_bounded() {
        let mut b = backend();
        let mut fb = FeedbackFrame::ZERO;
        let cpu = [1000.0, 100.0];
        b.exchange(&frame(&[on(1.0, 0.0), on(1.0, 0.0)], &cpu), &mut fb)
            .unwrap();
        // Y has the default two-cycle enable delay: not enabled yet
        assert_eq!(fb.axes[1].status_word, 0);
        assert!(b.watchdog_stop(0.001, &mut fb));
        assert_eq!(fb.axes[0].status_word, SW_FAULT);
        assert_eq!(fb.axes[1].status_word, SW_FAULT, "enable was requested");

        // an absurd velocity feed-forward: the bounded shutdown falls back
        let mut b = backend();
        let mut f = frame(&[on(0.0, 0.0), Command::default()], &cpu);
        b.exchange(&f, &mut fb).unwrap();
        f.axes[0] = AxisCommand {
            target_velocity: 1e300,
            ..f.axes[0]
        };
        b.exchange(&f, &mut fb).unwrap();
        assert!(!b.shutdown(0.001, &mut fb));
        assert_eq!(fb.axes[0].status_word, SW_FAULT);
        assert_eq!(fb.axes[0].velocity, 0.0);

        // and a dt that is not a time stops at once
        let mut b = backend();
        b.exchange(&frame(&[on(0.0, 50.0), Command::default()], &cpu), &mut fb)
            .unwrap();
        assert!(b.watchdog_stop(f64::NAN, &mut fb));
        assert_eq!(fb.axes[0].status_word, SW_FAULT);
    }

    /// Fuzzed: command frames of any content (as a forger holding
    /// the key could send; the ports checked key and layout), in any order
    /// with watchdog and emergency stops: no panic, and the feedback the
    /// drives give back stays a reading (finite, never the no-number
    /// sentinel).
    #[test]
    fn any_command_frame_never_breaks_the_drives() {
        use motion_frames::{INVALID_COUNTS, MAX_AXES};
        use proptest::prelude::*;
        use proptest::test_runner::{Config, TestRunner};

        #[derive(Clone, Debug)]
        enum Step {
            /// Any bytes in the two axes' commands (a right axis count
            /// unless `count` is given).
            Exchange {
                bytes: Vec<u8>,
                count: Option<u32>,
            },
            Watchdog(f64),
            Emergency,
        }
        let axis = std::mem::size_of::<AxisCommand>();
        let step = prop_oneof![
            6 => (
                prop::collection::vec(any::<u8>(), 0..=2 * axis),
                prop::option::weighted(0.1, any::<u32>()),
            )
                .prop_map(|(bytes, count)| Step::Exchange { bytes, count }),
            1 => prop_oneof![Just(0.001), Just(f64::NAN), Just(-1.0), Just(1e300), any::<f64>()]
                .prop_map(Step::Watchdog),
            1 => Just(Step::Emergency),
        ];
        let mut runner = TestRunner::new(Config {
            cases: 128,
            failure_persistence: None,
            ..Config::default()
        });
        runner
            .run(&prop::collection::vec(step, 1..40), |steps| {
                let mut b = backend();
                let mut fb = FeedbackFrame::ZERO;
                // Moving first: garbage arrives mid-motion.
                for k in 0..20 {
                    let f = frame(&[on(k as f64 * 0.03, 30.0), on(1.0, 0.0)], &[1000.0, 100.0]);
                    b.exchange(&f, &mut fb).unwrap();
                }
                for st in &steps {
                    match st {
                        Step::Exchange { bytes, count } => {
                            let mut f = CommandFrame::ZERO;
                            f.header.axis_count = count.unwrap_or(2);
                            let n = bytes.len().min(MAX_AXES * axis);
                            // SAFETY: AxisCommand is a repr(C) struct of
                            // integers and floats (as on the wire): every bit
                            // pattern is a value; the write stays in `axes`.
                            unsafe {
                                std::ptr::copy_nonoverlapping(
                                    bytes.as_ptr(),
                                    f.axes.as_mut_ptr().cast::<u8>(),
                                    n,
                                );
                            }
                            let _ = b.exchange(&f, &mut fb);
                        }
                        Step::Watchdog(dt) => {
                            b.watchdog_stop(*dt, &mut fb);
                        }
                        Step::Emergency => b.emergency_stop(&mut fb),
                    }
                    for (i, a) in fb.axes[..2].iter().enumerate() {
                        prop_assert_ne!(a.position, INVALID_COUNTS, "axis {}: {:?}", i, a);
                        prop_assert!(a.velocity.is_finite() && a.torque.is_finite(), "{a:?}");
                        prop_assert!(b.position(i).is_finite());
                    }
                }
                Ok(())
            })
            .unwrap();
    }
}
