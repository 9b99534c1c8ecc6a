//! "Home these axes and tell me how it ended": the request, then following
//! the status service until every named axis has finished. `motionctl home`
//! and `motion-supervisor home` both use it, so they report the same way.

use std::time::{Duration, Instant};

use crate::client::{Client, ClientError};
use crate::message::*;
use crate::report::AxisReport;
use crate::request::{Axes, Request};
use motion_report::AxisResult;

/// What `home` asks for.
#[derive(Clone, Debug, Default)]
pub struct HomeRequest {
    /// Names; empty = every axis (in home order).
    pub axes: Vec<String>,
    /// Start every named axis at once.
    pub parallel: bool,
    /// Seconds after which the supervisor stops what still homes (0: none).
    pub timeout_s: f64,
}

/// How a home request ended.
pub enum HomeOutcome {
    /// The supervisor refused it; nothing was started.
    Refused(Box<ControlResponse>),
    /// Every named axis finished; one row per axis, and the status at the end.
    Done(Vec<AxisResult>, Box<StatusFrame>),
}

/// Sends the home request and follows the status frames until every axis of
/// it has finished, calling `progress` with each new frame and the indices
/// of the axes followed. If `interrupted()` turns true, the axes are stopped
/// (ERR 12 / EXERR 1) and followed until they have.
pub fn home_and_follow(
    client: &mut Client,
    req: &HomeRequest,
    mut progress: impl FnMut(&StatusFrame, &[usize]),
    interrupted: impl Fn() -> bool,
) -> Result<HomeOutcome, ClientError> {
    let home = Request::Home {
        axes: Axes::from_names(&req.axes),
        parallel: req.parallel,
        // As given; the supervisor takes only a finite, positive one.
        timeout_s: (req.timeout_s > 0.0).then_some(req.timeout_s),
    };
    let resp = client.send(&home, Duration::from_secs(3))?;
    if resp.result != RESULT_ACCEPTED {
        return Ok(HomeOutcome::Refused(resp));
    }
    let wanted: Vec<String> = resp.answers().iter().map(|a| get_str(&a.name)).collect();
    let wall = if req.timeout_s > 0.0 {
        Duration::from_secs_f64(req.timeout_s.min(86_400.0) + 60.0)
    } else {
        Duration::from_secs(86_400)
    };
    let until = Instant::now() + wall;
    let mut members: Vec<usize> = Vec::new();
    let mut stopped = false;
    let mut last_seq = 0;
    loop {
        let st = client.status(Duration::from_secs(2))?;
        if st.cycle < resp.cycle || st.sequence == last_seq {
            std::thread::sleep(Duration::from_millis(5));
            continue;
        }
        last_seq = st.sequence;
        if members.is_empty() {
            let names = st.axis_names();
            members = wanted
                .iter()
                .filter_map(|w| names.iter().position(|n| n == w))
                .collect();
        }
        progress(&st, &members);
        let done = members.iter().all(|&i| {
            let a = &st.axes[i];
            !a.in_sequence() && !a.ip() && !a.stopping()
        });
        if done {
            let names = st.axis_names();
            let ios = st.io_names();
            let rows = members
                .iter()
                .map(|&i| st.axes[i].to_result(&names, &ios))
                .collect();
            return Ok(HomeOutcome::Done(rows, st));
        }
        if !stopped && interrupted() {
            stopped = true;
            let stop = Request::Stop {
                axes: Axes::from_names(&wanted),
            };
            client.send(&stop, Duration::from_secs(3))?;
        }
        if Instant::now() > until {
            return Err(ClientError::Timeout {
                what: "homing to finish",
                after: wall,
                pid: client.domain().pid,
            });
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// The refusal in words, one line per refused axis.
pub fn refusal_lines(resp: &ControlResponse) -> Vec<String> {
    let mut out = Vec::new();
    let msg = resp.message_text();
    if !msg.is_empty() {
        out.push(msg);
    }
    out
}
