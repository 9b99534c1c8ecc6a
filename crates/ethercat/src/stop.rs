//! The bounded stop of one drive: what the watchdog (commands stopped), the
//! shutdown (SIGTERM) and a refused set-point do, cycle by cycle. Pure.
//!
//! ```text
//!  quick stop ──at rest, or the drive left Quick stop active by itself──▶ (brake) ──▶ disable voltage
//!      │  └──────────── `quick_stop_timeout_ms` passed ──────────────────▶    │           (Switch on disabled:
//!      └── still Operation enabled after QS_ACK_CYCLES: quick stop ignored ──▶ │            power stage off)
//!                                                      brake: disable operation, `brake_delay_ms`
//! ```
//!
//! * **Quick stop** first: the drive decelerates on its own ramp (0x6085)
//!   and, depending on its quick stop option code (0x605A), ends in Switch
//!   on disabled by itself (1..4) or stays in Quick stop active holding the
//!   axis (5..8).
//! * **Disable voltage** at the end, always: once the drive is at rest
//!   (|v| below one count per cycle), when it has left Quick stop active by
//!   itself, when the bound passes, or at once when it ignores quick stop
//!   (still in Operation enabled [`QS_ACK_CYCLES`] after being told). The
//!   drive ends in Switch on disabled: power stage off.
//! * **A brake** (`ethercat_brake_delay_ms`, a vertical axis): between the
//!   two, *disable operation* (Operation enabled → Switched on: the drive
//!   closes its holding brake, 0x605C) for the brake delay with the power
//!   stage on; a drive in Quick stop active is held there meanwhile. Then
//!   disable voltage. The drive's own brake control does the closing; the
//!   backend only makes sure the power stage outlives it.
//!
//! * **Without data** ([`Stopper::step_blind`]: a frame lost, a working
//!   counter that cannot be trusted) the stop goes on, judged on time
//!   alone: quick stop until the bound, then (the brake, and) disable
//!   voltage. Nothing is concluded from a cycle not seen.
//!
//! The worst case from the first cycle of a stop to "disable voltage" sent
//! is `quick_stop_timeout_ms` + `brake_delay_ms` (+ one cycle); a drive that
//! answers takes a few cycles more to report Switch on disabled. With the
//! defaults (500 ms, no brake) that is well inside the 1 s the interface
//! promises after the watchdog fires.

use crate::cia402::{State, Target};

/// Cycles a drive may stay in Operation enabled after quick stop was sent
/// before it counts as ignoring quick stop (a drive takes one or two).
pub const QS_ACK_CYCLES: u32 = 10;

/// Where a stop is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// No stop asked for.
    Idle,
    /// Quick stop sent since `cycles`; `acked`: the drive left Operation
    /// enabled.
    QuickStop { cycles: u32, acked: bool },
    /// Disable operation (the brake closes), since `cycles`.
    Brake { cycles: u32 },
    /// Disable voltage.
    Off,
}

/// Why the quick stop ended (for the log and the tests).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ended {
    AtRest,
    LeftQuickStop,
    BoundPassed,
    Ignored,
    NotEnabled,
}

/// The stop of one drive, in cycles of the bus.
#[derive(Clone, Copy, Debug)]
pub struct Stopper {
    phase: Phase,
    /// `quick_stop_timeout_ms` in cycles.
    bound: u32,
    /// `brake_delay_ms` in cycles (0: no brake).
    brake: u32,
    ended: Option<Ended>,
}

impl Stopper {
    /// A stopper for a bus cycle of `cycle_s` seconds.
    pub fn new(cycle_s: f64, quick_stop_ms: u32, brake_ms: u32) -> Stopper {
        let cycles = |ms: u32| {
            if cycle_s > 0.0 {
                (f64::from(ms) * 1e-3 / cycle_s)
                    .ceil()
                    .clamp(0.0, f64::from(u32::MAX)) as u32
            } else {
                ms
            }
        };
        Stopper {
            phase: Phase::Idle,
            bound: cycles(quick_stop_ms).max(1),
            brake: cycles(brake_ms),
            ended: None,
        }
    }

    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// How the quick stop ended, once it has.
    pub fn ended(&self) -> Option<Ended> {
        self.ended
    }

    /// A stop of a drive that was enabled (or in Quick stop active) when it
    /// began is in progress or done, not yet reset.
    pub fn stopping(&self) -> bool {
        self.phase != Phase::Idle && self.ended != Some(Ended::NotEnabled)
    }

    /// No stop wanted (any more): the next one starts from the beginning.
    pub fn reset(&mut self) {
        self.phase = Phase::Idle;
        self.ended = None;
    }

    /// The stop is complete: disable voltage sent and the drive reports
    /// Switch on disabled (or a fault, whose reaction has ended).
    pub fn done(&self, state: State) -> bool {
        self.phase == Phase::Off
            && matches!(
                state,
                State::SwitchOnDisabled | State::NotReadyToSwitchOn | State::Fault
            )
    }

    /// One cycle of the stop: the drive's `state`, whether it is at rest;
    /// returns where the CiA 402 machine walks it.
    pub fn step(&mut self, state: State, at_rest: bool) -> Target {
        self.advance(state, at_rest, true)
    }

    /// One cycle of the stop without this cycle's data (`state`: the last
    /// one seen): the outputs still reach a drive whose data is missing
    /// (a working counter that cannot be trusted, a lost frame), but
    /// nothing can be concluded from it — not that it acknowledged, left
    /// or ignored the quick stop, nor that it is at rest. Only the bound
    /// ends the quick stop then; the brake's delay counts as it does.
    pub fn step_blind(&mut self, state: State) -> Target {
        self.advance(state, false, false)
    }

    fn advance(&mut self, state: State, at_rest: bool, seen: bool) -> Target {
        if self.phase == Phase::Idle {
            self.phase = if state.is_enabled() || state == State::QuickStopActive {
                Phase::QuickStop {
                    cycles: 0,
                    acked: state == State::QuickStopActive,
                }
            } else {
                self.ended = Some(Ended::NotEnabled);
                Phase::Off
            };
        }
        match self.phase {
            Phase::QuickStop { cycles, acked } => {
                let acked = acked || (seen && !state.is_enabled());
                let end = if !seen {
                    (cycles >= self.bound).then_some(Ended::BoundPassed)
                } else if state == State::QuickStopActive && at_rest {
                    Some(Ended::AtRest)
                } else if acked && state != State::QuickStopActive {
                    Some(Ended::LeftQuickStop)
                } else if !acked && cycles >= QS_ACK_CYCLES {
                    Some(Ended::Ignored)
                } else if cycles >= self.bound {
                    Some(Ended::BoundPassed)
                } else {
                    None
                };
                match end {
                    Some(e) => {
                        self.ended = Some(e);
                        self.after_quick_stop(state)
                    }
                    None => {
                        self.phase = Phase::QuickStop {
                            cycles: cycles + 1,
                            acked,
                        };
                        Target::QuickStop
                    }
                }
            }
            Phase::Brake { cycles } if cycles < self.brake && !power_off(state) => {
                self.phase = Phase::Brake { cycles: cycles + 1 };
                Target::DisableOperation
            }
            _ => {
                self.phase = Phase::Off;
                Target::Off
            }
        }
    }

    /// The quick stop is over: the brake's wait, or disable voltage.
    fn after_quick_stop(&mut self, state: State) -> Target {
        if self.brake > 0 && !power_off(state) {
            self.phase = Phase::Brake { cycles: 1 };
            Target::DisableOperation
        } else {
            self.phase = Phase::Off;
            Target::Off
        }
    }
}

/// The drive's power stage is off (or it is faulted, which takes it off).
pub fn power_off(state: State) -> bool {
    matches!(
        state,
        State::SwitchOnDisabled | State::NotReadyToSwitchOn | State::ReadyToSwitchOn | State::Fault
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use State::*;

    /// Runs `s` against a drive that goes through `states` (the last one
    /// repeats), at rest from cycle `rest`; returns the targets.
    fn run(s: &mut Stopper, states: &[State], rest: usize, n: usize) -> Vec<Target> {
        (0..n)
            .map(|k| s.step(states[k.min(states.len() - 1)], k >= rest))
            .collect()
    }

    #[test]
    fn a_drive_that_stops_on_its_ramp_is_disabled_at_rest() {
        let mut s = Stopper::new(0.001, 500, 0);
        let t = run(&mut s, &[OperationEnabled, QuickStopActive], 50, 52);
        assert!(t[..50].iter().all(|t| *t == Target::QuickStop));
        assert_eq!(t[50], Target::Off);
        assert_eq!(s.ended(), Some(Ended::AtRest));
        assert!(!s.done(QuickStopActive));
        assert!(s.done(SwitchOnDisabled));
        // 0x605A = 2: the drive goes to Switch on disabled by itself
        let mut s = Stopper::new(0.001, 500, 0);
        let t = run(
            &mut s,
            &[
                OperationEnabled,
                QuickStopActive,
                QuickStopActive,
                SwitchOnDisabled,
            ],
            1000,
            5,
        );
        assert_eq!(t[3], Target::Off);
        assert_eq!(s.ended(), Some(Ended::LeftQuickStop));
    }

    #[test]
    fn a_drive_that_ignores_quick_stop_is_disabled_after_qs_ack_cycles() {
        let mut s = Stopper::new(0.001, 500, 0);
        let t = run(&mut s, &[OperationEnabled], 1000, 20);
        let first_off = t.iter().position(|t| *t == Target::Off).unwrap();
        assert_eq!(first_off as u32, QS_ACK_CYCLES);
        assert_eq!(s.ended(), Some(Ended::Ignored));
    }

    #[test]
    fn a_quick_stop_that_never_ends_is_cut_at_the_bound() {
        // 200 ms at 1 ms: disable voltage in cycle 200
        let mut s = Stopper::new(0.001, 200, 0);
        let t = run(
            &mut s,
            &[OperationEnabled, QuickStopActive],
            usize::MAX,
            202,
        );
        assert_eq!(t.iter().position(|t| *t == Target::Off), Some(200));
        assert_eq!(s.ended(), Some(Ended::BoundPassed));
    }

    #[test]
    fn a_brake_gets_disable_operation_for_its_delay_first() {
        // 5 ms brake at 1 ms cycles
        let mut s = Stopper::new(0.001, 500, 5);
        let t = run(&mut s, &[OperationEnabled, QuickStopActive], 3, 12);
        assert_eq!(&t[..3], &[Target::QuickStop; 3]);
        assert_eq!(&t[3..8], &[Target::DisableOperation; 5]);
        assert_eq!(t[8], Target::Off);
        // ignoring quick stop: the brake delay still comes before the power
        let mut s = Stopper::new(0.001, 500, 5);
        let t = run(&mut s, &[OperationEnabled], 1000, 20);
        let k = QS_ACK_CYCLES as usize;
        assert_eq!(&t[k..k + 5], &[Target::DisableOperation; 5]);
        assert_eq!(t[k + 5], Target::Off);
    }

    #[test]
    fn without_data_only_the_bound_ends_the_quick_stop() {
        // 20 ms at 1 ms: a drive whose data is missing is told quick stop
        // until the bound, never judged as ignoring it, then disable voltage
        let mut s = Stopper::new(0.001, 20, 0);
        let t: Vec<Target> = (0..22).map(|_| s.step_blind(OperationEnabled)).collect();
        assert!(t[..20].iter().all(|t| *t == Target::QuickStop), "{t:?}");
        assert_eq!(t[20], Target::Off);
        assert_eq!(s.ended(), Some(Ended::BoundPassed));
        // data again in the middle: judged from there on (it still shows
        // Operation enabled after QS_ACK_CYCLES counted in all: ignored)
        let mut s = Stopper::new(0.001, 500, 0);
        for _ in 0..5 {
            assert_eq!(s.step_blind(OperationEnabled), Target::QuickStop);
        }
        let t = run(&mut s, &[OperationEnabled], 1000, 10);
        let first_off = t.iter().position(|t| *t == Target::Off).unwrap();
        assert_eq!(first_off as u32, QS_ACK_CYCLES - 5);
        assert_eq!(s.ended(), Some(Ended::Ignored));
        // a brake still gets its delay
        let mut s = Stopper::new(0.001, 3, 2);
        let t: Vec<Target> = (0..7).map(|_| s.step_blind(QuickStopActive)).collect();
        assert_eq!(
            t,
            [
                Target::QuickStop,
                Target::QuickStop,
                Target::QuickStop,
                Target::DisableOperation,
                Target::DisableOperation,
                Target::Off,
                Target::Off
            ]
        );
    }

    #[test]
    fn a_drive_not_enabled_is_disabled_at_once() {
        let mut s = Stopper::new(0.001, 500, 100);
        assert_eq!(s.step(ReadyToSwitchOn, true), Target::Off);
        assert_eq!(s.ended(), Some(Ended::NotEnabled));
        assert!(s.done(SwitchOnDisabled));
        s.reset();
        assert_eq!(s.phase(), Phase::Idle);
    }
}
