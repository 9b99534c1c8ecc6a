//! Property tests: random machines, speeds, accelerations and cycle times.
//!
//! * bidirectional sequences end at Home Position with raw final = event + offset;
//! * the event lies within the precision bound of spec §6 (markers, torque and
//!   registration exact; a sampled switch within speed × cycle / 2);
//! * the commanded profile never exceeds its speed, acceleration or deceleration;
//! * unidirectional sequences never reverse;
//! * every abort restores the torque limits and error tolerances;
//! * NaN / inf / absurd feedback never produces a non-finite command.
//!
//! The worst event error is printed (`cargo test -- --nocapture`) in units and
//! as a fraction of speed × cycle.

mod common;

use common::{run, run_with, runner, Outcome};
use motion_homing::codes::*;
use motion_homing::*;
use motion_plant::PlantConfig;
use proptest::prelude::*;
use std::sync::Mutex;

#[derive(Clone, Debug)]
struct Machine {
    seq: HomeSequence,
    forward: bool,
    cycle_s: f64,
    v: f64,
    r: f64,
    acc: f64,
    dec: f64,
    sw_lo: f64,
    sw_width: f64,
    nc: bool,
    registration: bool,
    marker_at: f64,
    marker_every: f64,
    offset: f64,
    home_position: f64,
    /// Distance from the start to the switch (or the hard stop) side.
    approach: f64,
    hard_stop: f64,
    torque_time: f64,
}

fn machine(seqs: &'static [HomeSequence]) -> impl Strategy<Value = Machine> {
    (
        (
            prop::sample::select(seqs),
            any::<bool>(),
            prop::sample::select(&[0.00025, 0.0005, 0.001, 0.002][..]),
            5.0..40.0f64,
            0.05..1.0f64, // return speed as a fraction of home speed
            50.0..5000.0f64,
            50.0..5000.0f64,
        ),
        (
            -20.0..20.0f64,
            1.0..10.0f64,
            any::<bool>(),
            any::<bool>(),
            0.0..1.0f64, // marker phase as a fraction of the spacing
            1.0..20.0f64,
        ),
        (
            -10.0..10.0f64,
            -50.0..50.0f64,
            2.0..30.0f64,
            70.0..100.0f64, // hard stops beyond every start (|start| <= 60)
            0.0..0.02f64,
        ),
    )
        .prop_map(
            |(
                (seq, forward, cycle_s, v, rf, acc, dec),
                (sw_lo, sw_width, nc, registration, phase, marker_every),
                (offset, home_position, approach, hard_stop, torque_time),
            )| Machine {
                seq,
                forward,
                cycle_s,
                v,
                r: v * rf,
                acc,
                dec,
                sw_lo,
                sw_width,
                nc,
                registration,
                marker_at: phase * marker_every,
                marker_every,
                offset,
                home_position,
                approach,
                hard_stop,
                torque_time,
            },
        )
}

impl Machine {
    fn dir(&self) -> f64 {
        if self.forward {
            1.0
        } else {
            -1.0
        }
    }

    fn sw_hi(&self) -> f64 {
        self.sw_lo + self.sw_width
    }

    fn start(&self) -> f64 {
        if self.seq.uses_torque() {
            return 0.0;
        }
        if self.forward {
            self.sw_lo - self.approach
        } else {
            self.sw_hi() + self.approach
        }
    }

    fn config(&self, direction: HomeDirection) -> AxisConfig {
        AxisConfig {
            counts_per_unit: 1000.0,
            marker: true,
            registration: self.registration,
            home_direction: direction,
            home_sequence: self.seq,
            home_switch_normally_closed: self.nc,
            home_position: self.home_position,
            home_offset: self.offset,
            home_speed: self.v,
            home_return_speed: self.r,
            home_acceleration: self.acc,
            home_deceleration: self.dec,
            // Above the plant's acceleration torque (0.01 %/(u/s²) x 5000 +
            // 1 % friction = 51 %): a threshold below it trips on the first
            // acceleration when the torque time is 0, as it would on a machine.
            home_torque_level: 80.0,
            home_torque_threshold: 60.0,
            home_torque_time: self.torque_time,
            torque_limit: 300.0,
            travel_limits: Some((-200.0, 200.0)),
            ..AxisConfig::default()
        }
    }

    fn plant(&self) -> PlantConfig {
        PlantConfig {
            start: self.start(),
            switch: Some((self.sw_lo, self.sw_hi())),
            switch_normally_closed: self.nc,
            marker_every: self.marker_every,
            marker_at: self.marker_at,
            hard_stop: Some((-self.hard_stop, self.hard_stop)),
            ..PlantConfig::default()
        }
    }

    /// First marker strictly beyond `x` going in direction `s`.
    fn marker_beyond(&self, x: f64, s: f64) -> f64 {
        let k = (x - self.marker_at) / self.marker_every;
        let k = if s > 0.0 {
            k.floor() + 1.0
        } else {
            k.ceil() - 1.0
        };
        self.marker_at + k * self.marker_every
    }

    /// Distance from the switch edge at `edge` to the nearest marker.
    fn marker_clearance(&self, edge: f64) -> f64 {
        let k = ((edge - self.marker_at) / self.marker_every).round();
        (edge - (self.marker_at + k * self.marker_every)).abs()
    }
}

/// Worst event error seen by one property: (units, fraction of speed × cycle, case).
#[derive(Default)]
struct Worst(Mutex<(f64, f64, f64, String)>);

impl Worst {
    fn note(&self, err: f64, speed: f64, cycle: f64, what: String) {
        let frac = err / (speed * cycle);
        let mut w = self.0.lock().unwrap();
        if frac > w.1 || (frac == w.1 && err > w.0) {
            *w = (err, frac, w.2.max(err), what);
        } else {
            w.2 = w.2.max(err);
        }
    }

    fn report(&self, name: &str) {
        let w = self.0.lock().unwrap();
        println!(
            "{name}: worst event error {:.6} units = {:.3} x speed x cycle \
             (largest absolute {:.6} units); case {}",
            w.0, w.1, w.2, w.3
        );
    }
}

/// Speed, acceleration and deceleration of the sampled command never exceed
/// the limits (tiny rounding slack).
fn check_limits(o: &Outcome, cycle: f64, vmax: f64, acc: f64, dec: f64) -> Result<(), String> {
    let p: Vec<f64> = o.commands.iter().map(|c| c.position).collect();
    let v: Vec<f64> = p.windows(2).map(|w| (w[1] - w[0]) / cycle).collect();
    for (k, s) in v.iter().enumerate() {
        if s.abs() > vmax * (1.0 + 1e-9) + 1e-6 {
            return Err(format!("speed {s} > {vmax} at cycle {k}"));
        }
    }
    for (k, w) in v.windows(2).enumerate() {
        let a = (w[1] - w[0]) / cycle;
        let lim = if w[0] * w[1] < 0.0 {
            acc.max(dec)
        } else if w[1].abs() > w[0].abs() {
            acc
        } else {
            dec
        };
        if a.abs() > lim * (1.0 + 1e-6) + 1e-3 {
            return Err(format!("acceleration {a} > {lim} at cycle {k}"));
        }
    }
    Ok(())
}

#[test]
fn bidirectional_ends_at_home_position() {
    use HomeSequence::*;
    const SEQS: &[HomeSequence] = &[Switch, Marker, SwitchThenMarker, Torque, TorqueThenMarker];
    let worst = Worst::default();
    runner(256)
        .run(&machine(SEQS), |m| {
            let dir = if m.forward {
                HomeDirection::BidirectionalForward
            } else {
                HomeDirection::BidirectionalReverse
            };
            let s = m.dir();
            // The edge the sequence keys on: the near side of the switch.
            let edge = if m.forward { m.sw_lo } else { m.sw_hi() };
            if m.seq == SwitchThenMarker {
                // A marker within the switch's sampling uncertainty of its edge
                // is ambiguous by nature; installations keep them apart.
                prop_assume!(m.marker_clearance(edge) > 2.0 * m.r * m.cycle_s);
            }
            let hs = m.hard_stop * s;
            if m.seq.uses_torque() {
                // Home Position must not lie inside the hard stop for PC.
                prop_assume!(m.offset * s < 0.0);
            }
            let (truth, tol, speed) = match m.seq {
                Switch if m.registration => (edge, 1e-9, m.r),
                Switch => (edge, m.r * m.cycle_s / 2.0 + 1e-9, m.r),
                Marker => (m.marker_beyond(m.start(), s), 1e-9, m.v),
                SwitchThenMarker => (m.marker_beyond(edge, -s), 1e-9, m.r),
                Torque => (hs, 1e-9, m.v),
                _ => (m.marker_beyond(hs, -s), 1e-9, m.r),
            };
            if m.seq == TorqueThenMarker {
                prop_assume!((truth + m.offset - hs) * s <= 0.0);
            }
            let cfg = m.config(dir);
            let o = run(cfg, m.plant(), m.cycle_s, 400.0);
            let st = o.status;
            prop_assert!(st.pc && st.homed && !st.er, "{st:?}");
            prop_assert_eq!(st.implausible, Implausible::default());
            let e = st.event_raw.unwrap();
            prop_assert!(
                (e - truth).abs() <= tol,
                "event {e} truth {truth} tol {tol}"
            );
            worst.note((e - truth).abs(), speed, m.cycle_s, format!("{m:?}"));
            let scale = 1e-9 * (1.0 + e.abs() + m.offset.abs());
            prop_assert!(
                (o.final_raw - (e + m.offset)).abs() <= scale,
                "final raw {} != event {e} + offset {}",
                o.final_raw,
                m.offset
            );
            prop_assert!((o.final_axis - m.home_position).abs() <= scale * 100.0);
            check_limits(&o, m.cycle_s, m.v.max(m.r), m.acc, m.dec).map_err(TestCaseError::fail)?;
            Ok(())
        })
        .unwrap();
    worst.report("bidirectional");
}

#[test]
fn unidirectional_never_reverses() {
    use HomeSequence::*;
    const SEQS: &[HomeSequence] = &[Switch, Marker, SwitchThenMarker];
    let worst = Worst::default();
    runner(256)
        .run(&(machine(SEQS), any::<bool>()), |(m, cyclic)| {
            let dir = if m.forward {
                HomeDirection::UnidirectionalForward
            } else {
                HomeDirection::UnidirectionalReverse
            };
            let s = m.dir();
            let mut cfg = m.config(dir);
            let mut plant = m.plant();
            if cyclic {
                cfg.travel = TravelMode::Cyclic;
                cfg.unwind = 50.0;
                cfg.home_position = m.home_position.rem_euclid(50.0);
                plant.marker_every = 50.0;
                plant.hard_stop = None;
            }
            let edge = if m.forward { m.sw_lo } else { m.sw_hi() };
            if m.seq == SwitchThenMarker {
                let mm = Machine {
                    marker_every: plant.marker_every,
                    ..m.clone()
                };
                prop_assume!(mm.marker_clearance(edge) > 2.0 * m.v * m.cycle_s);
            }
            let o = run(cfg, plant, m.cycle_s, 400.0);
            let st = o.status;
            prop_assert!(st.homed && !st.er && !st.ip, "{st:?}");
            prop_assert_eq!(st.implausible, Implausible::default());
            for w in o.commands.windows(2) {
                prop_assert!(
                    (w[1].position - w[0].position) * s >= -1e-12,
                    "reversed: {} -> {}",
                    w[0].position,
                    w[1].position
                );
            }
            let e = st.event_raw.unwrap();
            if m.seq == Switch {
                let tol = if m.registration {
                    1e-9
                } else {
                    m.v * m.cycle_s / 2.0 + 1e-9
                };
                prop_assert!((e - edge).abs() <= tol, "event {e} edge {edge}");
                worst.note((e - edge).abs(), m.v, m.cycle_s, format!("{m:?}"));
            }
            if cyclic {
                prop_assert!(st.pc, "a cyclic axis always gets there: {st:?}");
            }
            let scale = 1e-9 * (1.0 + o.final_raw.abs());
            if st.pc {
                let d = if cyclic {
                    let x = (o.final_axis - cfg.home_position).rem_euclid(50.0);
                    x.min(50.0 - x)
                } else {
                    (o.final_axis - cfg.home_position).abs()
                };
                // Zero offset on a linear axis: at rest past the event.
                if cyclic || m.offset != 0.0 {
                    prop_assert!(d <= scale * 1000.0, "final axis {}", o.final_axis);
                }
            } else {
                // Only when Home Position was behind or within the stopping distance.
                let stop = m.v * m.v / (2.0 * m.dec) + 2.0 * m.v * m.cycle_s;
                prop_assert!(
                    m.offset * s < stop + 1e-9,
                    "offset {} stop {stop}",
                    m.offset
                );
            }
            check_limits(&o, m.cycle_s, m.v, m.acc, m.dec).map_err(TestCaseError::fail)?;
            Ok(())
        })
        .unwrap();
    worst.report("unidirectional");
}

#[test]
fn passive_events_within_precision() {
    use HomeSequence::*;
    const SEQS: &[HomeSequence] = &[Switch, Marker, SwitchThenMarker];
    let worst = Worst::default();
    runner(256)
        .run(&(machine(SEQS), 0.5..20.0f64), |(m, speed)| {
            let s = m.dir();
            let edge = if m.forward { m.sw_lo } else { m.sw_hi() };
            let cfg = AxisConfig {
                configuration: AxisConfiguration::FeedbackOnly,
                home_mode: HomeMode::Passive,
                ..m.config(HomeDirection::BidirectionalForward)
            };
            let plant = PlantConfig {
                external_speed: speed * s,
                ..m.plant()
            };
            let (truth, tol) = match m.seq {
                Switch if m.registration => (edge, 1e-9),
                Switch => (edge, speed * m.cycle_s / 2.0 + 1e-9),
                Marker => (m.marker_beyond(m.start(), s), 1e-9),
                _ => {
                    prop_assume!(m.marker_clearance(edge) > 2.0 * speed * m.cycle_s);
                    (m.marker_beyond(edge, s), 1e-9)
                }
            };
            let o = run(cfg, plant, m.cycle_s, 400.0);
            prop_assert!(o.status.pc, "{:?}", o.status);
            let e = o.status.event_raw.unwrap();
            prop_assert!((e - truth).abs() <= tol, "event {e} truth {truth}");
            worst.note((e - truth).abs(), speed, m.cycle_s, format!("{m:?}"));
            let reads = o.axis_at_event.unwrap();
            prop_assert!((reads - (m.home_position - m.offset)).abs() < 1e-9);
            Ok(())
        })
        .unwrap();
    worst.report("passive");
}

#[derive(Clone, Copy, Debug)]
enum Cause {
    Stop,
    Timeout,
    Fault,
    /// Feedback missing for `n` cycles, then back.
    Dropout(usize),
    Nan,
    Shutdown,
}

#[test]
fn every_abort_restores_the_drive() {
    use HomeSequence::*;
    const SEQS: &[HomeSequence] = &[Torque, TorqueThenMarker, SwitchThenMarker, Marker];
    let cause = prop_oneof![
        Just(Cause::Stop),
        Just(Cause::Timeout),
        Just(Cause::Fault),
        (5usize..200).prop_map(Cause::Dropout),
        Just(Cause::Nan),
        Just(Cause::Shutdown),
    ];
    runner(256)
        .run(&(machine(SEQS), cause, 0.0..1.0f64), |(m, cause, when)| {
            let dir = if m.forward {
                HomeDirection::BidirectionalForward
            } else {
                HomeDirection::BidirectionalReverse
            };
            let mut cfg = m.config(dir);
            cfg.position_error_tolerance = 0.5;
            cfg.velocity_error_tolerance = 3.0;
            // How long the full sequence takes, to abort somewhere inside it.
            let full = run(cfg, m.plant(), m.cycle_s, 400.0);
            let at = ((full.cycles as f64) * when) as usize + 1;
            if let Cause::Timeout = cause {
                cfg.home_timeout = at as f64 * m.cycle_s;
            }
            let o = run_with(cfg, m.plant(), m.cycle_s, 400.0, |k, plant, mut fb, req| {
                match cause {
                    Cause::Stop => req.stop = k >= at,
                    Cause::Shutdown => req.shutdown = (at..at + 50).contains(&k),
                    Cause::Fault if k == at => plant.inject_fault(),
                    Cause::Dropout(n) if (at..at + n).contains(&k) => return None,
                    Cause::Nan if k == at => fb.torque = f64::NAN,
                    _ => {}
                }
                Some(fb)
            });
            let st = o.status;
            prop_assert!(!st.ip);
            // Either the abort came first (ER, not homed) or the sequence had
            // already finished (and a later loss of feedback may have cleared
            // HomedStatus, as it must; a later drive fault is an axis fault
            // at rest: ER with `faulted`, the reference kept).
            prop_assert!(st.dn, "{st:?}");
            // (A torque homing whose Home Position lies inside the hard stop
            // ends homed without PC by design — "homed, not at HP": a
            // drive fault after that end keeps the reference too.)
            if st.er && !st.pc && full.status.pc {
                prop_assert!(!st.homed, "{st:?}");
            }
            if st.er && st.pc {
                prop_assert!(st.faulted, "{st:?}");
            }
            let last = o.commands.last().unwrap();
            prop_assert_eq!(last.torque_limit_positive, cfg.torque_limit);
            prop_assert_eq!(last.torque_limit_negative, cfg.torque_limit);
            prop_assert_eq!(last.position_error_tolerance, 0.5);
            prop_assert_eq!(last.velocity_error_tolerance, 3.0);
            prop_assert!(o.commands.iter().all(|c| c.position.is_finite()));
            Ok(())
        })
        .unwrap();
}

#[test]
fn bad_feedback_never_becomes_a_bad_command() {
    use HomeSequence::*;
    const SEQS: &[HomeSequence] = &[Switch, Marker, SwitchThenMarker, Torque];
    let bad =
        prop::sample::select(&[f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300][..]);
    runner(256)
        .run(
            &(machine(SEQS), 0usize..6, bad, 1usize..3000, 1usize..20),
            |(m, field, value, at, len)| {
                let dir = if m.forward {
                    HomeDirection::BidirectionalForward
                } else {
                    HomeDirection::BidirectionalReverse
                };
                let cfg = m.config(dir);
                let mut homing_at_corruption = None;
                let mut axis = Axis::new(cfg);
                let mut plant = motion_plant::Plant::new(m.plant());
                let mut fb = plant.feedback();
                let req = Request {
                    home: true,
                    ..Request::default()
                };
                for k in 0..(at + len + 2000) {
                    let mut seen = fb;
                    if (at..at + len).contains(&k) {
                        match field {
                            0 => seen.position = value,
                            1 => seen.velocity = value,
                            2 => seen.torque = value,
                            3 => {
                                seen.marker_latch.latched = true;
                                seen.marker_latch.position = value;
                            }
                            4 => {
                                seen.switch_latch.latched = true;
                                seen.switch_latch.position = value;
                            }
                            _ => {
                                seen.position = value;
                                seen.torque = value;
                                seen.velocity = value;
                            }
                        }
                        if k == at {
                            homing_at_corruption = Some(axis.status().ip);
                        }
                    }
                    let now = (k as f64 * m.cycle_s * 1e9) as u64;
                    let cmd = axis.step(now, Some(&seen), &req);
                    for x in [
                        cmd.position,
                        cmd.velocity,
                        cmd.torque_limit_positive,
                        cmd.torque_limit_negative,
                        cmd.position_error_tolerance,
                        cmd.velocity_error_tolerance,
                    ] {
                        prop_assert!(x.is_finite(), "non-finite command {cmd:?} at {k}");
                    }
                    prop_assert!(cmd.position.abs() < 1e6, "absurd command {cmd:?}");
                    fb = plant.step(&cmd, m.cycle_s);
                }
                if homing_at_corruption == Some(true) {
                    let st = axis.status();
                    prop_assert!(st.er, "{st:?}");
                    prop_assert_eq!((st.err, st.exerr), (ERR_SERVO_MESSAGE, EX_FEEDBACK_INVALID));
                    prop_assert!(st.bad_attribute.is_some());
                }
                Ok(())
            },
        )
        .unwrap();
}
