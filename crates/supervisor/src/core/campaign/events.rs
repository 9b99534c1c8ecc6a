//! The events of the campaign, and what the oracle expects after each one:
//! whether the power stage must go off (and by when), whether the axis must
//! come to rest (by when), whether the soft limits stop applying (only an
//! operator's unhome), and whether a request gave the power stage back.
//! The bounds are stated here once, from the configuration: the stop's
//! time `v / d` for the deceleration `d` the stop must at least reach, plus
//! the cycles that carry an event to the engine and its answer to the
//! drive (two), plus one of rounding.

use super::oracle::{stop_cycles, Oracle};
use super::rig::{setpoint_frame, Client, Rig};
use super::states::{HOME_DECEL, LIMITS, MAX_DECEL, MAX_SPEED, STREAM_TIMEOUT_CYCLES};
use super::Rng;
use crate::shared::{Ask, Control};
use motion_homing::JogSpec;
use motion_homing::Operation;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Event {
    DriveFault,
    PowerDropped,
    FeedbackNan,
    FeedbackStale,
    FeedbackLost,
    FeedbackImplausible,
    LimitSwitch,
    SoftLimit,
    Reset,
    Enable,
    Disable,
    Stop,
    Home,
    Unhome,
    Release,
    OwnerDeath,
    TimestampJump,
    DriveLost,
    IoGone,
}

impl Event {
    pub const ALL: &'static [Event] = &[
        Event::DriveFault,
        Event::PowerDropped,
        Event::FeedbackNan,
        Event::FeedbackStale,
        Event::FeedbackLost,
        Event::FeedbackImplausible,
        Event::LimitSwitch,
        Event::SoftLimit,
        Event::Reset,
        Event::Enable,
        Event::Disable,
        Event::Stop,
        Event::Home,
        Event::Unhome,
        Event::Release,
        Event::OwnerDeath,
        Event::TimestampJump,
        Event::DriveLost,
        Event::IoGone,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Event::DriveFault => "drive_fault",
            Event::PowerDropped => "power_dropped",
            Event::FeedbackNan => "feedback_nan",
            Event::FeedbackStale => "feedback_stale",
            Event::FeedbackLost => "feedback_lost",
            Event::FeedbackImplausible => "feedback_implausible",
            Event::LimitSwitch => "limit_switch",
            Event::SoftLimit => "soft_limit",
            Event::Reset => "reset",
            Event::Enable => "enable",
            Event::Disable => "disable",
            Event::Stop => "stop",
            Event::Home => "home",
            Event::Unhome => "unhome",
            Event::Release => "release",
            Event::OwnerDeath => "owner_death",
            Event::TimestampJump => "timestamp_jump",
            Event::DriveLost => "drive_lost",
            Event::IoGone => "io_gone",
        }
    }
}

/// Cycles of missing feedback after which the loss rule has tripped for
/// sure (`feedback_timeout_ms` 10, one cycle of rounding).
const LOSS_CYCLES: u64 = 12;
/// Cycles a repeated (stale) frame is still taken as an answer: the link's
/// window, `feedback_timeout_ms` of cycles.
const STALE_WINDOW: u64 = 10;

/// The smallest deceleration a stop of what runs now may use: the running
/// motion's own (at least the operations' 500 of this campaign, Home
/// Deceleration 500), never below that.
const STOP_DECEL: f64 = 500.0;

fn op(r: &mut Rig, op: Operation) {
    r.control(Control::undated(
        9,
        Ask::Op {
            mask: 1,
            op,
            token: 0x77,
        },
    ));
}

/// Applies `event` to the rig now; tells the oracle what must follow.
/// Returns how many cycles the run goes on for.
pub fn inject(r: &mut Rig, o: &mut Oracle, event: Event, rng: &mut Rng) -> u64 {
    let k = r.k();
    let v = Oracle::speed(r);
    let mut horizon = 600;
    match event {
        Event::DriveFault => {
            r.b.plants[0].inject_fault();
            o.power_lost(k + 2);
            o.rest_by(k + 2);
        }
        Event::PowerDropped => {
            r.io.sto = true;
            // (an enable still waiting for the drive stays a request)
            if r.plant().feedback().drive.enabled {
                o.power_lost(k + 2);
            }
            o.rest_by(k + 2);
        }
        Event::FeedbackNan => {
            r.io.nan_for = rng.below(1, 50) as u32;
            o.rest_by(k + stop_cycles(v, MAX_DECEL.min(HOME_DECEL), 0));
        }
        Event::FeedbackStale => {
            // taken as answers within the link's window, then missing:
            // a stop once the loss rule trips (a shorter spell is within
            // the rule's tolerance: nothing to stop)
            let n = rng.below(5, 200);
            r.io.stale_for = n as u32;
            if n > STALE_WINDOW + LOSS_CYCLES {
                o.rest_by(k + stop_cycles(v, HOME_DECEL, STALE_WINDOW + LOSS_CYCLES));
            }
        }
        Event::FeedbackLost => {
            let n = rng.below(5, 200);
            r.io.no_data_for = n as u32;
            if n > LOSS_CYCLES {
                o.rest_by(k + stop_cycles(v, HOME_DECEL, LOSS_CYCLES));
            }
        }
        Event::FeedbackImplausible => {
            r.io.jump = true;
            o.rest_by(k + stop_cycles(v, HOME_DECEL, 0));
        }
        Event::LimitSwitch => {
            // the motion towards it stops within the stop's distance;
            // away from it, it may go on
            let dir = Oracle::direction(r).unwrap_or(rng.coin());
            r.io.overtravel = Some(dir);
            o.switch_tripped(r, dir, k);
        }
        Event::SoftLimit => horizon = soft_limit(r, o, rng),
        Event::Reset => op(r, Operation::Reset),
        Event::Enable => {
            op(r, Operation::Enable);
            o.asked_power();
        }
        Event::Disable => {
            op(r, Operation::Disable);
            let by = k + stop_cycles(v, STOP_DECEL.min(HOME_DECEL), 0);
            o.rest_by(by);
            o.power_off_by(by + 2);
        }
        Event::Stop => {
            r.control(Control::undated(9, Ask::Stop { mask: 1 }));
            o.rest_by(k + stop_cycles(v, STOP_DECEL.min(HOME_DECEL), 0));
        }
        Event::Home => {
            r.control(Control::undated(
                9,
                Ask::Home {
                    mask: 1,
                    parallel: false,
                    timeout_ns: 0,
                },
            ));
            o.asked_power();
            o.homing();
            horizon = 3000;
        }
        Event::Unhome => {
            r.control(Control::undated(9, Ask::Unhome { mask: 1 }));
            o.unhomed();
        }
        Event::Release => release(r, o, k, v),
        Event::OwnerDeath => owner_death(r, o, k, v),
        Event::TimestampJump => timestamp_jump(r, o, k),
        Event::DriveLost => {
            let n = rng.below(20, 300);
            r.io.lost_for = n as u32;
            o.power_lost(k + n + 2);
            o.rest_by(k + 2);
            horizon = n + 400;
        }
        Event::IoGone => {
            let n = rng.below(20, 300);
            r.io.gone_for = n as u32;
            o.power_lost(k + n + 2);
            o.rest_by(k + 2);
            horizon = n + 400;
        }
    }
    horizon
}

/// A jog at full speed towards a soft limit; the cycles it may take to
/// reach it and stop.
fn soft_limit(r: &mut Rig, o: &mut Oracle, rng: &mut Rng) -> u64 {
    let up = rng.coin();
    op(
        r,
        Operation::Jog(JogSpec {
            speed: if up { MAX_SPEED } else { -MAX_SPEED },
            lease: Some(5.0),
            accel: Some(2000.0),
            decel: Some(MAX_DECEL),
        }),
    );
    o.asked_power();
    // (refused where another motion runs: that one goes on; the soft
    // limits hold either way)
    let to = if up { LIMITS.1 } else { LIMITS.0 };
    let dist = (to - r.plant().position()).abs();
    (dist / MAX_SPEED * 1000.0) as u64 + stop_cycles(MAX_SPEED, STOP_DECEL, 0) + 300
}

/// A jog's HMI lets go (its end), a program releases its stream.
fn release(r: &mut Rig, o: &mut Oracle, k: u64, v: f64) {
    match r.client.clone() {
        Client::Jog { token, .. } => {
            r.control(Control::undated(
                9,
                Ask::JogRenew {
                    token,
                    mask: 0,
                    end: true,
                },
            ));
            r.client = Client::None;
            o.rest_by(k + stop_cycles(v, STOP_DECEL, 0));
        }
        Client::Stream(p) => {
            r.control(Control::undated(9, Ask::StreamRelease { token: p.token }));
            r.client = Client::None;
            o.rest_by(k + stop_cycles(v, MAX_DECEL, 2));
        }
        Client::None => r.control(Control::undated(9, Ask::StreamRelease { token: 0x99 })),
    }
}

/// The client dies: a jog is no longer renewed, a program no longer
/// publishes and, 100 ms later, the owners' check releases its stream.
fn owner_death(r: &mut Rig, o: &mut Oracle, k: u64, v: f64) {
    match &mut r.client {
        Client::Jog { alive, .. } => {
            *alive = false;
            // renewed at most 100 cycles ago with a 500 ms lease
            o.rest_by(k + stop_cycles(v, STOP_DECEL, 500));
        }
        Client::Stream(p) => {
            p.alive = false;
            let (token, last) = (p.token, p.last_k);
            o.rest_by(last + stop_cycles(v, MAX_DECEL, STREAM_TIMEOUT_CYCLES));
            for _ in 0..100 {
                r.cycle();
                if let Err(e) = o.check(r) {
                    o.early(e);
                    return;
                }
            }
            r.control(Control::undated(9, Ask::StreamRelease { token }));
        }
        Client::None => {}
    }
}

/// A program publishes a setpoint an hour ahead on its clock, 9 units away,
/// and one a millisecond after it — then nothing more.
fn timestamp_jump(r: &mut Rig, o: &mut Oracle, k: u64) {
    let Client::Stream(p) = &mut r.client else {
        r.inject.push(setpoint_frame(0x99, 1, 1, 0.0));
        return;
    };
    p.alive = false;
    let (token, t, at) = (p.token, p.t_ns, p.p);
    let to = if at + 9.0 < LIMITS.1 - 1.0 {
        at + 9.0
    } else {
        at - 9.0
    };
    let hour = 3_600_000_000_000;
    for (dt, seq) in [(hour, 1_000_001), (hour + 1_000_000, 1_000_002)] {
        r.inject.push(setpoint_frame(token, seq, t + dt, to));
        r.cycle();
        if let Err(e) = o.check(r) {
            o.early(e);
            return;
        }
    }
    o.rest_by(k + stop_cycles(MAX_SPEED, MAX_DECEL, 2 + STREAM_TIMEOUT_CYCLES));
}
