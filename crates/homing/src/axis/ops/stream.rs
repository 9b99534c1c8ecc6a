//! The supervised setpoint stream: a program's positions, checked one by
//! one, made into a reference path on the cycle's timeline, and followed
//! by a command that is never faster or harder than the limits, whatever
//! the setpoints' timestamps say.
//!
//! **The reference.** When setpoint k arrives (program time t_k, previous
//! t_{k−1}), the reference runs linearly from where it is to p_k, reaching
//! it Δ = t_k − t_{k−1} later, rounded to whole cycles (at least one), and
//! rests on it until the next one. A 100 Hz stream on a 1 kHz cycle
//! becomes ten equal steps per setpoint; one that comes early restarts
//! from where the reference is.
//!
//! **The command follows the reference, within the limits** (`follower`):
//! sampled each cycle, its velocity never changes by more than
//! `stream_acceleration` × cycle between two cycles, and it is never faster
//! than the speed cap that applies — `max_speed`, and `unhomed_speed` while
//! not homed (`stream_unhomed`), as for jog and move — nor carried past a
//! travel limit. Where the reference is reachable within those bounds (a
//! stream at the cycle rate, a sparse stream whose corners need no more
//! than `stream_acceleration` × cycle) the command is on it exactly, in the
//! step the setpoint arrives (one cycle after it was published). Where it
//! is not — a corner too sharp for one cycle, a setpoint that comes late
//! (the command brakes past the last one instead of stopping dead on it),
//! timestamps that claim more time than the cycle gives — the command
//! closes in at the bounds. If it would lag the reference by more than
//! `max_speed`² / (2 `stream_acceleration`) + one cycle at `max_speed`
//! (the cap that applies, in fact: see `follower::lag_bound`), the stream
//! cannot be followed: refused with 1019 / 3 (held back by the speed cap)
//! or 1019 / 4 (by the acceleration), from the command of the step before —
//! nothing of that step reaches the drive. The guarantee is on the
//! commanded positions as the cycle samples them: no timestamp can buy a
//! faster or harder command.
//!
//! Why shape rather than only refuse: judged on the cycle's timeline
//! alone, a 100 Hz stream on a 1 kHz cycle could change its velocity per
//! setpoint by no more than `stream_acceleration` × one cycle — a tenth of
//! what its own timeline honestly allows — and a setpoint one cycle late
//! would still stop the command dead on the one before. Shaping keeps
//! every honest stream (the bench's circles at the cycle rate and at
//! 100 Hz, the 100 Hz Python programs) within the bounds, on its
//! setpoints wherever they are reachable; refusing what cannot be followed
//! within a stop's distance keeps a hostile stream from dragging the
//! command far from the path it asked for.
//!
//! **Checks** of every setpoint on the program's own timeline (a program's
//! trajectory that is nonsense is refused before it is followed), each an
//! axis fault that stops the axis and ends the stream (ER 1019 / EXERR): 1
//! position or feed-forward not finite; 2 outside `travel_limits` (homed,
//! linear) or beyond ±`max_position`; 3 segment speed |p_k − p_{k−1}| / Δ
//! (or the feed-forward) above the speed cap; 4 change of segment velocity
//! |v_k − v_{k−1}| / Δ above `stream_acceleration`; 6 t_k not after
//! t_{k−1}; 7 not homed and `stream_unhomed` false. The first setpoint is
//! judged against the current command position as if it came one cycle
//! after it, from rest. Δ here is the program's own (exact, not rounded).
//! Speeds and accelerations get a relative tolerance of 1e-9 (a trajectory
//! exactly at the bound passes despite rounding).
//!
//! **Silence.** No new setpoint for `stream_timeout_ms` after the last one
//! *arrived* → 1019 / 5, however far ahead that setpoint lay: a program
//! that hangs or dies runs out nothing. A program must publish at least
//! every `stream_timeout_ms` (a setpoint far ahead in time is not a promise
//! to keep the axis moving).
//! **Not homed** (the reference cleared while streaming) → 1019 / 7.
//!
//! **Stops.** A stream's stops — a refusal, silence, a fault, `stop`, the
//! release — brake from the command's state at the larger of
//! `max_deceleration` and `stream_acceleration` (what the stream was
//! allowed, it can stop), inside the travel limits. `StreamEnd` (released,
//! or the owner gone) stops at once (normal: `StopCause::Released`, PC at
//! rest); a program that releases at rest on its last setpoint — the
//! normal end — finds the axis there. The bound for a program that stops
//! sending (released, dead or hung): at rest within `stream_timeout_ms`
//! of its last setpoint's arrival (plus a cycle), travelling at most
//! v × (`stream_timeout_ms` + cycle) + v² / (2 d) (v its speed, d that
//! deceleration).

use super::follower::{self, Bounds};
use super::motion::{Halt, Motion, Run, Stream, Taken};
use super::{within, Code};
use crate::axis::state::State;
use crate::axis::Axis;
use crate::codes::*;
use crate::config::TravelMode;
use crate::operation::{OpKind, Setpoint, StopCause};
use crate::position::nearest_cyclic;
use crate::profile::Profile;
use crate::time::{f64_as_ns, ns_to_s};

/// Relative tolerance of the speed and acceleration checks.
const TOLERANCE: f64 = 1e-9;

impl Axis {
    /// The stream takes the axis over: enabled, at rest, homed (unless
    /// `stream_unhomed`), with a speed bound and a deceleration to stop it.
    pub(super) fn stream_start(&mut self, now: u64) -> Result<(), Code> {
        self.motion_gate()?;
        if matches!(self.state, State::Motion(_) | State::Stopping { .. }) {
            return Err(super::rules::COLLISION);
        }
        self.speed_bound()?;
        if !self.status.homed && !self.cfg.stream_unhomed {
            return Err((ERR_SETPOINT_REFUSED, EX_SETPOINT_NOT_HOMED));
        }
        if self.speed_cap() <= 0.0 {
            return Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_SPEED));
        }
        if self.limits.max_deceleration <= 0.0 || self.limits.max_deceleration.is_nan() {
            return Err((ERR_PARAMETER_OUT_OF_RANGE, EX_PARAM_DECELERATION));
        }
        let op = self.accept_op(OpKind::StreamStart);
        let (p, _) = self.profile.at(now);
        self.profile.set(Profile::hold(now, p));
        self.state = State::Motion(Motion {
            op,
            run: Run::Stream(Stream {
                prev: None,
                seg_start_ns: now,
                seg_from: p,
                seg_to: p,
                seg_end_ns: now,
                seg_velocity: 0.0,
                velocity: 0.0,
                on_reference: true,
                feed_forward: None,
                arrived_ns: now,
            }),
        });
        Ok(())
    }

    /// The stream is released (or its owner is gone): always accepted. The
    /// axis stops now, from the command's state, at the stream's
    /// deceleration — not at the end of a segment that may lie far ahead.
    pub(super) fn stream_end(&mut self, now: u64) {
        let id = self.accept_op(OpKind::StreamEnd);
        let State::Motion(Motion {
            run: Run::Stream(_),
            ..
        }) = self.state
        else {
            // Nothing streams (it ended already): nothing to do.
            self.op_done(id, true);
            return;
        };
        let (t, k) = self.motion_state(now);
        let decel = self.stream_decel();
        let limits = self.stop_limits();
        // A stream's stops have no jerk: its command has no planned
        // acceleration to ramp from.
        self.profile
            .set(Self::stop_within(t, k, decel, 0.0, limits));
        self.status.last_stop = StopCause::Released;
        self.state = State::Motion(Motion {
            op: id,
            run: Run::Halt(Halt {
                normal: true,
                decel,
                jerk: 0.0,
                limits,
            }),
        });
    }

    /// A new setpoint: judged, then followed (or the stream stops the axis).
    pub(super) fn take_setpoint(&mut self, now: u64, sp: &Setpoint) {
        let State::Motion(Motion {
            run: Run::Stream(st),
            op,
        }) = self.state
        else {
            return;
        };
        match self.judge(now, sp, &st) {
            Ok(taken) => self.new_segment(now, op, taken, sp.velocity),
            Err(exerr) => {
                self.op_fault(
                    now,
                    (ERR_SETPOINT_REFUSED, exerr),
                    StopCause::SetpointRefused,
                    false,
                );
            }
        }
    }

    /// The length of a cycle, ns: the configured one, else the time since
    /// the previous step.
    pub(super) fn cycle_ns(&self, now: u64) -> u64 {
        if self.cfg.cycle_ns > 0 {
            self.cfg.cycle_ns
        } else {
            self.ops
                .prev_step_ns
                .map_or(1, |t| now.saturating_sub(t))
                .max(1)
        }
    }

    /// Every check of a setpoint; the setpoint as taken, or the EXERR.
    fn judge(&self, now: u64, sp: &Setpoint, st: &Stream) -> Result<Taken, u16> {
        let finite = |x: f64| x.is_finite();
        if !finite(sp.position) || !sp.velocity.is_none_or(finite) {
            return Err(EX_SETPOINT_NOT_FINITE);
        }
        if !self.status.homed && !self.cfg.stream_unhomed {
            return Err(EX_SETPOINT_NOT_HOMED);
        }
        let cycle = self.cycle_ns(now);
        // The first setpoint comes one cycle after the command, from rest.
        let (dt_ns, from, v_prev) = match st.prev {
            Some(k) if sp.t_ns <= k.t_ns => return Err(EX_SETPOINT_OUT_OF_ORDER),
            Some(k) => (sp.t_ns - k.t_ns, k.raw, k.velocity),
            None => (cycle, self.last_command.position, 0.0),
        };
        let raw = match self.cfg.travel {
            TravelMode::Cyclic if self.cfg.unwind > 0.0 => {
                nearest_cyclic(sp.position - self.offset, from, self.cfg.unwind)
            }
            _ => sp.position - self.offset,
        };
        let outside = match self.soft_limits_axis() {
            Some((lo, hi)) => !(lo..=hi).contains(&sp.position),
            None => false,
        };
        if outside || !within(raw, self.cfg.max_position.min(f64::MAX)) {
            return Err(EX_SETPOINT_OUTSIDE_LIMITS);
        }
        let dt = ns_to_s(dt_ns);
        let velocity = (raw - from) / dt;
        let vmax = self.speed_cap() * (1.0 + TOLERANCE);
        let ff_fast = sp.velocity.is_some_and(|f| f.abs() > vmax);
        if !within(velocity, vmax) || ff_fast {
            return Err(EX_SETPOINT_SPEED);
        }
        let amax = self.limits.stream_acceleration * (1.0 + TOLERANCE);
        if !within((velocity - v_prev) / dt, amax) {
            return Err(EX_SETPOINT_ACCELERATION);
        }
        Ok(Taken {
            t_ns: sp.t_ns,
            raw,
            velocity,
        })
    }

    /// An accepted setpoint: the reference's next segment, from where the
    /// reference is at the previous step to it, lasting the program's Δ in
    /// whole cycles.
    fn new_segment(&mut self, now: u64, op: u32, k: Taken, feed_forward: Option<f64>) {
        let State::Motion(Motion {
            run: Run::Stream(st),
            ..
        }) = self.state
        else {
            return;
        };
        let cycle = self.cycle_ns(now);
        let dt_ns = st.prev.map_or(cycle, |p| k.t_ns - p.t_ns);
        let cycles = (dt_ns as f64 / cycle as f64).round().max(1.0);
        let t0 = self.ops.prev_step_ns.unwrap_or(now.saturating_sub(cycle));
        let from = st.reference(t0).0;
        let seg_ns = f64_as_ns(cycles * cycle as f64);
        self.state = State::Motion(Motion {
            op,
            run: Run::Stream(Stream {
                prev: Some(k),
                seg_start_ns: t0,
                seg_from: from,
                seg_to: k.raw,
                seg_end_ns: t0.saturating_add(seg_ns),
                seg_velocity: (k.raw - from) / ns_to_s(seg_ns),
                feed_forward,
                arrived_ns: now,
                ..st
            }),
        });
    }

    /// One step of the stream: still homed, not silent, then the command
    /// one cycle further along the reference, within the bounds.
    pub(super) fn advance_stream(&mut self, now: u64, op: u32, st: Stream) {
        let fault = if !self.status.homed && !self.cfg.stream_unhomed {
            Some(EX_SETPOINT_NOT_HOMED)
        } else if now.saturating_sub(st.arrived_ns) > self.limits.stream_timeout_ns {
            Some(EX_SETPOINT_STALE)
        } else {
            self.follow(now, op, st).err()
        };
        if let Some(exerr) = fault {
            self.op_fault(
                now,
                (ERR_SETPOINT_REFUSED, exerr),
                StopCause::SetpointRefused,
                false,
            );
        }
    }

    /// This step's command along the reference (`follower`); the EXERR
    /// when it would lag the reference further than it can be followed
    /// (nothing of this step is then commanded).
    fn follow(&mut self, now: u64, op: u32, st: Stream) -> Result<(), u16> {
        let Some(dt_ns) = self.ops.prev_step_ns.map(|t| now.saturating_sub(t)) else {
            return Ok(());
        };
        if dt_ns == 0 {
            return Ok(());
        }
        let (r, _) = st.reference(now);
        let u = if now <= st.seg_end_ns {
            st.seg_velocity
        } else {
            0.0
        };
        let bounds = Bounds {
            cap: self.speed_cap(),
            accel: self.limits.stream_acceleration,
            limits: self.soft_limits_raw(),
        };
        let x = self.last_command.position;
        let step = follower::step(x, st.velocity, r, u, ns_to_s(dt_ns), &bounds);
        let cycle_s = ns_to_s(self.cycle_ns(now));
        if !within(
            r - step.position,
            follower::lag_bound(bounds.cap, bounds.accel, cycle_s),
        ) {
            return Err(if step.capped {
                EX_SETPOINT_SPEED
            } else {
                EX_SETPOINT_ACCELERATION
            });
        }
        self.profile.set(Profile::hold(now, step.position));
        self.state = State::Motion(Motion {
            op,
            run: Run::Stream(Stream {
                velocity: step.velocity,
                on_reference: step.on_reference,
                ..st
            }),
        });
        Ok(())
    }
}
