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

impl AxisStatusEntry {
    /// The operation `op_id` has ended on this axis (or a later one took
    /// over) and the axis is at rest.
    pub fn op_ended(&self, op_id: u32) -> bool {
        let moving = self.motion & (MS_JOGGING | MS_MOVING | MS_STREAMING) != 0;
        let busy =
            (self.op_id == op_id && self.op_flags & OP_IP != 0) || self.has(ST_STOPPING) || moving;
        self.op_id != op_id || !busy
    }

    /// How operation `op_id` ended, as a row of `move --json`.
    pub fn op_row(&self, op_id: u32) -> MotionRow {
        let refused = self.op_id == op_id && self.op_flags & OP_REFUSED != 0;
        let (err, exerr) = if self.has(ST_ER) {
            (self.err, self.exerr)
        } else if refused {
            (self.op_err, self.op_exerr)
        } else {
            (0, 0)
        };
        let error = if self.op_id != op_id {
            Some("another operation took the axis over".to_string())
        } else if err != 0 {
            Some(motion_report::codes::describe(
                err,
                exerr,
                Some(self.feedback_gap_s),
            ))
        } else {
            None
        };
        MotionRow {
            name: get_str(&self.name),
            pc: self.op_id == op_id && self.op_flags & OP_PC != 0,
            er: self.has(ST_ER) || refused,
            err,
            exerr,
            position: self
                .has(ST_FEEDBACK)
                .then_some(self.position)
                .filter(|p| p.is_finite()),
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
