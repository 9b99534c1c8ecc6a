//! The alternating slices: in each, the supervisor on the demo machine, on
//! the 64-axis machine (homing), with the EtherCAT backend (`--ethercat`),
//! then cyclictest, one after the other, until each has run `--duration`.
//! Alternating, not back to back, so that every tool sees the same host
//! noise: on a VM the noise changes by the minute.
//!
//! The first failure of any tool ends the slices (what ran is still
//! reported); so does SIGINT/SIGTERM.

use crate::cli::Opts;
use crate::cyclictest_slice::{self, CtSlice};
use crate::homing64::{self, Homing64};
use crate::supervisor::{self, leftover_shm, our_slice, OurSlice};
use motion_bench::ecat::{self, BusRun, EcatRig};
use motion_bench::hist::us;
use motion_bench::host::OtherRt;
use motion_bench::machine::{self, Machine, Supervisor};
use motion_bench::proc::{self, Running};
use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// Slices of `--slice` s that make up `--duration` (the last one shorter).
pub fn count(o: &Opts) -> usize {
    (o.duration / o.slice - 1e-9).ceil().max(1.0) as usize
}

/// Seconds of slice `i`.
fn len(o: &Opts, i: usize) -> f64 {
    (o.duration - i as f64 * o.slice).min(o.slice)
}

/// What the slices run with.
pub struct Plan<'a> {
    pub o: &'a Opts,
    /// Number of slices ([`count`]).
    pub slices: usize,
    /// Makes the service prefixes unique to this bench.
    pub pid: u32,
    /// Configs and interval logs of the runs.
    pub tmp: &'a Path,
    /// Start of the bench: slices are timed from here.
    pub t0: Instant,
    pub supervisor: &'a Path,
    pub motionctl: &'a Path,
    /// The veth pair and emulated drives (`--ethercat`).
    pub rig: Option<&'a EcatRig>,
    /// None: the cyclictest half is skipped.
    pub cyclictest: Option<&'a Path>,
}

/// Everything the slices measured, and how they ended.
#[derive(Default)]
pub struct Collected {
    /// The demo machine, idle.
    pub ours: Vec<OurSlice>,
    /// The 64-axis machine, homing.
    pub ours64: Vec<OurSlice>,
    /// The demo machine on the EtherCAT backend.
    pub ours_ecat: Vec<OurSlice>,
    pub homing64: Homing64,
    /// motion-io's bus round trips, one per EtherCAT slice that reported it.
    pub bus_runs: Vec<BusRun>,
    pub ct: Vec<CtSlice>,
    /// cyclictest's command line as reported (empty if it never ran).
    pub ct_command: String,
    /// The supervisors' warnings (each once).
    pub warnings: BTreeSet<String>,
    pub failures: Vec<String>,
    pub interrupted: bool,
}

/// Whether the slices go on after one tool's run.
#[derive(PartialEq)]
enum Flow {
    Go,
    /// Interrupted, or a tool failed (recorded in [`Collected`]).
    Stop,
}

/// Runs the slices. An `Err` is a bench that could not go on (a config or
/// a process that could not be made), not a tool that failed.
pub fn run(p: &Plan, other_rt: &mut OtherRt) -> Result<Collected, String> {
    let mut c = Collected::default();
    for i in 0..p.slices {
        let len = len(p.o, i);
        if ours_demo(p, i, len, &mut c)? == Flow::Stop {
            break;
        }
        if p.o.axes64 && ours_axes64(p, i, len, &mut c)? == Flow::Stop {
            break;
        }
        if let Some(rig) = p.rig {
            if ours_ethercat(p, rig, i, len, &mut c)? == Flow::Stop {
                break;
            }
        }
        if let Some(ct_bin) = p.cyclictest {
            if cyclictest(p, ct_bin, i, len, &mut c)? == Flow::Stop {
                break;
            }
        }
        other_rt.note("during the bench");
    }
    if proc::stop_requested() {
        c.interrupted = true;
    }
    Ok(c)
}

/// The `[supervisor]` section of every run: the bench's period, CPU and
/// priority, and a prefix of its own.
fn sup(o: &Opts, prefix: &str) -> Supervisor {
    Supervisor {
        cycle_us: o.period_us,
        cpu: o.cpu,
        priority: o.priority,
        service_prefix: prefix.to_string(),
    }
}

/// One series of supervisor slices: the letter of its service prefixes,
/// its name in the progress lines and failures.
struct Series {
    letter: char,
    label: &'static str,
}

/// One supervisor slice of a series: `launch` runs it under `prefix` with
/// its interval log at `hlog` and returns how it ended with whatever else
/// it measured; `keep` files the slice (and that) and returns what to add
/// to the progress line. The stop request, the report, the progress line,
/// the failure and the clean-up are the same for every series.
fn our_slice_of<X>(
    p: &Plan,
    i: usize,
    len: f64,
    c: &mut Collected,
    series: Series,
    launch: impl FnOnce(&str, &Path) -> Result<(proc::Ended, X), String>,
    keep: impl FnOnce(&mut Collected, OurSlice, Vec<String>, X, &proc::Ended) -> String,
) -> Result<Flow, String> {
    if proc::stop_requested() {
        c.interrupted = true;
        return Ok(Flow::Stop);
    }
    let prefix = format!("mbj{}{}{i}", p.pid, series.letter);
    let hlog_path = p.tmp.join(format!("{}{i}.hlog", series.letter));
    let start = p.t0.elapsed();
    let (ended, extra) = launch(&prefix, &hlog_path)?;
    if ended.interrupted {
        c.interrupted = true;
        return Ok(Flow::Stop);
    }
    match our_slice(&ended, &hlog_path, start, len) {
        Ok((s, w)) => {
            let line = format!(
                "jitter: slice {}/{} {:<11} {:>6} cycles, wake-up p99 {:>7} µs, max {:>7} µs, {} deadline miss(es), {} late repl(ies)",
                i + 1,
                p.slices,
                format!("{}:", series.label),
                s.cycles,
                us(s.json_wakeup.p99),
                us(s.json_wakeup.max),
                s.misses,
                s.late
            );
            let more = keep(c, s, w, extra, &ended);
            eprintln!("{line}{more}");
        }
        Err(e) => {
            c.failures.push(format!(
                "slice {}: motion-supervisor ({}): {e}",
                i + 1,
                series.label
            ));
            return Ok(Flow::Stop);
        }
    }
    leftover_shm(&prefix, &mut c.warnings);
    Ok(Flow::Go)
}

/// The supervisor on the demo machine, idle.
fn ours_demo(p: &Plan, i: usize, len: f64, c: &mut Collected) -> Result<Flow, String> {
    let series = Series {
        letter: 's',
        label: "ours",
    };
    our_slice_of(
        p,
        i,
        len,
        c,
        series,
        |prefix, hlog| {
            let (toml, _) = machine::demo_with(&sup(p.o, prefix))?;
            let ended = supervisor::run(
                p.supervisor,
                p.tmp,
                &format!("slice{i}"),
                &toml,
                prefix,
                len,
                hlog,
            )?;
            Ok((ended, ()))
        },
        |c, s, w, (), _| {
            c.warnings.extend(w);
            c.ours.push(s);
            String::new()
        },
    )
}

/// The supervisor with 64 axes, homing in parallel again and again.
fn ours_axes64(p: &Plan, i: usize, len: f64, c: &mut Collected) -> Result<Flow, String> {
    let series = Series {
        letter: 'a',
        label: "64 axes",
    };
    our_slice_of(
        p,
        i,
        len,
        c,
        series,
        |prefix, hlog| {
            let (toml, _) = Machine::Axes64.with(&sup(p.o, prefix))?;
            homing64::run(
                p.supervisor,
                p.motionctl,
                p.tmp,
                &format!("axes64_{i}"),
                &toml,
                prefix,
                len,
                hlog,
            )
        },
        |c, s, w, h: Homing64, _| {
            let more = format!(
                "; {} homing(s) of 64 axes: {} ok, {} failed, {} cut off by the slice's end",
                h.started, h.ok, h.failed, h.cut_off
            );
            c.warnings
                .extend(w.into_iter().map(|w| format!("64 axes: {w}")));
            c.ours64.push(s);
            c.homing64.merge(h);
            more
        },
    )
}

/// The supervisor on the demo machine with the EtherCAT backend.
fn ours_ethercat(
    p: &Plan,
    rig: &EcatRig,
    i: usize,
    len: f64,
    c: &mut Collected,
) -> Result<Flow, String> {
    let series = Series {
        letter: 'e',
        label: "EtherCAT",
    };
    our_slice_of(
        p,
        i,
        len,
        c,
        series,
        |prefix, hlog| {
            let (toml, _) = machine::demo_with(&sup(p.o, prefix))?;
            let (toml, _) = ecat::on_ethercat(&toml, rig.interface())?;
            let ended = supervisor::run(
                p.supervisor,
                p.tmp,
                &format!("ecat{i}"),
                &toml,
                prefix,
                len,
                hlog,
            )?;
            Ok((ended, ()))
        },
        |c, s, w, (), ended| {
            let bus = ecat::bus_run(&ended.stderr);
            let more = format!(
                "; bus round trip {}",
                bus.map_or("not reported".to_string(), |b| format!(
                    "p50 {} / p99 {} / max {} µs, {} lost frame(s)",
                    us(b.p50),
                    us(b.p99),
                    us(b.max),
                    b.lost
                ))
            );
            c.warnings
                .extend(w.into_iter().map(|w| format!("EtherCAT: {w}")));
            c.ours_ecat.push(s);
            match bus {
                Some(b) => c.bus_runs.push(b),
                None => {
                    c.warnings
                        .insert("EtherCAT: motion-io reported no bus summary in a slice".into());
                }
            }
            more
        },
    )
}

/// cyclictest, as many periods as fit in the slice.
fn cyclictest(
    p: &Plan,
    ct_bin: &Path,
    i: usize,
    len: f64,
    c: &mut Collected,
) -> Result<Flow, String> {
    if proc::stop_requested() {
        c.interrupted = true;
        return Ok(Flow::Stop);
    }
    let o = p.o;
    let period_s = f64::from(o.period_us) * 1e-6;
    let loops = ((len / period_s).round() as u64).max(1);
    let hist_path = p.tmp.join(format!("ct{i}.hist"));
    let mut cmd = Command::new(ct_bin);
    let (args, shown) = cyclictest_slice::command(o, loops, &hist_path);
    c.ct_command = shown;
    cmd.args(&args);
    let start = p.t0.elapsed();
    let ended = Running::spawn(&mut cmd, "cyclictest", true, false)?
        .wait(Duration::from_secs_f64(len + 30.0), Duration::from_secs(3));
    if ended.interrupted {
        c.interrupted = true;
        return Ok(Flow::Stop);
    }
    match cyclictest_slice::ct_slice(&ended, &hist_path, start, loops as f64 * period_s) {
        Ok(s) => {
            eprintln!(
                "jitter: slice {}/{} cyclictest: {:>6} samples, wake-up p99 {:>7} µs, max {:>7} µs",
                i + 1,
                p.slices,
                s.hist.samples(),
                us(s.hdr.value_at_quantile(0.99) as f64 / 1000.0),
                us(s.hist.max_us as f64)
            );
            c.ct.push(s);
        }
        Err(e) => {
            c.failures.push(format!("slice {}: cyclictest: {e}", i + 1));
            return Ok(Flow::Stop);
        }
    }
    Ok(Flow::Go)
}
