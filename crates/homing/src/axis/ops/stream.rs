//! The supervised setpoint stream: a program's positions, checked one by
//! one and interpolated to the cycle.
//!
//! **Interpolation.** When setpoint k arrives (program time t_k, previous
//! t_{k−1}), the command runs linearly from the previous step's command
//! position to p_k, reaching it Δ = t_k − t_{k−1} later, rounded to whole
//! cycles (at least one): a stream at the cycle rate is commanded exactly,
//! in the step it arrives (one cycle after it was published); a 100 Hz
//! stream on a 1 kHz cycle becomes ten equal steps per setpoint. A
//! setpoint that comes early restarts the interpolation from where the
//! command is; one that comes late leaves the command resting on the
//! previous one — the command never extrapolates, so it only ever passes
//! positions between accepted setpoints. Should a catch-up segment be
//! faster than `max_speed` (the command lagging behind the program), it is
//! stretched to `max_speed`.
//!
//! **Checks** of every setpoint, each an axis fault that stops the axis at
//! `max_deceleration` (inside the travel limits) and ends the stream
//! (ER 1019 / EXERR): 1 position or feed-forward not finite; 2 outside
//! `travel_limits` (homed, linear) or beyond ±`max_position`; 3 segment
//! speed |p_k − p_{k−1}| / Δ (or the feed-forward) above `max_speed`;
//! 4 change of segment velocity |v_k − v_{k−1}| / Δ above
//! `stream_acceleration`; 6 t_k not after t_{k−1}; 7 not homed and
//! `stream_unhomed` false. The first setpoint is judged against the
//! current command position as if it came one cycle after it, from rest.
//! Δ here is the program's own (exact, not rounded): the checks judge the
//! program's trajectory, not the transport's jitter. Speeds and
//! accelerations get a relative tolerance of 1e-9 (a trajectory exactly at
//! the bound passes despite rounding).
//!
//! **Silence.** No new setpoint for `stream_timeout_ms` after the command
//! reached the last one → 1019 / 5 (the axis already rests on it).
//! **Not homed** (the reference cleared while streaming) → 1019 / 7.
//!
//! **End.** `StreamEnd` (released, or the owner gone): the axis lands on
//! the last setpoint when it can stop there at `max_deceleration`, else it
//! stops at `max_deceleration`; normal (`StopCause::Released`, PC at rest).
//! A `stop` stops it at `max_deceleration` at once.

use super::motion::{Halt, Motion, Run, Stream, Taken};
use super::{within, Code};
use crate::axis::state::State;
use crate::axis::Axis;
use crate::codes::*;
use crate::config::TravelMode;
use crate::operation::{OpKind, Setpoint, StopCause};
use crate::position::nearest_cyclic;
use crate::profile::{reaches_without_reversing, Profile};
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
        if !self.status.homed && !self.cfg.stream_unhomed {
            return Err((ERR_SETPOINT_REFUSED, EX_SETPOINT_NOT_HOMED));
        }
        if self.limits.max_speed.is_none() {
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
                seg_end_ns: now,
                seg_velocity: 0.0,
                feed_forward: None,
            }),
        });
        Ok(())
    }

    /// The stream is released (or its owner is gone): always accepted.
    pub(super) fn stream_end(&mut self, now: u64) {
        let id = self.accept_op(OpKind::StreamEnd);
        let State::Motion(Motion {
            run: Run::Stream(st),
            ..
        }) = self.state
        else {
            // Nothing streams (it ended already): nothing to do.
            self.op_done(id, true);
            return;
        };
        let (t, p, v) = self.motion_state(now);
        let decel = self.limits.max_deceleration;
        let last = st.prev.map_or(p, |k| k.raw);
        let landing = if v != 0.0 && reaches_without_reversing(p, v, last, decel) {
            Profile::move_to(t, p, v, last, v.abs(), decel, decel)
        } else {
            self.stop_inside(t, p, v, decel)
        };
        self.profile.set(landing);
        self.status.last_stop = StopCause::Released;
        self.state = State::Motion(Motion {
            op: id,
            run: Run::Halt(Halt { normal: true }),
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
            Ok(taken) => self.follow(now, op, taken, sp.velocity),
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
    fn cycle_ns(&self, now: u64) -> u64 {
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
        let outside = match (self.soft_limits_raw(), self.cfg.travel_limits) {
            (Some(_), Some((lo, hi))) => !(lo..=hi).contains(&sp.position),
            _ => false,
        };
        if outside || !within(raw, self.cfg.max_position.min(f64::MAX)) {
            return Err(EX_SETPOINT_OUTSIDE_LIMITS);
        }
        let dt = ns_to_s(dt_ns);
        let velocity = (raw - from) / dt;
        let vmax = self.limits.max_speed.unwrap_or(0.0) * (1.0 + TOLERANCE);
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

    /// Follows an accepted setpoint: a segment from the previous step's
    /// command to it, lasting the program's Δ in whole cycles.
    fn follow(&mut self, now: u64, op: u32, k: Taken, feed_forward: Option<f64>) {
        let State::Motion(Motion {
            run: Run::Stream(st),
            ..
        }) = self.state
        else {
            return;
        };
        let cycle = self.cycle_ns(now);
        let dt_ns = st.prev.map_or(cycle, |p| k.t_ns - p.t_ns);
        let mut cycles = (dt_ns as f64 / cycle as f64).round().max(1.0);
        let t0 = self.ops.prev_step_ns.unwrap_or(now.saturating_sub(cycle));
        let from = self.last_command.position;
        // Catching up: never faster than max_speed.
        let vmax = self.limits.max_speed.unwrap_or(f64::INFINITY);
        let need = (k.raw - from).abs() / vmax / ns_to_s(cycle);
        if need > cycles {
            cycles = need.ceil();
        }
        let seg_ns = f64_as_ns(cycles * cycle as f64);
        self.profile.set(Profile::segment(t0, from, k.raw, seg_ns));
        self.state = State::Motion(Motion {
            op,
            run: Run::Stream(Stream {
                prev: Some(k),
                seg_end_ns: t0.saturating_add(seg_ns),
                seg_velocity: (k.raw - from) / ns_to_s(seg_ns),
                feed_forward,
            }),
        });
    }

    /// One step of the stream: still homed, not silent.
    pub(super) fn advance_stream(&mut self, now: u64, _op: u32, st: Stream) {
        let fault = if !self.status.homed && !self.cfg.stream_unhomed {
            Some(EX_SETPOINT_NOT_HOMED)
        } else if now.saturating_sub(st.seg_end_ns) > self.limits.stream_timeout_ns {
            Some(EX_SETPOINT_STALE)
        } else {
            None
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
}
