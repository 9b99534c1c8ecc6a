//! Dead-peer reaction time: from a signal (SIGKILL, or SIGSTOP) sent to the
//! `motion-io` process while an axis is homing to the first stopping
//! command the supervisor publishes for that axis. See `bench/README.md`.
//!
//! Observation point: a spy subscriber on the I/O process's command topic
//! (the frames' services admit the peer plus one observer). Every command
//! frame carries the supervisor's `CLOCK_MONOTONIC` taken right before it
//! was sent (`header.timestamp_ns`); the bench takes `CLOCK_MONOTONIC` right
//! before `kill(2)`. Both are the same system-wide clock, so the reaction
//! time is the difference of two timestamps, whatever the spy's own delay.
//! The spy also subscribes to the feedback topic: the last feedback frame
//! motion-io published (its own timestamp) shows when the silence began.

use clap::{Parser, ValueEnum};
use motion_bench::drive::{self, Binaries};
use motion_bench::machine::{self, Supervisor};
use motion_bench::proc::{self, Running};
use motion_bench::spy::{Cmd, Recording, Spy};
use motion_bench::sys;
use motion_frames::{monotonic_ns, CW_ENABLE};
use serde::Serialize;
use serde_json::json;
use std::path::PathBuf;
use std::process::Command;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// `bench/out` of the source tree, wherever the bench is started from.
const DEFAULT_OUT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/out");

/// `counts_per_unit` of the bench's axis.
const COUNTS_PER_UNIT: f64 = 1000.0;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
enum Sig {
    /// SIGKILL: the process is gone.
    Kill,
    /// SIGSTOP: the process hangs (SIGCONT after the trial).
    Stop,
}

impl Sig {
    fn number(self) -> i32 {
        match self {
            Sig::Kill => libc::SIGKILL,
            Sig::Stop => libc::SIGSTOP,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Sig::Kill => "SIGKILL",
            Sig::Stop => "SIGSTOP",
        }
    }
}

#[derive(Debug, Parser)]
#[command(
    name = "deadpeer",
    about = "Measures how fast the supervisor stops a homing axis when its motion-io is \
             SIGKILLed or SIGSTOPped: signal → first stopping command, observed by a spy \
             subscriber on the command topic (the supervisor's own send timestamps).",
    after_help = "Exit status: 0 when every trial ran (whatever the times: they are figures, not \
                  assertions), 1 if a trial could not be run, 2 on a command-line mistake, 130 if \
                  interrupted."
)]
struct Opts {
    /// Trials per signal.
    #[arg(long, default_value_t = 20)]
    trials: u32,
    /// Signals, in this order.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "kill,stop")]
    signals: Vec<Sig>,
    /// Cycle period, µs.
    #[arg(long, default_value_t = 1000)]
    period_us: u32,
    /// CPU of the cycle (and of motion-io, the supervisor's default).
    #[arg(long, default_value_t = 1)]
    cpu: usize,
    /// SCHED_FIFO priority of the cycle.
    #[arg(long, default_value_t = 80)]
    priority: i32,
    /// CPU of the spy thread (default: another CPU than --cpu).
    #[arg(long)]
    spy_cpu: Option<usize>,
    /// SCHED_FIFO priority of the spy thread (0: normal scheduling).
    #[arg(long, default_value_t = 70)]
    spy_priority: i32,
    /// Home Speed of the axis, units/s (its seek takes 60 s at most).
    #[arg(long, default_value_t = 20.0)]
    speed: f64,
    /// How long the axis cruises at Home Speed before the signal, ms (plus
    /// a random part of one period, so the signal falls anywhere in the cycle).
    #[arg(long, default_value_t = 200)]
    cruise_ms: u64,
    /// Output directory (deadpeer.json).
    #[arg(long, default_value = DEFAULT_OUT)]
    out: PathBuf,
    /// motion-supervisor binary (motion-io and motionctl next to it).
    #[arg(long)]
    supervisor: Option<PathBuf>,
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

/// One trial's result.
#[derive(Clone, Debug, Serialize)]
struct Trial {
    signal: Sig,
    index: u32,
    prefix: String,
    /// Signal → first stopping command, ms.
    reaction_ms: Option<f64>,
    /// Last feedback motion-io published → first stopping command, ms.
    from_last_feedback_ms: Option<f64>,
    /// Signal → the last command sent before it, ms (negative: the phase of
    /// the signal within the cycle).
    last_cmd_before_signal_ms: Option<f64>,
    /// Commands sent after the signal up to the stopping one (that one included).
    commands_until_stop: Option<u64>,
    /// Frames the spy missed (sequence gaps) from 20 ms before the signal to the stop.
    spy_missed: u64,
    /// Velocity of the first stopping command, units/s, and of the one before.
    stop_velocity: Option<f64>,
    velocity_before: Option<f64>,
    /// kill(2) itself, µs.
    kill_us: f64,
    /// The homing's result row: err, exerr, error text.
    err: Option<u16>,
    exerr: Option<u16>,
    error: Option<String>,
    problems: Vec<String>,
}

fn main() {
    let o = Opts::parse();
    std::process::exit(match real_main(&o) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("deadpeer: FAILED: {e}");
            1
        }
    });
}

fn real_main(o: &Opts) -> Result<i32, String> {
    if o.cpu >= sys::cpus() {
        eprintln!(
            "deadpeer: --cpu {}: this machine has {} CPUs",
            o.cpu,
            sys::cpus()
        );
        return Ok(2);
    }
    if !(o.speed > 0.0 && o.speed <= 1000.0) {
        eprintln!("deadpeer: --speed must be within (0, 1000] units/s");
        return Ok(2);
    }
    proc::install_stop_handler();
    let b = Binaries::find(o.supervisor.as_deref())?;
    let spy_cpu = o.spy_cpu.unwrap_or(if o.cpu == 0 { 1 } else { 0 });
    let state = std::env::temp_dir().join(format!("motion-bench-deadpeer-{}", std::process::id()));
    std::fs::create_dir_all(&state).map_err(|e| format!("{}: {e}", state.display()))?;
    let _rm = RemoveDir(state.clone());
    std::fs::create_dir_all(&o.out).map_err(|e| format!("{}: {e}", o.out.display()))?;
    let (preemption, _) = sys::preemption();
    let load_before = sys::loadavg();
    eprintln!(
        "deadpeer: {} trial(s) per signal ({}), {} µs cycle, SCHED_FIFO {} on CPU {} (motion-io there too), \
         spy on CPU {spy_cpu}; feedback_timeout_ms 10 (default); kernel {} ({preemption}); load {load_before}",
        o.trials,
        o.signals.iter().map(|s| s.name()).collect::<Vec<_>>().join(", "),
        o.period_us,
        o.priority,
        o.cpu,
        sys::kernel()
    );
    for t in sys::other_rt_tasks() {
        eprintln!("deadpeer: WARNING: another real-time thread is running: {t}");
    }
    let t0 = Instant::now();
    let mut trials: Vec<Trial> = Vec::new();
    let mut leftovers: Vec<String> = Vec::new();
    let mut interrupted = false;
    'all: for &sig in &o.signals {
        for i in 0..o.trials {
            if proc::stop_requested() {
                interrupted = true;
                break 'all;
            }
            let t = trial(o, &b, &state, spy_cpu, sig, i, &mut leftovers)?;
            eprintln!(
                "deadpeer: {} trial {}/{}: signal → stop {} ms (from the last feedback {} ms), {} command(s), result {}/{} {}{}",
                sig.name(),
                i + 1,
                o.trials,
                t.reaction_ms.map_or("-".into(), |x| format!("{x:.2}")),
                t.from_last_feedback_ms.map_or("-".into(), |x| format!("{x:.2}")),
                t.commands_until_stop.map_or("-".into(), |x| x.to_string()),
                t.err.map_or("-".into(), |x| x.to_string()),
                t.exerr.map_or("-".into(), |x| x.to_string()),
                t.error.as_deref().unwrap_or(""),
                if t.problems.is_empty() {
                    String::new()
                } else {
                    format!(" PROBLEMS: {}", t.problems.join("; "))
                }
            );
            trials.push(t);
        }
    }
    let wall = t0.elapsed().as_secs_f64();

    // --- report
    let period_ms = f64::from(o.period_us) / 1000.0;
    let mut text = String::new();
    let mut line = |s: String| {
        text.push_str(&s);
        text.push('\n');
    };
    line(format!(
        "== deadpeer: signal to motion-io while X seeks at {} units/s → first stopping command, {} µs cycle, SCHED_FIFO {} on CPU {}",
        o.speed, o.period_us, o.priority, o.cpu
    ));
    line(format!(
        "kernel {} | preemption: {preemption} | {} CPUs | load before {load_before}, after {} | wall {:.0} s",
        sys::kernel(),
        sys::cpus(),
        sys::loadavg(),
        wall
    ));
    line(format!(
        "configured bound: feedback_timeout_ms = 10 (default) → the rule trips after > 10 ms of missing answers, + 1 cycle ({period_ms} ms) to the first slower command; goal ≤ 20 ms"
    ));
    line(String::new());
    line(format!(
        "{:<10}{:>7}{:>9}{:>9}{:>9}{:>9}{:>9}   {:<28}{:>12}",
        "signal",
        "trials",
        "min ms",
        "p50 ms",
        "p90 ms",
        "max ms",
        "mean",
        "from last feedback p50/max",
        "12/40 result"
    ));
    let mut summary = Vec::new();
    for &sig in &o.signals {
        let ts: Vec<&Trial> = trials.iter().filter(|t| t.signal == sig).collect();
        let mut r: Vec<f64> = ts.iter().filter_map(|t| t.reaction_ms).collect();
        let mut f: Vec<f64> = ts.iter().filter_map(|t| t.from_last_feedback_ms).collect();
        r.sort_by(f64::total_cmp);
        f.sort_by(f64::total_cmp);
        let lost = ts
            .iter()
            .filter(|t| t.err == Some(12) && t.exerr == Some(40))
            .count();
        let mean = if r.is_empty() {
            f64::NAN
        } else {
            r.iter().sum::<f64>() / r.len() as f64
        };
        line(format!(
            "{:<10}{:>7}{:>9}{:>9}{:>9}{:>9}{:>9}   {:<28}{:>12}",
            sig.name(),
            format!("{}/{}", r.len(), ts.len()),
            fmt(r.first().copied()),
            fmt(pct(&r, 0.5)),
            fmt(pct(&r, 0.9)),
            fmt(r.last().copied()),
            fmt((!r.is_empty()).then_some(mean)),
            format!("{} / {}", fmt(pct(&f, 0.5)), fmt(f.last().copied())),
            format!("{lost} of {}", ts.len())
        ));
        summary.push(json!({
            "signal": sig,
            "trials": ts.len(),
            "measured": r.len(),
            "reaction_ms": {"min": r.first(), "p50": pct(&r, 0.5), "p90": pct(&r, 0.9), "max": r.last(), "mean": (!r.is_empty()).then_some(mean)},
            "from_last_feedback_ms": {"min": f.first(), "p50": pct(&f, 0.5), "max": f.last()},
            "results_12_40": lost,
        }));
    }
    let problems: Vec<String> = trials
        .iter()
        .flat_map(|t| {
            t.problems
                .iter()
                .map(move |p| format!("{} trial {}: {p}", t.signal.name(), t.index + 1))
        })
        .collect();
    line(String::new());
    line("p50/p90: nearest rank; reaction = the supervisor's send time of the first command slower than the cruise (or disabling) − CLOCK_MONOTONIC right before kill(2)".into());
    if !problems.is_empty() {
        line(format!("problems ({}):", problems.len()));
        for p in problems.iter().take(30) {
            line(format!("  {p}"));
        }
    }
    if leftovers.is_empty() {
        line("shared memory and session files: nothing left behind".into());
    } else {
        line(format!(
            "left behind (then cleaned by the bench): {}",
            leftovers.join(", ")
        ));
    }
    print!("{text}");
    let report = json!({
        "period_us": o.period_us,
        "cpu": o.cpu,
        "priority": o.priority,
        "spy_cpu": spy_cpu,
        "spy_priority": o.spy_priority,
        "speed": o.speed,
        "feedback_timeout_ms": 10,
        "kernel": sys::kernel(),
        "preemption": preemption,
        "load_before": load_before,
        "load_after": sys::loadavg(),
        "wall_s": wall,
        "summary": summary,
        "trials": trials,
        "leftovers": leftovers,
        "interrupted": interrupted,
    });
    let path = o.out.join(format!("deadpeer-{}us.json", o.period_us));
    std::fs::write(
        &path,
        serde_json::to_string_pretty(&report).unwrap_or_default() + "\n",
    )
    .map_err(|e| format!("{}: {e}", path.display()))?;
    println!("files: {}", path.display());
    Ok(if interrupted { 130 } else { 0 })
}

fn fmt(x: Option<f64>) -> String {
    x.map_or("-".into(), |x| format!("{x:.2}"))
}

/// Nearest-rank percentile of sorted `v`.
fn pct(v: &[f64], p: f64) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let k = ((p * v.len() as f64).ceil() as usize).clamp(1, v.len());
    Some(v[k - 1])
}

/// One trial: a fresh supervisor, the spy, a homing, the signal, the stop.
#[allow(clippy::too_many_arguments)]
fn trial(
    o: &Opts,
    b: &Binaries,
    state: &std::path::Path,
    spy_cpu: usize,
    sig: Sig,
    index: u32,
    leftovers: &mut Vec<String>,
) -> Result<Trial, String> {
    let prefix = format!(
        "mbd{}{}{index}",
        std::process::id(),
        match sig {
            Sig::Kill => "k",
            Sig::Stop => "s",
        }
    );
    let (toml, _) = machine::long_seek_axis_with(
        &Supervisor {
            cycle_us: o.period_us,
            cpu: o.cpu,
            priority: o.priority,
            service_prefix: prefix.clone(),
        },
        state.to_str(),
        o.speed,
        o.speed * 60.0,
    )?;
    let cfg = state.join(format!("{prefix}.toml"));
    std::fs::write(&cfg, toml).map_err(|e| format!("{}: {e}", cfg.display()))?;
    let mut t = Trial {
        signal: sig,
        index,
        prefix: prefix.clone(),
        reaction_ms: None,
        from_last_feedback_ms: None,
        last_cmd_before_signal_ms: None,
        commands_until_stop: None,
        spy_missed: 0,
        stop_velocity: None,
        velocity_before: None,
        kill_us: 0.0,
        err: None,
        exerr: None,
        error: None,
        problems: Vec::new(),
    };
    let cruise = o.speed * COUNTS_PER_UNIT;
    let mut daemon = drive::spawn_run(b, &cfg, &prefix, None, None)?;
    if let Err(e) =
        drive::wait_until_ready(&b.motionctl, &prefix, &mut daemon, Duration::from_secs(20))
    {
        let ended = drive::stop_run(daemon, Duration::from_secs(20));
        return Err(format!(
            "{prefix}: {e} ({}; {})",
            ended.describe(),
            drive::tail(&ended.stderr, 5)
        ));
    }
    let io = drive::io_children(daemon.pid());
    let io_pid = match io.as_slice() {
        [p] => *p,
        _ => {
            drive::stop_run(daemon, Duration::from_secs(20));
            return Err(format!(
                "{prefix}: expected one motion-io child of the supervisor, found {io:?}"
            ));
        }
    };

    // the spy, which also watches for the cruise and the stop
    let shared = Arc::new(Shared::default());
    let on_cmd = {
        let shared = shared.clone();
        move |c: &Cmd| {
            let sig = shared.signal_ns.load(Ordering::Acquire);
            if sig == 0 {
                if cruising(c, cruise) {
                    let _ = shared.cruise_since.compare_exchange(
                        0,
                        c.ts,
                        Ordering::AcqRel,
                        Ordering::Acquire,
                    );
                } else {
                    shared.cruise_since.store(0, Ordering::Release);
                }
            } else if c.ts > sig && stopping(c, cruise) {
                let _ =
                    shared
                        .stop_seen
                        .compare_exchange(0, c.ts, Ordering::AcqRel, Ordering::Acquire);
            }
        }
    };
    let spy = Spy::start(&prefix, "io", spy_cpu, o.spy_priority, 200_000, on_cmd);
    let mut home: Option<Running> = None;
    let mut signalled = false;
    let result = (|| -> Result<(), String> {
        if let Err(e) = &spy {
            return Err(e.clone());
        }
        let mut cmd = Command::new(&b.motionctl);
        cmd.args([
            "--service-prefix",
            &prefix,
            "home",
            "X",
            "--json",
            "--timeout",
            "120",
        ]);
        home = Some(Running::spawn(&mut cmd, "motionctl home", true, false)?);
        // cruising long enough?
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
        // a random phase within the cycle
        let jitter_ns = monotonic_ns() % (u64::from(o.period_us) * 1000);
        std::thread::sleep(Duration::from_nanos(jitter_ns));
        let t_sig = monotonic_ns();
        shared.signal_ns.store(t_sig, Ordering::Release);
        // SAFETY: kill(2) on the motion-io child of the supervisor we started.
        let rc = unsafe { libc::kill(io_pid as i32, sig.number()) };
        let t_after = monotonic_ns();
        if rc != 0 {
            return Err(format!(
                "kill({io_pid}, {}): {}",
                sig.name(),
                std::io::Error::last_os_error()
            ));
        }
        signalled = true;
        t.kill_us = (t_after - t_sig) as f64 / 1000.0;
        let until = Instant::now() + Duration::from_secs(5);
        while shared.stop_seen.load(Ordering::Acquire) == 0 && Instant::now() < until {
            std::thread::sleep(Duration::from_millis(1));
        }
        // a few more frames after the stop
        std::thread::sleep(Duration::from_millis(30));
        Ok(())
    })();
    let rec = spy.map_or_else(|_| Recording::default(), |mut s| s.finish());
    if let Some(e) = &rec.error {
        t.problems.push(format!("spy: {e}"));
    }
    if let Err(e) = &result {
        t.problems.push(e.clone());
    }
    // the homing's own result
    if let Some(h) = home.take() {
        let ended = h.wait(Duration::from_secs(10), Duration::from_secs(3));
        match drive::last_json(&ended.stdout) {
            Some(v) => {
                let rows = drive::rows_of(&v);
                if let Some(r) = rows.first() {
                    t.err = Some(r.err);
                    t.exerr = Some(r.exerr);
                    t.error = r.error.clone();
                } else {
                    t.problems.push(format!("motionctl home: no row: {v}"));
                }
            }
            None => t.problems.push(format!(
                "motionctl home printed nothing ({}; {})",
                ended.describe(),
                drive::tail(&ended.stderr, 3)
            )),
        }
    }
    if signalled && sig == Sig::Stop {
        // SAFETY: as above.
        unsafe {
            libc::kill(io_pid as i32, libc::SIGCONT);
        }
    }
    let ended = drive::stop_run(daemon, Duration::from_secs(30));
    if !ended.success() {
        t.problems.push(format!(
            "the supervisor ended with {} ({})",
            ended.describe(),
            drive::tail(&ended.stderr, 3)
        ));
    }
    let (found, remaining) = drive::clean_leftovers(&prefix);
    if !found.is_empty() {
        t.problems.push(format!(
            "left behind (then cleaned by the bench{}): {}",
            if remaining.is_empty() {
                ""
            } else {
                ", NOT all"
            },
            found.join(", ")
        ));
        leftovers.extend(found);
    }
    let _ = std::fs::remove_file(&cfg);
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

/// Reaction time and its context from the spy's recording.
fn analyse(t: &mut Trial, rec: &Recording, t_sig: u64, cruise: f64) {
    let cmds = &rec.cmds;
    let Some(k) = cmds
        .iter()
        .position(|c| c.ts > t_sig && stopping(c, cruise))
    else {
        t.problems.push(format!(
            "no stopping command seen ({} commands recorded)",
            cmds.len()
        ));
        return;
    };
    let stop = cmds[k];
    t.reaction_ms = Some((stop.ts - t_sig) as f64 / 1e6);
    t.stop_velocity = Some(stop.velocity / COUNTS_PER_UNIT);
    if k > 0 {
        let before = cmds[k - 1];
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
    let window = cmds
        .iter()
        .filter(|c| c.ts + 20_000_000 >= t_sig && c.ts <= stop.ts)
        .collect::<Vec<_>>();
    t.spy_missed = window
        .windows(2)
        .map(|w| w[1].seq.saturating_sub(w[0].seq + 1))
        .sum();
    if let Some(fb) = rec
        .fbs
        .iter()
        .filter(|f| f.ts <= stop.ts)
        .max_by_key(|f| f.ts)
    {
        t.from_last_feedback_ms = Some((stop.ts as f64 - fb.ts as f64) / 1e6);
    }
}

/// Removes a directory on drop.
struct RemoveDir(PathBuf);

impl Drop for RemoveDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
