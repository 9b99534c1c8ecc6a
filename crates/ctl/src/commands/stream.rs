//! `stream AXIS... --csv FILE [--json]`: plays a file of timed setpoints
//! through the supervised setpoint stream — the commissioning tool and the
//! reference client of the stream. The file is checked first; then the
//! axes are acquired (owner "motionctl"), the rows published at their times
//! — filled in on the line between rows further apart than 5 ms, because
//! an axis stops (1019 / 5) when no setpoint has arrived for its
//! `stream_timeout_ms`, however far ahead the last one lay —, the last row
//! held (published again) until every axis's command is on it, the axes
//! released (a release stops them at once, where they are: on the last
//! row), and followed to rest. Progress on
//! stderr; at the end one row per axis with the largest following error
//! seen (command − actual, from the 100 Hz status) and the final error
//! (last row − final position).
//!
//! Exit: 0 when every axis streamed to the end and was released normally,
//! 1 when refused or an axis stopped with an error (a refused setpoint:
//! ERR 1019), 130 / 143 when interrupted (the stream released: the axes
//! stop).

use super::csv::{self, Row};
use super::moves::{follow_to_rest, op_error, report};
use super::{client_error, fail, EXIT_FAILED};
use crate::cli::StreamArgs;
use motion_control::follow::{followed, Followed};
use motion_control::progress::Progress;
use motion_control::stream::{Stream, StreamError};
use motion_control::*;
use motion_report::{ErrorEntry, MotionReport, MotionRow};
use std::time::Duration;

pub fn stream(client: &mut Client, a: &StreamArgs) -> i32 {
    let rows = match csv::read(&a.csv, a.axes.len()) {
        Ok(r) => r,
        Err(e) => return fail(a.json, vec![ErrorEntry::message(e)], super::EXIT_USAGE),
    };
    let mut s = match client.stream("motionctl", &a.axes) {
        Ok(s) => s,
        Err(StreamError::Op(e)) => return op_error(a.json, "stream", &e),
        Err(e) => {
            return fail(
                a.json,
                vec![ErrorEntry::message(e.to_string())],
                EXIT_FAILED,
            )
        }
    };
    let axes = followed(s.answer());
    let column = columns(&s, &axes);
    let cycle = s.answer().cycle;
    let mut play = Play::new(axes.len());
    let mut progress = Progress::new();
    if let Err(e) = play.run(&mut s, &rows, (&axes, &column), &mut progress) {
        drop(s);
        return client_error(a.json, &e);
    }
    // Released: followed by the stream ends' operations (PC: at rest on the
    // last setpoint). Not released: already over on the supervisor's side
    // (an axis stopped with an error ends the stream): followed by the
    // stream's own operations, whose rows say why.
    let (axes, cycle) = match s.release() {
        Ok(resp) => (followed(&resp), resp.cycle),
        Err(e) => {
            log::debug!("release: {e}");
            (axes, cycle)
        }
    };
    let last = &rows[rows.len() - 1];
    match follow_to_rest(client, &axes, cycle, &mut progress) {
        Err(e) => client_error(a.json, &e),
        Ok(rows) => {
            let rows = rows
                .into_iter()
                .zip(&column)
                .zip(&play.max_error)
                .map(|((r, &k), &m)| with_errors(r, last.p.get(k).copied(), m))
                .collect();
            report(a.json, MotionReport { axes: rows })
        }
    }
}

/// For each followed axis, the file column that moves it (a gantry side:
/// its gantry's column).
fn columns(s: &Stream, axes: &[Followed]) -> Vec<usize> {
    axes.iter()
        .map(|f| {
            (s.map().axes.iter())
                .position(|m| m.sides.contains(&(f.index as u32)))
                .unwrap_or(0)
        })
        .collect()
}

/// A row with its following errors.
fn with_errors(mut r: MotionRow, last: Option<f64>, max: f64) -> MotionRow {
    r.following_error_max = Some(motion_report::round(max, 6));
    r.final_error = match (last, r.position) {
        (Some(l), Some(p)) => Some(motion_report::round(l - p, 6)),
        _ => None,
    };
    r
}

/// Longest the program holds at its last row for the axes to get there.
const HOLD_S: f64 = 2.0;

/// Sleeps until `t` (CLOCK_MONOTONIC, ns), in slices of at most 2 ms.
fn sleep_until(t: u64) {
    while motion_rt::now_ns() < t {
        std::thread::sleep(Duration::from_nanos(
            (t - motion_rt::now_ns()).min(2_000_000),
        ));
    }
}

/// Every followed axis's command is on its column of `last` (or the axis
/// no longer streams: nothing to wait for).
fn on_last(
    s: &mut Stream,
    axes: &[Followed],
    column: &[usize],
    last: &Row,
) -> Result<bool, ClientError> {
    let st = s.client().status(Duration::from_secs(2))?;
    Ok(axes.iter().zip(column).all(|(f, &k)| {
        let Some(e) = st.axes().get(f.index) else {
            return true;
        };
        let target = last.p.get(k).copied().unwrap_or(f64::NAN);
        let there = e
            .cmd_position()
            .is_some_and(|c| (c - target).abs() <= 1e-9 * (1.0 + target.abs()));
        there || (st.cycle > s.answer().cycle && !e.streaming())
    }))
}

/// Playing the points.
struct Play {
    /// Per followed axis, the largest |command − actual| seen.
    max_error: Vec<f64>,
}

impl Play {
    fn new(n: usize) -> Self {
        Self {
            max_error: vec![0.0; n],
        }
    }

    /// Publishes every point of `rows` ([`csv::points`]) at its time (the
    /// program's clock: CLOCK_MONOTONIC from the first row), watching the
    /// status between points; stops early on a signal or when an axis no
    /// longer streams. Then holds on the last row until the axes are there.
    fn run(
        &mut self,
        s: &mut Stream,
        rows: &[Row],
        (axes, column): (&[Followed], &[usize]),
        progress: &mut Progress,
    ) -> Result<(), ClientError> {
        let t0 = motion_rt::now_ns();
        let first = rows[0].t;
        let at = |p: &Row| t0 + ((p.t - first) * 1e9) as u64;
        let mut next_look = t0;
        for p in csv::points(rows) {
            let t = at(&p);
            sleep_until(t);
            if motion_rt::termination::received().is_some() {
                return Ok(());
            }
            if let Err(e) = s.publish(t, &p.p, None) {
                log::error!("{e}");
                return Ok(());
            }
            if motion_rt::now_ns() >= next_look {
                next_look = motion_rt::now_ns() + 50_000_000;
                if !self.look(s, axes, progress)? {
                    return Ok(());
                }
            }
        }
        let last = &rows[rows.len() - 1];
        self.hold(s, at(last), last, (axes, column))
    }

    /// The program holds at its last row — publishing it again, later,
    /// every [`csv::FILL_S`] (a program silent for `stream_timeout_ms` is
    /// stopped) — until every axis's command is on it, for at most
    /// [`HOLD_S`]: a release stops the axes at once, where their command
    /// is, and a loaded host may have published the last rows late.
    fn hold(
        &mut self,
        s: &mut Stream,
        mut t: u64,
        last: &Row,
        (axes, column): (&[Followed], &[usize]),
    ) -> Result<(), ClientError> {
        let until = motion_rt::now_ns() + (HOLD_S * 1e9) as u64;
        let step = (csv::FILL_S * 1e9) as u64;
        while motion_rt::now_ns() < until && motion_rt::termination::received().is_none() {
            t += step;
            sleep_until(t);
            if let Err(e) = s.publish(t, &last.p, None) {
                log::error!("{e}");
                return Ok(());
            }
            if on_last(s, axes, column, last)? {
                break;
            }
        }
        Ok(())
    }

    /// One look at the status: the following errors, the progress; false
    /// when an axis no longer streams.
    fn look(
        &mut self,
        s: &mut Stream,
        axes: &[Followed],
        progress: &mut Progress,
    ) -> Result<bool, ClientError> {
        let st = s.client().status(Duration::from_secs(2))?;
        let members: Vec<usize> = axes.iter().map(|a| a.index).collect();
        progress.show_motion(&st, &members);
        let mut streaming = true;
        for (k, f) in axes.iter().enumerate() {
            let Some(e) = st.axes().get(f.index) else {
                continue;
            };
            if let (Some(cmd), Some(pos)) = (e.cmd_position(), e.position()) {
                self.max_error[k] = self.max_error[k].max((cmd - pos).abs());
            }
            if st.cycle > s.answer().cycle && !e.streaming() {
                streaming = false;
            }
        }
        Ok(streaming)
    }
}
