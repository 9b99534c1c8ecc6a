//! The alternating slices: in each, the supervisor on the demo machine, on
//! the 64-axis machine (homing), with the EtherCAT backend (`--ethercat`),
//! then cyclictest, one after the other, until each has run `--duration`.
//! Alternating, not back to back, so that every tool sees the same host
//! noise: on a VM the noise changes by the minute.
//!
//! The first failure of any tool ends the slices (what ran is still
//! reported); so does SIGINT/SIGTERM.

use crate::bus::{bus_run, BusRun};
use crate::cli::Opts;
use motion_bench::bins::Binaries;
use motion_bench::cyclictest::{self, CtHistogram};
use motion_bench::ecat::{self, EcatRig};
use motion_bench::homing::Repeated;
use motion_bench::host::OtherRt;
use motion_bench::machine::{self, Machine};
use motion_bench::outcome;
use motion_bench::proc::{self, Running};
use motion_bench::slice::Slice;
use motion_bench::table::us;
use motion_bench::{drive, runs};
use motion_bench::{histogram, plot::RGBColor};
use std::collections::BTreeSet;
use std::path::Path;
use std::time::{Duration, Instant};

/// A supervisor variant measured in every slice.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// The demo machine, idle.
    Demo,
    /// The 64-axis machine, homing in parallel again and again.
    Axes64,
    /// The demo machine on the EtherCAT backend.
    Ethercat,
}

/// What a variant is called wherever it shows.
pub struct Names {
    /// Letter of its service prefixes and temporary files.
    pub letter: char,
    /// In the progress lines and failures.
    pub label: &'static str,
    /// Its tag in the interval log.
    pub tag: &'static str,
    /// Before its warnings.
    pub warn: &'static str,
    /// Its rows in the report: wake-up, ratio to cyclictest, deadline
    /// misses, compute, round trip, late replies; who failed.
    pub row: &'static str,
    pub ratio: &'static str,
    pub misses: &'static str,
    pub compute: &'static str,
    pub roundtrip: &'static str,
    pub late: &'static str,
    pub who: &'static str,
    /// Its curve in the plot.
    pub curve: &'static str,
    pub colour: RGBColor,
}

impl Variant {
    pub const ALL: [Variant; 3] = [Variant::Demo, Variant::Axes64, Variant::Ethercat];

    pub fn names(self) -> &'static Names {
        &NAMES[self as usize]
    }
}

const NAMES: [Names; 3] = [
    Names {
        letter: 's',
        label: "ours",
        tag: "ours",
        warn: "",
        row: "ours, demo (idle)",
        ratio: "ratio demo/cyclictest",
        misses: "ours, demo",
        compute: "compute, demo",
        roundtrip: "I/O round trip, demo",
        late: "demo",
        who: "the supervisor",
        curve: "ours, demo machine (idle)",
        colour: RGBColor(31, 111, 209),
    },
    Names {
        letter: 'a',
        label: "64 axes",
        tag: "ours_axes64",
        warn: "64 axes: ",
        row: "ours, 64 axes homing",
        ratio: "ratio 64 axes/cyclic.",
        misses: "ours, 64 axes homing",
        compute: "compute, 64 axes",
        roundtrip: "round trip, 64 axes",
        late: "64 axes:",
        who: "the supervisor (64 axes homing)",
        curve: "ours, 64 axes homing",
        colour: RGBColor(148, 103, 189),
    },
    Names {
        letter: 'e',
        label: "EtherCAT",
        tag: "ours_ethercat",
        warn: "EtherCAT: ",
        row: "ours, EtherCAT backend",
        ratio: "ratio EtherCAT/cyclic.",
        misses: "EtherCAT backend",
        compute: "compute, EtherCAT",
        roundtrip: "round trip, EtherCAT",
        late: "EtherCAT backend:",
        who: "the supervisor (EtherCAT backend)",
        curve: "ours, EtherCAT backend",
        colour: RGBColor(44, 160, 44),
    },
];

/// What the slices run with.
pub struct Plan<'a> {
    pub o: &'a Opts,
    pub slices: usize,
    /// Configs and interval logs of the runs.
    pub tmp: &'a Path,
    /// Start of the bench: slices are timed from here.
    pub t0: Instant,
    pub bins: &'a Binaries,
    /// The veth pair and emulated drives (`--ethercat`).
    pub rig: Option<&'a EcatRig>,
    /// None: the cyclictest half is skipped.
    pub cyclictest: Option<&'a Path>,
}

/// One cyclictest slice.
pub struct CtSlice {
    pub start: Duration,
    pub len: Duration,
    pub hist: CtHistogram,
    pub hdr: hdrhistogram::Histogram<u64>,
}

/// Everything the slices measured, and how they ended.
#[derive(Default)]
pub struct Collected {
    /// Per variant (`Variant as usize`), its slices.
    pub ours: [Vec<Slice>; 3],
    /// The 64-axis machine's homings (`motionctl home --parallel`).
    pub homing64: Repeated,
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

impl Collected {
    /// A stop was requested (noted): the slices end.
    fn stopped(&mut self) -> bool {
        self.interrupted |= proc::stop_requested();
        self.interrupted
    }
}

/// Runs the slices. An `Err` is a bench that could not go on (a config or
/// a process that could not be made), not a tool that failed.
pub fn run(p: &Plan, other_rt: &mut OtherRt) -> Result<Collected, String> {
    let mut c = Collected::default();
    let on = [true, p.o.axes64, p.rig.is_some()];
    'slices: for i in 0..p.slices {
        let len = p.o.slicing.len(i);
        for v in Variant::ALL.into_iter().filter(|&v| on[v as usize]) {
            if !our_slice(p, v, i, len, &mut c)? {
                break 'slices;
            }
        }
        if let Some(bin) = p.cyclictest {
            if !cyclictest(p, bin, i, len, &mut c)? {
                break;
            }
        }
        other_rt.note("during the bench");
    }
    c.stopped();
    Ok(c)
}

/// One supervisor slice of `v`; false: the slices end (interrupted, or the
/// run failed, recorded in `c`).
fn our_slice(p: &Plan, v: Variant, i: usize, len: f64, c: &mut Collected) -> Result<bool, String> {
    if c.stopped() {
        return Ok(false);
    }
    let n = v.names();
    let prefix = format!("mbj{}{}{i}", std::process::id(), n.letter);
    let sup = p.o.cycle.supervisor(&prefix);
    let (toml, _) = match (v, p.rig) {
        (Variant::Axes64, _) => Machine::Axes64.with(&sup)?,
        (Variant::Ethercat, Some(rig)) => {
            ecat::on_ethercat(&machine::demo_with(&sup)?.0, rig.interface())?
        }
        _ => machine::demo_with(&sup)?,
    };
    let (start, t) = (p.t0.elapsed(), Instant::now());
    let tag = format!("{}{i}", n.letter);
    let (mut run, log) = runs::start(p.bins, p.tmp, (&tag, &toml, &prefix), len, &[])?;
    let homing = match v {
        Variant::Axes64 => Some(home_while(p, &prefix, &mut run, t, len)?),
        _ => None,
    };
    let left = Duration::from_secs_f64(len + 60.0).saturating_sub(t.elapsed());
    let ended = run.wait(left, Duration::from_secs(10));
    if ended.interrupted {
        c.interrupted = true;
        return Ok(false);
    }
    let (m, warnings) = match runs::read(&ended, &log) {
        Ok(x) => x,
        Err(e) => {
            let (k, label) = (i + 1, n.label);
            c.failures
                .push(format!("slice {k}: motion-supervisor ({label}): {e}"));
            return Ok(false);
        }
    };
    let (l, w) = (&m.report.latency, &m.report.latency.wakeup_us);
    let mut line = format!(
        "jitter: slice {}/{} {:<11} {:>6} cycles, wake-up p99 {:>7} µs, max {:>7} µs, {} deadline miss(es), {} late repl(ies)",
        i + 1, p.slices, format!("{}:", n.label), l.cycles, us(w.p99), us(w.max), l.deadline_misses, l.late_replies
    );
    if let Some(h) = homing {
        let (n, ok, failed, cut) = (h.started, h.ok, h.failed, h.cut_off);
        line += &format!("; {n} homing(s) of 64 axes: {ok} ok, {failed} failed, {cut} cut off by the slice's end");
        c.homing64.merge(h);
    }
    if v == Variant::Ethercat {
        line += &bus(c, &ended.stderr);
    }
    eprintln!("{line}");
    c.warnings
        .extend(warnings.into_iter().map(|w| format!("{}{w}", n.warn)));
    c.ours[v as usize].push(Slice { start, len, m });
    if let Some((_, note)) = outcome::cleaned(&prefix) {
        c.warnings
            .insert(format!("left in /dev/shm after a run {note}"));
    }
    Ok(true)
}

/// The 64-axis machine homed again and again, once it is ready, while it
/// is measured (so that the cycle computes every axis moving).
fn home_while(
    p: &Plan,
    prefix: &str,
    run: &mut Running,
    t: Instant,
    len: f64,
) -> Result<Repeated, String> {
    let m = &p.bins.motionctl;
    match drive::wait_until_ready(m, prefix, run, Duration::from_secs_f64(len)) {
        Ok(()) => Repeated::run(m, prefix, run, t, len),
        Err(_) => Ok(Repeated::default()),
    }
}

/// motion-io's bus round trip from the summary it logged (kept in `c`),
/// as the progress line shows it.
fn bus(c: &mut Collected, stderr: &str) -> String {
    let Some(b) = bus_run(stderr) else {
        let w = "EtherCAT: motion-io reported no bus summary in a slice";
        c.warnings.insert(w.into());
        return "; bus round trip not reported".into();
    };
    c.bus_runs.push(b);
    let (p50, p99, max) = (us(b.p50), us(b.p99), us(b.max));
    format!(
        "; bus round trip p50 {p50} / p99 {p99} / max {max} µs, {} lost frame(s)",
        b.lost
    )
}

/// cyclictest for as many periods as fit in the slice, its histogram
/// written to a file and read back; false: the slices end.
fn cyclictest(p: &Plan, bin: &Path, i: usize, len: f64, c: &mut Collected) -> Result<bool, String> {
    if c.stopped() {
        return Ok(false);
    }
    let cy = &p.o.cycle;
    let period_s = f64::from(cy.period_us) * 1e-6;
    let loops = ((len / period_s).round() as u64).max(1);
    let file = p.tmp.join(format!("ct{i}.hist"));
    let args = cyclictest::args(cy.priority, cy.cpu, cy.period_us, loops, p.o.hist_max_us);
    // the file's name left out: it is a temporary one
    c.ct_command = format!("cyclictest {args} --histfile=FILE");
    let start = p.t0.elapsed();
    let mut cmd = cyclictest::command(bin, &args, &file);
    let ended = Running::spawn(&mut cmd, "cyclictest", true, false)?
        .wait(Duration::from_secs_f64(len + 30.0), Duration::from_secs(3));
    if ended.interrupted {
        c.interrupted = true;
        return Ok(false);
    }
    let hist = match cyclictest::read_run(&ended, &file) {
        Ok(h) => h,
        Err(e) => {
            c.failures.push(format!("slice {}: cyclictest: {e}", i + 1));
            return Ok(false);
        }
    };
    let mut hdr = histogram();
    hist.record_into(&mut hdr);
    eprintln!(
        "jitter: slice {}/{} cyclictest: {:>6} samples, wake-up p99 {:>7} µs, max {:>7} µs",
        i + 1,
        p.slices,
        hist.samples(),
        us(hdr.value_at_quantile(0.99) as f64 / 1000.0),
        us(hist.max_us as f64)
    );
    let len = Duration::from_secs_f64(loops as f64 * period_s);
    c.ct.push(CtSlice {
        start,
        len,
        hist,
        hdr,
    });
    Ok(true)
}
