//! A drive that homes itself (CiA 402 mode 6): the command follows the
//! drive's readings while it homes (the drive is not following the
//! command), so the first command the drive follows again is never judged
//! as a step from a command it did not follow — whatever frame its
//! readings were in, whichever frames came late or not at all.
//!
//! The drive homes at 2 u/s from raw 40 towards its home point 10 units
//! away, redefines its position there (it reads 0 at the home point),
//! decelerates to rest past it, reports home attained and hands back to
//! cyclic position mode; the engine then moves to Home Position (the
//! drive's 0 + Home Offset 1).

use motion_homing::*;
use motion_monitor::{Cycle, Monitor};
use proptest::prelude::*;

const MS: u64 = 1_000_000;

fn cfg() -> AxisConfig {
    AxisConfig {
        counts_per_unit: 1000.0,
        drive_homing: true,
        home_sequence: HomeSequence::Switch,
        home_direction: HomeDirection::BidirectionalForward,
        home_speed: 2.0,
        home_return_speed: 1.0,
        home_acceleration: 100.0,
        home_deceleration: 100.0,
        home_position: 10.0,
        home_offset: 1.0,
        cycle_ns: MS,
        ..AxisConfig::default()
    }
}

/// The drive: homes at 2 u/s from 40 to its home point at 50 (old frame),
/// redefines its position there (0), decelerates to rest, reports attained
/// at rest; hands back `handback` cycles after the request dropped.
#[derive(Clone, Copy, Debug, Default)]
struct Drive {
    raw: f64,
    v: f64,
    enabled: bool,
    homing: DriveHoming,
    redefined: bool,
    dropped_for: u32,
    handback: u32,
    /// Its redefined position shows only from the frame in which homing
    /// mode ended (the frames in between read the old frame).
    late_redefinition: bool,
    /// Handed back: the command is followed once it is near.
    resync: bool,
}

impl Drive {
    fn feedback(&self) -> Feedback {
        let old_frame = self.late_redefinition && self.redefined && self.homing.active;
        Feedback {
            position: if old_frame { self.raw + 50.0 } else { self.raw },
            velocity: self.v,
            drive: DriveState {
                enabled: self.enabled,
                fault: false,
            },
            drive_homing: self.homing,
            ..Feedback::default()
        }
    }

    fn answer(&mut self, cmd: &Command) {
        self.enabled = cmd.enable;
        let dt = 0.001;
        if cmd.drive_home || (self.homing.active && !self.homing.attained) {
            self.homing.active = true;
            if !self.redefined {
                self.v = 2.0;
                self.raw += self.v * dt;
                if self.raw >= 50.0 {
                    self.raw -= 50.0;
                    self.redefined = true;
                }
            } else if self.v > 0.0 {
                self.v = (self.v - 100.0 * dt).max(0.0);
                self.raw += self.v * dt;
            } else {
                self.homing.attained = true;
            }
        } else if self.homing.active {
            self.dropped_for += 1;
            if self.dropped_for > self.handback {
                self.homing = DriveHoming::default();
                self.resync = true;
            }
        } else if cmd.enable {
            // back in cyclic position mode, its I/O process holds it until
            // the command is near (a command still at an older reading is
            // never jumped to)
            self.resync &= (cmd.position - self.raw).abs() > 0.02;
            if self.resync {
                return;
            }
            self.v = (cmd.position - self.raw) / dt;
            self.raw = cmd.position;
        }
    }
}

/// Plays a homing; `late`: cycles the feedback takes to reach the engine;
/// `lost(k)`: no frame in cycle k. Returns the monitor's trip, if any.
fn play(late: usize, handback: u32, lost: &dyn Fn(u64) -> bool) -> Result<(), String> {
    play_drive(
        Drive {
            raw: 40.0,
            handback,
            ..Drive::default()
        },
        late,
        lost,
    )
}

fn play_drive(d: Drive, late: usize, lost: &dyn Fn(u64) -> bool) -> Result<(), String> {
    play_tampered(d, late, lost, 0.0)
}

/// As [`play_drive`], the engine's commands from the first after the
/// drive's homing on moved by `jump` (a bug in the engine, played: a
/// profile started off the drive's position).
fn play_tampered(
    mut d: Drive,
    late: usize,
    lost: &dyn Fn(u64) -> bool,
    jump: f64,
) -> Result<(), String> {
    let (mut homing_before, mut handed_back) = (false, false);
    let mut axis = Axis::new(cfg());
    let mut mon = Monitor::new(&cfg());
    let mut queue: Vec<Feedback> = vec![d.feedback(); late + 1];
    let home = Request {
        home: true,
        ..Request::default()
    };
    for k in 0..12_000u64 {
        let req = if k < 5 { Request::default() } else { home };
        let fb = queue.remove(0);
        let fb = (!lost(k)).then_some(fb);
        let now = k * MS;
        let mut cmd = axis.step(now, fb.as_ref(), &req);
        let homing = axis.status().phase == Phase::DriveHoming;
        handed_back |= homing_before && !homing;
        if handed_back {
            cmd.position += jump;
        }
        homing_before = homing;
        let out = mon.check(&Cycle {
            now_ns: now,
            feedback: fb.as_ref(),
            request: &req,
            status: axis.status(),
            reference: axis.reference_offset(),
            command: &cmd,
            io_restarted: false,
        });
        if let Some(t) = mon.tripped() {
            return Err(format!("k {k}: {t:?} {:?} {:?}", axis.status().phase, d));
        }
        d.answer(&out);
        queue.push(d.feedback());
        if k > 100 && !axis.status().ip {
            let s = axis.status();
            return if s.pc { Ok(()) } else { Err(format!("{s:?}")) };
        }
    }
    Err("never ended".into())
}

#[test]
fn a_drive_homing_with_frames_on_time_or_late_never_trips() {
    for late in 0..4 {
        for handback in 0..4 {
            play(late, handback, &|_| false).unwrap();
        }
    }
}

/// The redefined position first shows in the frame in which the drive
/// left homing mode: the last command of the homing (at the old frame's
/// reading) and the first the drive follows (at the new one) are 50 units
/// apart, and the drive never was at the former — no step of the drive.
#[test]
fn the_position_redefined_in_the_frame_that_ends_homing_mode_is_no_step() {
    for late in 0..3 {
        let d = Drive {
            raw: 40.0,
            handback: 1,
            late_redefinition: true,
            ..Drive::default()
        };
        play_drive(d, late, &|_| false).unwrap_or_else(|e| panic!("late {late}: {e}"));
    }
}

/// The first command after the drive's homing is still judged: from where
/// the drive is. A profile that starts off the drive's position trips the
/// step check (0.1 in a cycle: 100 u/s against the homing speeds' 2) —
/// its later steps are all in bounds.
#[test]
fn a_jump_away_from_the_drive_at_the_hand_back_trips_the_step_check() {
    for late_redefinition in [false, true] {
        let d = Drive {
            raw: 40.0,
            handback: 1,
            late_redefinition,
            ..Drive::default()
        };
        let r = play_tampered(d, 1, &|_| false, 0.1);
        assert!(
            r.as_ref().is_err_and(|e| e.contains("invariant: Step")),
            "{r:?}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// Frames lost around the hand-back (every `every`-th cycle, `n`
    /// times, from cycle `from`), frames `late` cycles late.
    #[test]
    fn frames_lost_around_the_hand_back_never_trip(
        late in 0usize..4,
        handback in 0u32..4,
        from in 5000u64..5200,
        n in 1u64..6,
        every in 1u64..4,
    ) {
        let lost = |k: u64| k >= from && k < from + n * every && (k - from) % every == 0;
        let r = play(late, handback, &lost);
        prop_assert!(r.is_ok(), "{:?}", r);
    }
}
