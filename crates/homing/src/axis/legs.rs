//! Running the legs of a plan: how each leg starts, what its find means, and
//! what follows when it ends.
//!
//! * **Hard stops.** After a torque event the command has run past the wall by
//!   the following error plus the stopping distance. Before anything else the
//!   command is *released*: moved back onto the actual position at Home Return
//!   Speed (a profile, not a jump), so the drive's torque falls to zero before
//!   its limits are restored.
//! * **Offsets** (spec §3): at the event the axis position is redefined so the
//!   event point reads Home Position − Home Offset; the move home then goes to
//!   event + offset (raw).

use super::intake::Sample;
use super::state::{Homing, Run, State};
use super::{Abort, Axis};
use crate::codes::ERR_AMBIGUOUS_MARKER;
use crate::config::{HomeMode, TravelMode};
use crate::plan::{find_at, first_return, plan_for, Find, Goal, Leg};
use crate::position::{ahead_cyclic, nearest_cyclic};
use crate::profile::{reaches_without_reversing, stopping_distance, Profile};

impl Axis {
    /// The configured sequence, with the drive ready: its first leg.
    pub(super) fn begin(&mut self, now: u64, s: &Sample) {
        let plan = plan_for(&self.cfg);
        let mut first = 0;
        if self.cfg.home_mode == HomeMode::Active {
            if self.cfg.home_sequence.uses_torque() {
                self.overrides = true;
            }
            // (the drive's own homing starts with its leg, whatever the switch)
            let by_us = !self.cfg.drive_homing;
            if by_us && self.cfg.home_sequence.uses_switch() && s.switch_active {
                if self.cfg.home_direction.is_unidirectional() {
                    // Establish the event where we stand, then go on if the
                    // unidirectional constraint allows.
                    self.event(now, s.fb.position);
                    first = 1;
                } else {
                    // Already on the switch: start with the return leg.
                    first = first_return(plan);
                }
            }
        }
        self.state = State::Homing(Homing::new(plan, first));
        self.enter_leg(now, s);
    }

    /// The current leg is next: it starts now, unless a coordinator holds the
    /// axis at the barrier (`Request::hold`) and the leg would start motion
    /// from rest; then the axis waits there, reporting how long its move home
    /// would take at least.
    fn enter_leg(&mut self, now: u64, s: &Sample) {
        let State::Homing(h) = self.state else {
            return;
        };
        let Some(leg) = h.current() else {
            return;
        };
        let (p, v) = self.profile.sample(now);
        if self.request.hold && leg.moves() && v == 0.0 {
            let min_move_ns = self.home_move(&h, leg, p, v).map_or(0, |(target, speed)| {
                Profile::move_to(
                    now,
                    p,
                    v,
                    target,
                    speed,
                    self.cfg.home_acceleration,
                    self.cfg.home_deceleration,
                )
                .duration_ns()
            });
            if let State::Homing(h) = &mut self.state {
                h.run = Run::Waiting { min_move_ns };
            }
            // At rest: hold exactly here, whatever profile brought the axis.
            self.profile.set(Profile::hold(now, p));
            return;
        }
        self.start_leg(now, s);
    }

    /// Starts the current leg of the running sequence (completes it when the
    /// plan is done).
    pub(super) fn start_leg(&mut self, now: u64, s: &Sample) {
        let State::Homing(h) = self.state else {
            return;
        };
        let Some(leg) = h.current() else {
            return;
        };
        let (p, v) = self.profile.sample(now);
        let run = match leg {
            Leg::Seek(goal) => {
                let search = self.begin_search(goal, p);
                self.profile
                    .set(self.jog(now, self.dir * self.cfg.home_speed));
                Run::Search(search)
            }
            Leg::Return(goal) | Leg::Pass(goal) => {
                let mut search = self.begin_search(goal, p);
                if goal != Goal::Marker && s.switch_active {
                    search.seen_active = true;
                    self.arm_switch(false);
                }
                // Back past the home switch after a limit: at Home Speed, a
                // search like the first seek.
                let speed = if matches!(leg, Leg::Pass(_)) {
                    self.cfg.home_speed
                } else {
                    self.cfg.home_return_speed
                };
                self.profile.set(self.jog(now, -self.dir * speed));
                Run::Search(search)
            }
            Leg::Creep => {
                // Back over the rough marker, whichever side of it we stopped.
                let target = h.rough_marker.unwrap_or(p);
                let dir = if target >= p { 1.0 } else { -1.0 };
                let search = self.begin_search(Goal::Marker, p);
                self.profile
                    .set(self.jog(now, dir * self.cfg.home_creep_speed));
                Run::Search(search)
            }
            Leg::Watch(goal) => Run::Search(self.begin_search(goal, s.fb.position)),
            Leg::DriveHomes => self.start_drive_homing(now, s),
            Leg::Stop | Leg::StopAtLimit => {
                self.profile
                    .set(Profile::stop(now, p, v, self.cfg.home_deceleration));
                Run::Profile { to_home: false }
            }
            Leg::Release => {
                self.profile.set(self.release_profile(now, s.fb.position));
                Run::Profile { to_home: false }
            }
            Leg::Restore => {
                self.overrides = false;
                return self.next_leg(now, s, true);
            }
            Leg::MoveHome => match self.home_move(&h, leg, p, v) {
                // Home Position inside the hard stop: stay; homed, not at HP.
                None => return self.complete(now, false),
                Some((target, speed)) => {
                    self.profile.set(self.home_profile(now, target, speed));
                    Run::Profile { to_home: true }
                }
            },
            Leg::Continue => match self.home_move(&h, leg, p, v) {
                Some((target, speed)) => {
                    self.profile.set(self.home_profile(now, target, speed));
                    Run::Profile { to_home: true }
                }
                None => {
                    self.profile
                        .set(Profile::stop(now, p, v, self.cfg.home_deceleration));
                    Run::Profile { to_home: false }
                }
            },
        };
        if let State::Homing(h) = &mut self.state {
            h.run = run;
        }
    }

    /// The current leg ended. `pc`: the PC the sequence gets if this was its
    /// last leg.
    pub(super) fn next_leg(&mut self, now: u64, s: &Sample, pc: bool) {
        let State::Homing(h) = &mut self.state else {
            return;
        };
        h.leg += 1;
        if h.leg >= h.plan.len() {
            return self.complete(now, pc);
        }
        self.enter_leg(now, s);
    }

    /// The current search leg found its goal at raw position `at`.
    pub(super) fn found(&mut self, now: u64, s: &Sample, at: f64) {
        let State::Homing(h) = &mut self.state else {
            return;
        };
        let leg = h.plan[h.leg];
        if leg.goal() == Some(Goal::Torque) {
            h.hard_stop = Some(at);
        }
        match find_at(h.plan, h.leg) {
            Find::Rough => h.rough_marker = Some(at),
            Find::Event if self.refuses_marker(at) => {
                return self.fail(now, ERR_AMBIGUOUS_MARKER, 0, Abort::Controlled);
            }
            Find::Event => self.event(now, at),
            Find::Waypoint => {}
        }
        self.next_leg(now, s, true);
    }

    /// Switch then marker: a marker closer than `marker_min_distance` to the
    /// switch edge is ambiguous (the edge's own uncertainty could put the
    /// neighbouring marker first). Sets the warning; true when the
    /// configuration refuses it.
    fn refuses_marker(&mut self, marker: f64) -> bool {
        let Some(edge) = self.status.switch_edge_raw else {
            return false;
        };
        let min = self.cfg.marker_min_distance;
        if !(min > 0.0 && (marker - edge).abs() < min) {
            return false;
        }
        self.status.ambiguous_marker = true;
        self.cfg.refuse_ambiguous_marker
    }

    /// The current profile leg reached its end.
    pub(super) fn profile_done(&mut self, now: u64, s: &Sample, to_home: bool) {
        // A continue leg that only stopped still completes with PC when the
        // offset is zero: the axis rests past the event, which is where a
        // zero offset puts Home Position on a linear axis.
        let pc = to_home || self.cfg.home_offset == 0.0;
        self.next_leg(now, s, pc);
    }

    /// The home event at raw position `e`: redefine the axis position so the
    /// event point reads Home Position − Home Offset (spec §3).
    pub(super) fn event(&mut self, now: u64, e: f64) {
        self.status.event_raw = Some(e);
        self.status.event_command = Some(self.profile.sample(now).0);
        self.offset = self.cfg.home_position - self.cfg.home_offset - e;
        self.shift = 0.0;
        self.latches.disarm();
    }

    /// The move to Home Position that leg `leg` (move home or continue)
    /// makes from command state `(p, v)`: target (raw) and speed. `None`: no
    /// move — Home Position lies inside the hard stop (torque sequences), or
    /// a unidirectional axis cannot reach it without reversing (it stops).
    fn home_move(&self, h: &Homing, leg: Leg, p: f64, v: f64) -> Option<(f64, f64)> {
        match leg {
            Leg::MoveHome => {
                let target = self.home_target_bidirectional(p);
                let inside_stop = h
                    .hard_stop
                    .is_some_and(|stop| (target - stop) * self.dir > 0.0);
                (!inside_stop).then_some((target, self.cfg.home_return_speed))
            }
            Leg::Continue => {
                let target = self.home_target_unidirectional(p, v);
                let forward = (target - p) * self.dir >= 0.0;
                (forward && reaches_without_reversing(p, v, target, self.cfg.home_deceleration))
                    .then_some((target, self.cfg.home_speed))
            }
            _ => None,
        }
    }

    /// The move to Home Position: time-optimal, or from rest lasting exactly
    /// `Request::move_duration_ns` when a coordinator asks for it.
    fn home_profile(&self, now: u64, target: f64, speed: f64) -> Profile {
        let (p, v) = self.profile.sample(now);
        let duration = self.request.move_duration_ns;
        if duration > 0 && v == 0.0 {
            Profile::move_to_in(
                now,
                p,
                target,
                duration,
                speed,
                self.cfg.home_acceleration,
                self.cfg.home_deceleration,
            )
        } else {
            self.move_to(now, target, speed)
        }
    }

    /// Home Position of a bidirectional sequence, raw: event + offset, the
    /// nearest one (at most half a revolution away) on a cyclic axis.
    fn home_target_bidirectional(&self, p: f64) -> f64 {
        let base = self.status.event_raw.unwrap_or(p) + self.cfg.home_offset;
        if self.cfg.travel == TravelMode::Cyclic {
            nearest_cyclic(base, p, self.cfg.unwind)
        } else {
            base
        }
    }

    /// Home Position of a unidirectional sequence, raw: on a cyclic axis whole
    /// revolutions are added until it lies beyond the stopping distance, so
    /// the axis always gets there without reversing.
    fn home_target_unidirectional(&self, p: f64, v: f64) -> f64 {
        let base = self.status.event_raw.unwrap_or(p) + self.cfg.home_offset;
        if self.cfg.travel == TravelMode::Cyclic {
            let d = stopping_distance(v, self.cfg.home_deceleration);
            ahead_cyclic(base, p, self.dir, d, self.cfg.unwind)
        } else {
            base
        }
    }

    /// Command back onto the actual position at return speed.
    pub(super) fn release_profile(&self, now: u64, actual: f64) -> Profile {
        let speed = if self.cfg.home_return_speed > 0.0 {
            self.cfg.home_return_speed
        } else {
            self.cfg.home_speed
        };
        if speed > 0.0 && self.cfg.home_acceleration > 0.0 && self.cfg.home_deceleration > 0.0 {
            self.move_to(now, actual, speed)
        } else {
            Profile::hold(now, actual)
        }
    }

    /// Jog from the current command state to velocity `v`.
    fn jog(&self, now: u64, v: f64) -> Profile {
        let (p0, v0) = self.profile.sample(now);
        Profile::jog(
            now,
            p0,
            v0,
            v,
            self.cfg.home_acceleration,
            self.cfg.home_deceleration,
        )
    }

    /// Time-optimal trapezoid from the current command state to `target`.
    fn move_to(&self, now: u64, target: f64, speed: f64) -> Profile {
        let (p0, v0) = self.profile.sample(now);
        Profile::move_to(
            now,
            p0,
            v0,
            target,
            speed,
            self.cfg.home_acceleration,
            self.cfg.home_deceleration,
        )
    }
}
