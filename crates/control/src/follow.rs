//! "Start an operation and tell me how it ended": following the accepted
//! axes of an answer in the status service until each one's operation (by
//! its id) has ended and the axis is at rest. `motionctl move` and `stream`
//! use it, so they report the same way.

use std::time::{Duration, Instant};

use crate::client::{Client, ClientError};
use crate::message::*;
use crate::request::{Axes, Request};
use motion_report::MotionRow;

/// One followed axis: its index in the status frame and the id of the
/// operation it was given.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Followed {
    pub name: String,
    pub index: usize,
    pub op_id: u32,
}

/// The accepted axes of `resp` (every axis it answered with an operation).
pub fn followed(resp: &ControlResponse) -> Vec<Followed> {
    resp.answers()
        .iter()
        .filter(|a| a.accepted == 1 && a.index != NO_INDEX)
        .map(|a| Followed {
            name: get_str(&a.name),
            index: a.index as usize,
            op_id: a.op_id,
        })
        .collect()
}

/// How an axis's operation ended, from its status entry.
pub trait OpOutcome {
    /// The operation `op_id` has ended on this axis (or a later one took
    /// over) and the axis is at rest.
    fn op_ended(&self, op_id: u32) -> bool;
    /// How operation `op_id` ended, as a row of `move --json`.
    fn op_row(&self, op_id: u32) -> MotionRow;
}

impl OpOutcome for AxisStatusEntry {
    fn op_ended(&self, op_id: u32) -> bool {
        let mine = self.op_id() == op_id;
        let busy = (mine && self.op_ip()) || self.stopping() || self.in_motion();
        !mine || !busy
    }

    fn op_row(&self, op_id: u32) -> MotionRow {
        let mine = self.op_id() == op_id;
        let refused = mine && self.op_refused();
        let (err, exerr) = if self.er() {
            (self.err(), self.exerr())
        } else if refused {
            (self.op_err(), self.op_exerr())
        } else {
            (0, 0)
        };
        let error = if !mine {
            Some("another operation took the axis over".to_string())
        } else if err != 0 {
            Some(motion_report::codes::describe(
                err,
                exerr,
                Some(self.feedback_gap_s()),
            ))
        } else {
            None
        };
        MotionRow {
            name: self.name_text(),
            pc: mine && self.op_pc(),
            er: self.er() || refused,
            err,
            exerr,
            position: self.position(),
            error,
            ..MotionRow::default()
        }
    }
}

/// Follows `axes` until each one's operation has ended, calling `progress`
/// with each new frame and the status indices followed. If `interrupted()`
/// turns true, the axes are stopped and followed until at rest. Gives up
/// after `wall`.
pub fn follow(
    client: &mut Client,
    axes: &[Followed],
    after_cycle: u64,
    wall: Duration,
    mut progress: impl FnMut(&StatusFrame, &[usize]),
    interrupted: impl Fn() -> bool,
) -> Result<(Vec<MotionRow>, Box<StatusFrame>), ClientError> {
    let members: Vec<usize> = axes.iter().map(|a| a.index).collect();
    let until = Instant::now() + wall;
    let mut stopped = false;
    let mut last_seq = 0;
    loop {
        let st = client.status(Duration::from_secs(2))?;
        if st.cycle < after_cycle || st.sequence == last_seq {
            std::thread::sleep(Duration::from_millis(5));
            continue;
        }
        last_seq = st.sequence;
        progress(&st, &members);
        let entry = |a: &Followed| st.axes().get(a.index);
        if axes
            .iter()
            .all(|a| entry(a).is_none_or(|e| e.op_ended(a.op_id)))
        {
            let rows = axes
                .iter()
                .filter_map(|a| entry(a).map(|e| e.op_row(a.op_id)))
                .collect();
            return Ok((rows, st));
        }
        if !stopped && interrupted() {
            stopped = true;
            let names = axes.iter().map(|a| a.name.clone()).collect::<Vec<_>>();
            let stop = Request::Stop {
                axes: Axes::from_names(&names),
            };
            client.send(&stop, Duration::from_secs(3))?;
        }
        if Instant::now() > until {
            return Err(ClientError::Timeout {
                what: "the operation to end",
                after: wall,
                pid: client.domain().pid,
            });
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}
