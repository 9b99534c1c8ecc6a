//! `jog AXIS --speed V [--accel A] [--decel D] [--for S]` (MAJ; the flags
//! are the engine's `JogSpec`, `spec_args.rs`), hold to run: the jog runs
//! while this command runs — its lease (500 ms) is renewed every 100 ms by
//! the [`Jog`] handle's thread. Ctrl-C / SIGTERM
//! or `--for` elapsing end it here; `stop`, a soft or hard limit, a fault
//! or lost feedback end it in the supervisor. Killed outright (SIGKILL),
//! this command stops renewing and the jog stops within its lease.
//!
//! Exit: 0 when it ended without an axis fault (`--for`, `stop`, a soft
//! limit), 1 with one (or refused), 130 / 143 when interrupted (the axis
//! was stopped).

use super::client_error;
use super::moves::{follow_to_rest, op_error, report};
use crate::cli::JogArgs;
use motion_control::follow::{followed, Followed};
use motion_control::progress::Progress;
use motion_control::*;
use motion_report::MotionReport;
use std::time::{Duration, Instant};

pub fn jog(client: &mut Client, a: &JogArgs) -> i32 {
    let handle = match client.jog(&a.axis, a.jog.spec) {
        Ok(j) => j,
        Err(e) => return op_error(a.json, "jog", &e),
    };
    let axes = followed(handle.answer());
    let cycle = handle.answer().cycle;
    let mut progress = Progress::new();
    if let Err(e) = hold(client, &handle, &axes, cycle, a.for_s, &mut progress) {
        drop(handle);
        return client_error(a.json, &e);
    }
    // Ends this jog if it still runs (a stop of this jog only).
    if let Some(problem) = handle.end() {
        log::warn!("{problem}");
    }
    match follow_to_rest(client, &axes, cycle, &mut progress) {
        Err(e) => client_error(a.json, &e),
        Ok(rows) => report(a.json, MotionReport { axes: rows }),
    }
}

/// Holds the jog until Ctrl-C / SIGTERM, `for_s` elapsing, or the jog ending
/// by itself (its operation over on every axis, or a renewal refused).
fn hold(
    client: &mut Client,
    handle: &Jog,
    axes: &[Followed],
    after_cycle: u64,
    for_s: Option<f64>,
    progress: &mut Progress,
) -> Result<(), ClientError> {
    let until = for_s.map(|s| Instant::now() + Duration::from_secs_f64(s));
    let members: Vec<usize> = axes.iter().map(|x| x.index).collect();
    loop {
        if motion_rt::termination::received().is_some()
            || until.is_some_and(|u| Instant::now() >= u)
            || handle.ended()
        {
            return Ok(());
        }
        let st = client.status(Duration::from_secs(2))?;
        if st.cycle > after_cycle {
            progress.show_motion(&st, &members);
            let over = axes.iter().all(|x| {
                st.axes()
                    .get(x.index)
                    .is_none_or(|e| e.op_id() != x.op_id || !e.in_motion())
            });
            if over {
                return Ok(());
            }
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}
