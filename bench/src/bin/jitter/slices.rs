//! The alternating slices: in each, the supervisor on the demo machine, on
//! the 64-axis machine (homing), with the EtherCAT backend (`--ethercat`),
//! then cyclictest, one after the other, until each has run `--duration`.
//! Alternating, not back to back, so that every tool sees the same host
//! noise: on a VM the noise changes by the minute.
//!
//! The first failure of any tool ends the slices (what ran is still
//! reported); so does SIGINT/SIGTERM.

use crate::cli::Opts;
use crate::homing64::{self, Homing64};
use motion_bench::cyclictest::{self, CtHistogram};
use motion_bench::ecat::{self, BusRun, EcatRig};
use motion_bench::host::OtherRt;
use motion_bench::machine::{self, Machine};
use motion_bench::proc::{self, Running};
use motion_bench::slice::{self, Slice};
use motion_bench::table::us;
use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;
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

impl Variant {
    /// Letter of its service prefixes and temporary files.
    fn letter(self) -> char {
        ['s', 'a', 'e'][self as usize]
    }

    /// Its name in the progress lines and failures.
    fn label(self) -> &'static str {
        ["ours", "64 axes", "EtherCAT"][self as usize]
    }

    /// Its tag in the interval log.
    pub fn tag(self) -> &'static str {
        ["ours", "ours_axes64", "ours_ethercat"][self as usize]
    }
}

/// What the slices run with.
pub struct Plan<'a> {
    pub o: &'a Opts,
    pub slices: usize,
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

/// Runs the slices. An `Err` is a bench that could not go on (a config or
/// a process that could not be made), not a tool that failed.
pub fn run(p: &Plan, other_rt: &mut OtherRt) -> Result<Collected, String> {
    let mut c = Collected::default();
    let on = [true, p.o.axes64, p.rig.is_some()];
    let variants = [Variant::Demo, Variant::Axes64, Variant::Ethercat];
    'slices: for i in 0..p.slices {
        let len = p.o.slicing.len(i);
        for v in variants.into_iter().filter(|&v| on[v as usize]) {
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
    c.interrupted |= proc::stop_requested();
    Ok(c)
}

/// One supervisor slice of `v`; false: the slices end (interrupted, or the
/// run failed, recorded in `c`).
fn our_slice(p: &Plan, v: Variant, i: usize, len: f64, c: &mut Collected) -> Result<bool, String> {
    if proc::stop_requested() {
        c.interrupted = true;
        return Ok(false);
    }
    let prefix = format!("mbj{}{}{i}", std::process::id(), v.letter());
    let sup = p.o.cycle.supervisor(&prefix);
    let (toml, _) = match v {
        Variant::Axes64 => Machine::Axes64.with(&sup)?,
        _ => machine::demo_with(&sup)?,
    };
    let toml = match (v, p.rig) {
        (Variant::Ethercat, Some(rig)) => ecat::on_ethercat(&toml, rig.interface())?.0,
        _ => toml,
    };
    let tag = format!("{}{i}", v.letter());
    let (mut cmd, hlog) = slice::command(p.supervisor, p.tmp, &tag, &toml, &prefix, len)?;
    let (start, t) = (p.t0.elapsed(), Instant::now());
    let mut run = Running::spawn(&mut cmd, "motion-supervisor", true, false)?;
    let homing = match v {
        Variant::Axes64 => Some(homing64::home_while(
            p.motionctl,
            &prefix,
            &mut run,
            t,
            len,
        )?),
        _ => None,
    };
    let left = Duration::from_secs_f64(len + 60.0).saturating_sub(t.elapsed());
    let ended = run.wait(left, Duration::from_secs(10));
    if ended.interrupted {
        c.interrupted = true;
        return Ok(false);
    }
    let (s, warnings) = match slice::read(&ended, &hlog, start, len) {
        Ok(x) => x,
        Err(e) => {
            let (n, label) = (i + 1, v.label());
            c.failures
                .push(format!("slice {n}: motion-supervisor ({label}): {e}"));
            return Ok(false);
        }
    };
    let (l, w) = (&s.lat, &s.lat.wakeup_us);
    let mut line = format!(
        "jitter: slice {}/{} {:<11} {:>6} cycles, wake-up p99 {:>7} µs, max {:>7} µs, {} deadline miss(es), {} late repl(ies)",
        i + 1, p.slices, format!("{}:", v.label()), l.cycles, us(w.p99), us(w.max), l.deadline_misses, l.late_replies
    );
    if let Some(h) = homing {
        line += &h.progress();
        c.homing64.merge(h);
    }
    if v == Variant::Ethercat {
        let bus = ecat::bus_run(&ended.stderr);
        line += &format!(
            "; bus round trip {}",
            match bus {
                Some(b) => format!(
                    "p50 {} / p99 {} / max {} µs, {} lost frame(s)",
                    us(b.p50),
                    us(b.p99),
                    us(b.max),
                    b.lost
                ),
                None => "not reported".into(),
            }
        );
        match bus {
            Some(b) => c.bus_runs.push(b),
            None => {
                c.warnings
                    .insert("EtherCAT: motion-io reported no bus summary in a slice".into());
            }
        }
    }
    eprintln!("{line}");
    let shown = ["", "64 axes: ", "EtherCAT: "][v as usize];
    c.warnings
        .extend(warnings.into_iter().map(|w| format!("{shown}{w}")));
    c.ours[v as usize].push(s);
    let (found, remaining) = motion_bench::drive::clean_leftovers(&prefix);
    if !found.is_empty() {
        let all = if remaining.is_empty() {
            ""
        } else {
            ", NOT all"
        };
        c.warnings.insert(format!(
            "left in /dev/shm after a run (then cleaned by the bench{all}): {}",
            found.join(", ")
        ));
    }
    Ok(true)
}

/// cyclictest for as many periods as fit in the slice (`-l`, since `-D`
/// takes whole seconds only), its histogram written to a file and read
/// back; false: the slices end.
fn cyclictest(p: &Plan, bin: &Path, i: usize, len: f64, c: &mut Collected) -> Result<bool, String> {
    if proc::stop_requested() {
        c.interrupted = true;
        return Ok(false);
    }
    let cy = &p.o.cycle;
    let period_s = f64::from(cy.period_us) * 1e-6;
    let loops = ((len / period_s).round() as u64).max(1);
    let hist_path = p.tmp.join(format!("ct{i}.hist"));
    let args = format!(
        "-m -p {} -t 1 -a {} -i {} -l {loops} -q -h {}",
        cy.priority, cy.cpu, cy.period_us, p.o.hist_max_us
    );
    // the file's name left out: it is a temporary one
    c.ct_command = format!("cyclictest {args} --histfile=FILE");
    let mut cmd = Command::new(bin);
    cmd.args(args.split(' '))
        .arg(format!("--histfile={}", hist_path.display()));
    let start = p.t0.elapsed();
    let ended = Running::spawn(&mut cmd, "cyclictest", true, false)?
        .wait(Duration::from_secs_f64(len + 30.0), Duration::from_secs(3));
    if ended.interrupted {
        c.interrupted = true;
        return Ok(false);
    }
    match cyclictest::read_run(&ended, &hist_path) {
        Ok(hist) => {
            let hdr = hist.to_hdr();
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
        Err(e) => {
            c.failures.push(format!("slice {}: cyclictest: {e}", i + 1));
            Ok(false)
        }
    }
}
