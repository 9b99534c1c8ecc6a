//! One trial: a fresh supervisor, the spy, a homing of X, the signal to its
//! motion-io once X cruises, the stop; then the reaction time and its
//! context from the spy's recording.
//!
//! Observation point: a spy subscriber on the I/O process's command topic
//! (the frames' services admit the peer plus one observer). Every command
//! frame carries the supervisor's `CLOCK_MONOTONIC` taken right before it
//! was sent (`header.timestamp_ns`); the bench takes `CLOCK_MONOTONIC` right
//! before `kill(2)`. Both are the same system-wide clock, so the reaction
//! time is the difference of two timestamps, whatever the spy's own delay.
//! The spy also subscribes to the feedback topic: the last feedback frame
//! motion-io published (its own timestamp) shows when the silence began.

use crate::{Opts, Sig};
use motion_bench::bins::Binaries;
use motion_bench::drive;
use motion_bench::homing;
use motion_bench::machine;
use motion_bench::outcome::{self, Bench};
use motion_bench::proc::{self, Running};
use motion_bench::spy::{Cmd, Recording, Spy};
use motion_frames::CW_ENABLE;
use motion_ipc::monotonic_ns;
use serde::Serialize;
use std::path::Path;
use std::process::Command;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// `counts_per_unit` of the bench's axis.
const COUNTS_PER_UNIT: f64 = 1000.0;

/// One trial's result.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Trial {
    pub signal: Sig,
    pub index: u32,
    pub prefix: String,
    /// Signal → first stopping command, ms.
    pub reaction_ms: Option<f64>,
    /// Last feedback motion-io published → first stopping command, ms.
    pub from_last_feedback_ms: Option<f64>,
    /// Signal → the last command sent before it, ms (negative: the phase of
    /// the signal within the cycle).
    pub last_cmd_before_signal_ms: Option<f64>,
    /// Commands sent after the signal up to the stopping one (that one included).
    pub commands_until_stop: Option<u64>,
    /// Frames the spy missed (sequence gaps) from 20 ms before the signal to the stop.
    pub spy_missed: u64,
    /// Velocity of the first stopping command, units/s, and of the one before.
    pub stop_velocity: Option<f64>,
    pub velocity_before: Option<f64>,
    /// kill(2) itself, µs.
    pub kill_us: f64,
    /// The homing's result row: err, exerr, error text.
    pub err: Option<u16>,
    pub exerr: Option<u16>,
    pub error: Option<String>,
    pub problems: Vec<String>,
}

/// What the spy thread shares with the main thread while it runs.
#[derive(Default)]
struct Shared {
    /// Send time of the first frame of the current run of cruise frames (0: not cruising).
    cruise_since: AtomicU64,
    /// CLOCK_MONOTONIC right before kill(2) (0: not yet).
    signal_ns: AtomicU64,
    /// Send time of the first stopping frame after the signal (0: none yet).
    stop_seen: AtomicU64,
}

/// A command is a stopping one: slower than the cruise or the power stage off.
fn stopping(c: &Cmd, cruise: f64) -> bool {
    c.velocity.abs() < cruise * (1.0 - 1e-6) || c.control_word & CW_ENABLE == 0
}

fn cruising(c: &Cmd, cruise: f64) -> bool {
    (c.velocity.abs() - cruise).abs() <= cruise * 1e-6 && c.control_word & CW_ENABLE != 0
}

/// A supervisor of the long-seek axis under `prefix`, ready, and the pid of
/// the one motion-io it spawned.
fn daemon(o: &Opts, b: &Binaries, tmp: &Path, prefix: &str) -> Result<(Running, u32), String> {
    let s = o.cycle.supervisor(prefix);
    let (toml, _) = machine::long_seek_axis_with(&s, tmp.to_str(), o.speed, o.speed * 60.0)?;
    let daemon = drive::start_machine(b, tmp, prefix, &toml)?;
    match proc::io_children(daemon.pid()).as_slice() {
        [p] => Ok((daemon, *p)),
        io => {
            let e =
                format!("{prefix}: expected one motion-io child of the supervisor, found {io:?}");
            drive::stop_run(daemon, Duration::from_secs(20));
            Err(e)
        }
    }
}

/// One trial of signal `sig`; `leftovers` collects what it left behind.
pub fn run(
    o: &Opts,
    b: &Binaries,
    bench: &Bench,
    (sig, index): (Sig, u32),
    leftovers: &mut Vec<String>,
) -> Result<Trial, String> {
    let prefix = format!(
        "mbd{}{}{index}",
        std::process::id(),
        ["k", "s"][sig as usize]
    );
    let mut t = Trial {
        signal: sig,
        index,
        prefix: prefix.clone(),
        ..Trial::default()
    };
    let cruise = o.speed * COUNTS_PER_UNIT;
    let (daemon, io_pid) = daemon(o, b, &bench.tmp, &prefix)?;
    // the spy, which also watches for the cruise and the stop
    let shared = Arc::new(Shared::default());
    let sh = shared.clone();
    let on_cmd = move |c: &Cmd| {
        let at = match sh.signal_ns.load(Ordering::Acquire) {
            0 if !cruising(c, cruise) => return sh.cruise_since.store(0, Ordering::Release),
            0 => &sh.cruise_since,
            sig if c.ts > sig && stopping(c, cruise) => &sh.stop_seen,
            _ => return,
        };
        // the first frame of the cruise, the first stopping one
        let _ = at.compare_exchange(0, c.ts, Ordering::AcqRel, Ordering::Acquire);
    };
    let spy = Spy::start(&prefix, "io", o.spy_cpu(), o.spy_priority, 200_000, on_cmd);
    let mut home = None;
    let result = spy.as_ref().map_err(String::clone).and_then(|_| {
        let mut cmd = Command::new(&b.motionctl);
        cmd.args(["--service-prefix", &prefix]);
        cmd.args(["home", "X", "--json", "--timeout", "120"]);
        home = Some(Running::spawn(&mut cmd, "motionctl home", true, false)?);
        signal(o, &shared, io_pid, sig, &mut t)
    });
    let signalled = result.is_ok();
    let rec = spy.map_or_else(|_| Recording::default(), |mut s| s.finish());
    t.problems
        .extend(rec.error.iter().map(|e| format!("spy: {e}")));
    t.problems.extend(result.err());
    if let Some(h) = home {
        homing_result(&mut t, h);
    }
    if signalled && sig == Sig::Stop {
        // SAFETY: kill(2) on the motion-io child of the supervisor we started.
        unsafe { libc::kill(io_pid as i32, libc::SIGCONT) };
    }
    let ended = drive::stop_run(daemon, Duration::from_secs(30));
    if !ended.success() {
        let (how, tail) = (ended.describe(), proc::tail(&ended.stderr, 3));
        t.problems
            .push(format!("the supervisor ended with {how} ({tail})"));
    }
    if let Some((found, note)) = outcome::cleaned(&prefix) {
        t.problems.push(format!("left behind {note}"));
        leftovers.extend(found);
    }
    let _ = std::fs::remove_file(bench.tmp.join(format!("{prefix}.toml")));
    if signalled {
        analyse(
            &mut t,
            &rec,
            shared.signal_ns.load(Ordering::Acquire),
            cruise,
        );
    }
    Ok(t)
}

/// Once X has cruised `--cruise-ms`, at a random phase within the cycle:
/// the signal to motion-io; then up to 5 s for the stop, and a few frames
/// more.
fn signal(o: &Opts, shared: &Shared, io_pid: u32, sig: Sig, t: &mut Trial) -> Result<(), String> {
    let until = Instant::now() + Duration::from_secs(15);
    loop {
        let since = shared.cruise_since.load(Ordering::Acquire);
        if since != 0 && monotonic_ns().saturating_sub(since) >= o.cruise_ms * 1_000_000 {
            break;
        }
        if Instant::now() > until || proc::stop_requested() {
            return Err("the axis did not cruise at Home Speed".into());
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    std::thread::sleep(Duration::from_nanos(
        monotonic_ns() % (u64::from(o.cycle.period_us) * 1000),
    ));
    let t_sig = monotonic_ns();
    shared.signal_ns.store(t_sig, Ordering::Release);
    // SAFETY: kill(2) on the motion-io child of the supervisor we started.
    let rc = unsafe { libc::kill(io_pid as i32, sig.number()) };
    let t_after = monotonic_ns();
    if rc != 0 {
        let e = std::io::Error::last_os_error();
        return Err(format!("kill({io_pid}, {}): {e}", sig.name()));
    }
    t.kill_us = (t_after - t_sig) as f64 / 1000.0;
    let until = Instant::now() + Duration::from_secs(5);
    while shared.stop_seen.load(Ordering::Acquire) == 0 && Instant::now() < until {
        std::thread::sleep(Duration::from_millis(1));
    }
    // a few more frames after the stop
    std::thread::sleep(Duration::from_millis(30));
    Ok(())
}

/// The homing's own result row.
fn homing_result(t: &mut Trial, home: Running) {
    let ended = home.wait(Duration::from_secs(10), Duration::from_secs(3));
    let Some(v) = homing::last_json(&ended.stdout) else {
        let (how, tail) = (ended.describe(), proc::tail(&ended.stderr, 3));
        return t
            .problems
            .push(format!("motionctl home printed nothing ({how}; {tail})"));
    };
    match homing::rows_of(&v).first() {
        Some(r) => (t.err, t.exerr, t.error) = (Some(r.err), Some(r.exerr), r.error.clone()),
        None => t.problems.push(format!("motionctl home: no row: {v}")),
    }
}

/// Reaction time and its context from the spy's recording.
fn analyse(t: &mut Trial, rec: &Recording, t_sig: u64, cruise: f64) {
    let cmds = &rec.cmds;
    let Some(k) = cmds
        .iter()
        .position(|c| c.ts > t_sig && stopping(c, cruise))
    else {
        return t.problems.push(format!(
            "no stopping command seen ({} commands recorded)",
            cmds.len()
        ));
    };
    let stop = cmds[k];
    t.reaction_ms = Some((stop.ts - t_sig) as f64 / 1e6);
    t.stop_velocity = Some(stop.velocity / COUNTS_PER_UNIT);
    if let Some(before) = k.checked_sub(1).map(|j| cmds[j]) {
        t.velocity_before = Some(before.velocity / COUNTS_PER_UNIT);
        if !cruising(&before, cruise) {
            t.problems
                .push("the command before the stopping one was not at cruise speed".into());
        }
        if stop.seq != before.seq + 1 {
            t.problems.push(format!(
                "the spy missed {} command(s) just before the stopping one: the reaction may be \
                 up to that many cycles shorter",
                stop.seq - before.seq - 1
            ));
        }
    }
    if let Some(last) = cmds.iter().rev().find(|c| c.ts <= t_sig) {
        t.last_cmd_before_signal_ms = Some(-((t_sig - last.ts) as f64) / 1e6);
        t.commands_until_stop = Some(stop.seq.saturating_sub(last.seq));
    }
    // any slower command between the cruise and the signal?
    if cmds
        .iter()
        .any(|c| c.ts + 100_000_000 > t_sig && c.ts <= t_sig && !cruising(c, cruise))
    {
        t.problems
            .push("not at cruise speed in the 100 ms before the signal".into());
    }
    // frames the spy missed around the event
    let window: Vec<&Cmd> = cmds
        .iter()
        .filter(|c| c.ts + 20_000_000 >= t_sig && c.ts <= stop.ts)
        .collect();
    t.spy_missed = window
        .windows(2)
        .map(|w| w[1].seq.saturating_sub(w[0].seq + 1))
        .sum();
    let last_fb = rec
        .fbs
        .iter()
        .filter(|f| f.ts <= stop.ts)
        .max_by_key(|f| f.ts);
    t.from_last_feedback_ms = last_fb.map(|fb| (stop.ts as f64 - fb.ts as f64) / 1e6);
}
