//! Soak bench: spurious homing failures. Many one-axis switch homings at the
//! supervisor's default settings (part of them with stress-ng on the other
//! CPU), then parallel homings of a 64-axis machine; counts every result
//! that failed with ERR 12 / EXERR 40 (feedback lost) or anything else, and
//! every axis that ended not homed. See `bench/README.md`.

use clap::{Parser, ValueEnum};
use motion_bench::drive::{self, Binaries, HomeRun, Tally};
use motion_bench::machine::{self, Supervisor};
use motion_bench::proc;
use motion_bench::spy::Spy;
use motion_bench::sys;
use motion_report::AxisResult;
use motion_report::GapCounts;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// `bench/out` of the source tree, wherever the bench is started from.
const DEFAULT_OUT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/out");

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Via {
    /// One `motion-supervisor run` daemon per block; each homing is a
    /// `motionctl home X --json` (and a `motionctl status` before the next
    /// one checks that X is still homed).
    Daemon,
    /// Each homing is its own `motion-supervisor home --json` (start, spawn
    /// motion-io, home, stop).
    Home,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Which {
    /// The one-axis switch machine.
    One,
    /// The 64-axis machine.
    Axes64,
}

#[derive(Debug, Parser)]
#[command(
    name = "soak",
    about = "Counts spurious homing failures: N one-axis switch homings at default settings \
             (a share of them with stress-ng on the other CPU) and parallel homings of a \
             64-axis machine.",
    after_help = "Exit status: 0 when it ran to its end (whatever the counts: they are figures, \
                  not assertions), 1 if a supervisor could not be run, 2 on a command-line \
                  mistake, 130 if interrupted (partial counts are printed and written)."
)]
struct Opts {
    /// One-axis homings in all (0: skip that part).
    #[arg(long, default_value_t = 500)]
    homings: u32,
    /// Share of the one-axis homings run with `stress-ng --cpu 1` on the
    /// other CPU (in whole blocks, interleaved with unloaded blocks).
    #[arg(long, default_value_t = 0.5)]
    stress_share: f64,
    /// How the one-axis homings are run.
    #[arg(long, value_enum, default_value = "daemon")]
    via: Via,
    /// One-axis homings per block (one daemon per block with --via daemon;
    /// stress-ng is switched per block).
    #[arg(long, default_value_t = 50)]
    block: u32,
    /// Parallel homings of the 64-axis machine (each a fresh
    /// `motion-supervisor home --parallel --json`; 0: skip that part).
    #[arg(long, default_value_t = 20)]
    runs64: u32,
    /// Run the 64-axis homings with stress-ng on the other CPU too.
    #[arg(long)]
    stress64: bool,
    /// Cycle period, µs.
    #[arg(long, default_value_t = 1000)]
    period_us: u32,
    /// CPU of the cycle (motion-io runs there too, the supervisor's
    /// default); stress-ng goes on another one.
    #[arg(long, default_value_t = 1)]
    cpu: usize,
    /// SCHED_FIFO priority of the cycle.
    #[arg(long, default_value_t = 80)]
    priority: i32,
    /// Seconds one homing may take before it counts as failed.
    #[arg(long, default_value_t = 60.0)]
    timeout: f64,
    /// Output directory (soak.json).
    #[arg(long, default_value = DEFAULT_OUT)]
    out: PathBuf,
    /// motion-supervisor binary (motion-io and motionctl next to it).
    #[arg(long)]
    supervisor: Option<PathBuf>,
    /// With --via daemon: record every one-axis homing with `motionctl trace
    /// X --home` (every cycle: phase, commanded and actual motion, fresh
    /// feedback or not) instead of `motionctl home X`, the result read from
    /// `motionctl status`; the traces of failed homings are kept in
    /// OUT/soak-evidence/.
    #[arg(long)]
    trace: bool,
    /// With --via daemon: a spy subscriber (on the other CPU, SCHED_FIFO 70)
    /// records every command and feedback frame of each block with their
    /// send times; blocks with a failed homing get them in
    /// OUT/soak-evidence/PREFIX.frames.csv.
    #[arg(long)]
    spy: bool,
    /// Print the config of a machine (with this run's settings) and exit.
    #[arg(long, value_enum)]
    print_config: Option<Which>,
}

fn main() {
    let o = Opts::parse();
    std::process::exit(match real_main(&o) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("soak: FAILED: {e}");
            1
        }
    });
}

/// Latency and I/O figures of the supervisors of one part, summed.
#[derive(Default)]
struct RunFigures {
    runs: u64,
    cycles: u64,
    deadline_misses: u64,
    late_replies: u64,
    frames_missing: u64,
    gaps: GapCounts,
    wakeup_max_us: f64,
    warnings: Vec<String>,
}

impl RunFigures {
    /// Adds a `run --json` / `home --json` object's latency and I/O figures.
    fn add(&mut self, v: &Value) {
        self.runs += 1;
        let lat = &v["latency"];
        self.cycles += lat["cycles"].as_u64().unwrap_or(0);
        self.deadline_misses += lat["deadline_misses"].as_u64().unwrap_or(0);
        self.late_replies += lat["late_replies"].as_u64().unwrap_or(0);
        self.wakeup_max_us = self
            .wakeup_max_us
            .max(lat["wakeup_us"]["max"].as_f64().unwrap_or(0.0));
        for io in v["io"].as_array().into_iter().flatten() {
            self.frames_missing += io["frames_missing"].as_u64().unwrap_or(0);
            if let Ok(g) = serde_json::from_value::<GapCounts>(io["gaps"].clone()) {
                self.gaps.merge(&g);
            }
        }
    }

    fn json(&self) -> Value {
        json!({
            "supervisor_runs": self.runs,
            "cycles": self.cycles,
            "deadline_misses": self.deadline_misses,
            "late_replies": self.late_replies,
            "frames_missing": self.frames_missing,
            "gaps": self.gaps,
            "wakeup_max_us": self.wakeup_max_us,
            "warnings": self.warnings,
        })
    }
}

/// One part (unloaded one-axis, stressed one-axis, 64-axis).
#[derive(Default)]
struct Part {
    tally: Tally,
    figures: RunFigures,
    seconds: f64,
}

impl Part {
    fn json(&self) -> Value {
        json!({
            "seconds": (self.seconds * 10.0).round() / 10.0,
            "tally": self.tally,
            "supervisors": self.figures.json(),
        })
    }
}

struct Ctx {
    b: Binaries,
    tmp: PathBuf,
    other_cpu: usize,
    leftovers: Vec<String>,
    not_cleaned: Vec<String>,
    seq: u32,
}

impl Ctx {
    /// A unique service prefix for this bench's next supervisor.
    fn prefix(&mut self, tag: &str) -> String {
        self.seq += 1;
        format!("mbs{}{tag}{}", std::process::id(), self.seq)
    }

    /// Reports what `prefix` left behind, then cleans it (see
    /// [`drive::clean_leftovers`]).
    fn check_leftovers(&mut self, prefix: &str) {
        let (found, remaining) = drive::clean_leftovers(prefix);
        if !found.is_empty() {
            eprintln!(
                "soak: WARNING: {prefix} left {} ({})",
                found.join(", "),
                if remaining.is_empty() {
                    "cleaned"
                } else {
                    "NOT all cleaned"
                }
            );
            self.leftovers.extend(found);
            self.not_cleaned.extend(remaining);
        }
    }
}

fn sup(o: &Opts, prefix: &str) -> Supervisor {
    Supervisor {
        cycle_us: o.period_us,
        cpu: o.cpu,
        priority: o.priority,
        service_prefix: prefix.to_string(),
    }
}

fn real_main(o: &Opts) -> Result<i32, String> {
    if o.cpu >= sys::cpus() {
        eprintln!(
            "soak: --cpu {}: this machine has {} CPUs",
            o.cpu,
            sys::cpus()
        );
        return Ok(2);
    }
    if !(0.0..=1.0).contains(&o.stress_share) || o.block == 0 {
        eprintln!("soak: --stress-share must be within 0..=1 and --block at least 1");
        return Ok(2);
    }
    let state = std::env::temp_dir().join(format!("motion-bench-soak-{}", std::process::id()));
    if let Some(w) = o.print_config {
        let s = sup(o, "mbsoak");
        let (text, _) = match w {
            Which::One => machine::one_switch_axis_with(&s, state.to_str())?,
            Which::Axes64 => machine::axes64_with(&s)?,
        };
        print!("{text}");
        return Ok(0);
    }
    proc::install_stop_handler();
    let b = Binaries::find(o.supervisor.as_deref())?;
    let other_cpu = if o.cpu == 0 { 1 } else { 0 };
    let stressed_blocks_needed = o.stress_share > 0.0 || o.stress64;
    if stressed_blocks_needed && (sys::cpus() < 2 || sys::find_in_path("stress-ng").is_none()) {
        return Err(
            "stress-ng (apt-get install -y stress-ng) and a second CPU are needed \
                    (or --stress-share 0)"
                .into(),
        );
    }
    std::fs::create_dir_all(&state).map_err(|e| format!("{}: {e}", state.display()))?;
    let _rm = RemoveDir(state.clone());
    std::fs::create_dir_all(&o.out).map_err(|e| format!("{}: {e}", o.out.display()))?;
    let mut ctx = Ctx {
        b,
        tmp: state.clone(),
        other_cpu,
        leftovers: Vec::new(),
        not_cleaned: Vec::new(),
        seq: 0,
    };
    let (preemption, _) = sys::preemption();
    eprintln!(
        "soak: {} one-axis homings via {:?} in blocks of {} ({:.0} % with stress-ng on CPU {other_cpu}), \
         {} parallel homings of 64 axes{}; {} µs cycle, SCHED_FIFO {} on CPU {}; kernel {} ({preemption}); load {}",
        o.homings,
        o.via,
        o.block,
        o.stress_share * 100.0,
        o.runs64,
        if o.stress64 { " with stress-ng" } else { "" },
        o.period_us,
        o.priority,
        o.cpu,
        sys::kernel(),
        sys::loadavg()
    );
    for t in sys::other_rt_tasks() {
        eprintln!("soak: WARNING: another real-time thread is running: {t}");
    }
    let t0 = Instant::now();
    let load_before = sys::loadavg();

    // --- one axis, in blocks; stressed blocks spread evenly
    let mut unloaded = Part::default();
    let mut stressed = Part::default();
    let blocks = o.homings.div_ceil(o.block);
    let mut interrupted = false;
    let mut stressed_so_far = 0u32;
    for k in 0..blocks {
        if proc::stop_requested() {
            interrupted = true;
            break;
        }
        let n = o.block.min(o.homings - k * o.block);
        // stress this block if that keeps the stressed share closest to the goal
        let want = ((f64::from(k + 1) * o.stress_share).round() as u32).min(k + 1);
        let loaded = stressed_so_far < want;
        if loaded {
            stressed_so_far += 1;
        }
        let part = if loaded { &mut stressed } else { &mut unloaded };
        let t = Instant::now();
        let _stress = if loaded {
            Some(drive::stress(
                ctx.other_cpu,
                Duration::from_secs_f64(f64::from(n) * (o.timeout + 10.0) + 60.0),
            )?)
        } else {
            None
        };
        let r = match o.via {
            Via::Daemon => one_axis_daemon_block(o, &mut ctx, n, part),
            Via::Home => one_axis_home_block(o, &mut ctx, n, part),
        };
        part.seconds += t.elapsed().as_secs_f64();
        eprintln!(
            "soak: block {}/{blocks} ({}): {} homings, {} ok, {} feedback lost, {} other errors, {} not homed, {} lost between, {} without result; {:.0} s",
            k + 1,
            if loaded { "stress-ng" } else { "no load" },
            n,
            part.tally.ok,
            part.tally.feedback_lost,
            part.tally.other_errors,
            part.tally.not_homed,
            part.tally.lost_between,
            part.tally.run_failures,
            t.elapsed().as_secs_f64()
        );
        match r {
            Ok(false) => {}
            Ok(true) => {
                interrupted = true;
                break;
            }
            Err(e) => return Err(format!("block {}: {e}", k + 1)),
        }
    }

    // --- 64 axes in parallel, each a fresh `home`
    let mut axes64 = Part::default();
    if !interrupted && o.runs64 > 0 {
        let t = Instant::now();
        let _stress = if o.stress64 {
            Some(drive::stress(
                ctx.other_cpu,
                Duration::from_secs_f64(f64::from(o.runs64) * (o.timeout + 10.0) + 60.0),
            )?)
        } else {
            None
        };
        for i in 0..o.runs64 {
            if proc::stop_requested() {
                interrupted = true;
                break;
            }
            let prefix = ctx.prefix("p");
            let (text, _) = machine::axes64_with(&sup(o, &prefix))?;
            let cfg = ctx.tmp.join(format!("{prefix}.toml"));
            std::fs::write(&cfg, text).map_err(|e| format!("{}: {e}", cfg.display()))?;
            let mut cmd = Command::new(&ctx.b.supervisor);
            cmd.arg("home")
                .arg("--config")
                .arg(&cfg)
                .args(["--parallel", "--json", "--timeout"])
                .arg(format!("{}", o.timeout))
                .args(["--service-prefix", &prefix]);
            let run = drive::home_run(
                &mut cmd,
                "motion-supervisor home",
                Duration::from_secs_f64(o.timeout + 60.0),
            )?;
            if run.ended.interrupted {
                interrupted = true;
                break;
            }
            count_home_run(&mut axes64, &format!("64-axis run {}", i + 1), &run);
            ctx.check_leftovers(&prefix);
            let _ = std::fs::remove_file(&cfg);
            eprintln!(
                "soak: 64 axes, run {}/{}: {} of {} axes ok, {} feedback lost, {} other errors, {} not homed; {:.1} s",
                i + 1,
                o.runs64,
                run.rows.iter().filter(|r| r.succeeded()).count(),
                run.rows.len(),
                run.rows.iter().filter(|r| r.er && r.err == 12 && r.exerr == 40).count(),
                run.rows.iter().filter(|r| r.er && !(r.err == 12 && r.exerr == 40)).count(),
                run.rows.iter().filter(|r| !r.homed).count(),
                run.seconds
            );
        }
        axes64.seconds = t.elapsed().as_secs_f64();
    }
    let wall = t0.elapsed().as_secs_f64();
    if proc::stop_requested() {
        interrupted = true;
    }

    // --- report
    let mut t = String::new();
    let mut line = |s: String| {
        t.push_str(&s);
        t.push('\n');
    };
    line(format!(
        "== soak: spurious homing failures, {} µs cycle, SCHED_FIFO {} on CPU {} (motion-io on the same CPU, the default), default settings (feedback_timeout_ms 10)",
        o.period_us, o.priority, o.cpu
    ));
    line(format!(
        "kernel {} | preemption: {preemption} | {} CPUs | load before {load_before}, after {} | wall {:.0} s",
        sys::kernel(),
        sys::cpus(),
        sys::loadavg(),
        wall
    ));
    line(String::new());
    line(format!(
        "{:<34}{:>9}{:>7}{:>10}{:>8}{:>10}{:>9}{:>10}{:>8}",
        "part", "homings", "ok", "12/40", "other", "not homed", "no rows", "lost betw", "time s"
    ));
    let row = |name: &str, p: &Part, between: bool| {
        format!(
            "{:<34}{:>9}{:>7}{:>10}{:>8}{:>10}{:>9}{:>10}{:>8.0}",
            name,
            p.tally.axis_homings + p.tally.run_failures,
            p.tally.ok,
            p.tally.feedback_lost,
            p.tally.other_errors,
            p.tally.not_homed,
            p.tally.run_failures,
            if between && o.via == Via::Daemon {
                p.tally.lost_between.to_string()
            } else {
                "-".into()
            },
            p.seconds
        )
    };
    line(row("1 axis, no load", &unloaded, true));
    line(row(
        &format!("1 axis, stress-ng on CPU {other_cpu}"),
        &stressed,
        true,
    ));
    let mut both = Tally::default();
    both.merge(&unloaded.tally);
    both.merge(&stressed.tally);
    line(row(
        "1 axis, all",
        &Part {
            tally: both.clone(),
            figures: RunFigures::default(),
            seconds: unloaded.seconds + stressed.seconds,
        },
        true,
    ));
    // 64 axes: axis homings, and runs
    line(row(
        &format!(
            "64 axes parallel, {} runs{}",
            axes64.tally.requests,
            if o.stress64 { ", stress-ng" } else { "" }
        ),
        &axes64,
        false,
    ));
    line(format!(
        "one-axis homings {}; 64 axes: each run a fresh `motion-supervisor home --parallel --json`",
        match o.via {
            Via::Daemon if o.trace => "through one `motion-supervisor run` per block of --block, each a `motionctl trace X --home` (result from `motionctl status`)",
            Via::Daemon => "through one `motion-supervisor run` per block of --block, each a `motionctl home X --json`",
            Via::Home => "each a fresh `motion-supervisor home --json`",
        }
    ));
    line(String::new());
    line("columns: homings = axis homings (+ requests without a result); 12/40 = failed with ERR 12 / EXERR 40 (feedback lost); other = any other error; not homed = ended with HomedStatus clear (failed ones included); no rows = the command gave no result; lost betw = found not homed by `motionctl status` before the next homing".into());
    line(String::new());
    line(format!(
        "{:<34}{:>8}{:>11}{:>8}{:>9}{:>7}{:>7}{:>7}{:>7}{:>9}{:>12}",
        "supervisors (sum)",
        "runs",
        "cycles",
        "misses",
        "late rep",
        "gap 1",
        "2-3",
        "4-10",
        ">10",
        "longest",
        "wake max µs"
    ));
    for (name, p) in [
        ("1 axis, no load", &unloaded),
        ("1 axis, stress-ng", &stressed),
        ("64 axes", &axes64),
    ] {
        let f = &p.figures;
        line(format!(
            "{:<34}{:>8}{:>11}{:>8}{:>9}{:>7}{:>7}{:>7}{:>7}{:>9}{:>12.0}",
            name,
            f.runs,
            f.cycles,
            f.deadline_misses,
            f.late_replies,
            f.gaps.one,
            f.gaps.two_to_three,
            f.gaps.four_to_ten,
            f.gaps.over_ten,
            f.gaps.longest_cycles,
            f.wakeup_max_us
        ));
    }
    let details: Vec<&String> = unloaded
        .tally
        .details
        .iter()
        .chain(&stressed.tally.details)
        .chain(&axes64.tally.details)
        .collect();
    if !details.is_empty() {
        line(String::new());
        line(format!("problems ({}):", details.len()));
        for d in details.iter().take(40) {
            line(format!("  {d}"));
        }
    }
    if ctx.leftovers.is_empty() {
        line("shared memory and session files: nothing left behind".into());
    } else {
        line(format!(
            "left behind by {} run(s) (then cleaned by the bench{}): {}",
            ctx.leftovers.len(),
            if ctx.not_cleaned.is_empty() {
                ""
            } else {
                "; NOT cleaned: see soak.json"
            },
            ctx.leftovers.join(", ")
        ));
    }
    print!("{t}");

    let report = json!({
        "period_us": o.period_us,
        "cpu": o.cpu,
        "priority": o.priority,
        "via": format!("{:?}", o.via).to_lowercase(),
        "block": o.block,
        "stress_share": o.stress_share,
        "stress_cpu": other_cpu,
        "kernel": sys::kernel(),
        "preemption": preemption,
        "load_before": load_before,
        "load_after": sys::loadavg(),
        "wall_s": wall,
        "one_axis_no_load": unloaded.json(),
        "one_axis_stress": stressed.json(),
        "axes64": axes64.json(),
        "axes64_stress": o.stress64,
        "leftovers": ctx.leftovers,
        "leftovers_not_cleaned": ctx.not_cleaned,
        "interrupted": interrupted,
    });
    let path = o.out.join("soak.json");
    std::fs::write(
        &path,
        serde_json::to_string_pretty(&report).unwrap_or_default() + "\n",
    )
    .map_err(|e| format!("{}: {e}", path.display()))?;
    println!("files: {}", path.display());
    if interrupted {
        eprintln!("soak: interrupted: the counts above are partial");
        return Ok(130);
    }
    Ok(0)
}

/// Counts one `home --json` run (rows, latency, gaps) into `p`.
fn count_home_run(p: &mut Part, what: &str, run: &HomeRun) {
    p.tally.add(what, run);
    if let Some(j) = &run.json {
        if j.get("latency").is_some() {
            p.figures.add(j);
        }
        if let Some(w) = j["warnings"].as_array() {
            for w in w.iter().filter_map(|w| w.as_str()) {
                if !p.figures.warnings.iter().any(|x| x == w) {
                    p.figures.warnings.push(w.to_string());
                }
            }
        }
    }
}

/// `n` homings, each its own `motion-supervisor home --json`. Ok(true):
/// interrupted.
fn one_axis_home_block(o: &Opts, ctx: &mut Ctx, n: u32, part: &mut Part) -> Result<bool, String> {
    for _ in 0..n {
        if proc::stop_requested() {
            return Ok(true);
        }
        let prefix = ctx.prefix("h");
        let (text, _) = machine::one_switch_axis_with(&sup(o, &prefix), ctx.tmp.to_str())?;
        let cfg = ctx.tmp.join(format!("{prefix}.toml"));
        std::fs::write(&cfg, text).map_err(|e| format!("{}: {e}", cfg.display()))?;
        let mut cmd = Command::new(&ctx.b.supervisor);
        cmd.arg("home")
            .arg("--config")
            .arg(&cfg)
            .args(["--json", "--timeout"])
            .arg(format!("{}", o.timeout))
            .args(["--service-prefix", &prefix]);
        let run = drive::home_run(
            &mut cmd,
            "motion-supervisor home",
            Duration::from_secs_f64(o.timeout + 60.0),
        )?;
        if run.ended.interrupted {
            return Ok(true);
        }
        count_home_run(part, &prefix, &run);
        ctx.check_leftovers(&prefix);
        let _ = std::fs::remove_file(&cfg);
    }
    Ok(false)
}

/// `n` homings of X through one daemon. Ok(true): interrupted.
fn one_axis_daemon_block(o: &Opts, ctx: &mut Ctx, n: u32, part: &mut Part) -> Result<bool, String> {
    let prefix = ctx.prefix("d");
    let (text, _) = machine::one_switch_axis_with(&sup(o, &prefix), ctx.tmp.to_str())?;
    let cfg = ctx.tmp.join(format!("{prefix}.toml"));
    std::fs::write(&cfg, text).map_err(|e| format!("{}: {e}", cfg.display()))?;
    let mut daemon = drive::spawn_run(&ctx.b, &cfg, &prefix, None, None)?;
    if let Err(e) = drive::wait_until_ready(
        &ctx.b.motionctl,
        &prefix,
        &mut daemon,
        Duration::from_secs(20),
    ) {
        let ended = drive::stop_run(daemon, Duration::from_secs(20));
        if ended.interrupted || proc::stop_requested() {
            return Ok(true);
        }
        return Err(format!(
            "{e} ({}; {})",
            ended.describe(),
            drive::tail(&ended.stderr, 5)
        ));
    }
    let mut spy = if o.spy {
        match Spy::start(&prefix, "io", ctx.other_cpu, 70, 400_000, |_| {}) {
            Ok(s) => Some(s),
            Err(e) => {
                part.tally.note(format!("{prefix}: {e}"));
                None
            }
        }
    } else {
        None
    };
    let mut interrupted = false;
    let mut failed_in_block = false;
    let t_block = Instant::now();
    for i in 0..n {
        if proc::stop_requested() {
            interrupted = true;
            break;
        }
        if i > 0 {
            // still homed since the last homing?
            match drive::status(&ctx.b.motionctl, &prefix) {
                Some(v) => {
                    let homed = v["axes"][0]["homed"].as_bool().unwrap_or(false);
                    if !homed && part.tally.details.len() < 1000 {
                        part.tally.lost_between += 1;
                        let a = &v["axes"][0];
                        part.tally.note(format!(
                            "{prefix} before homing {}: X not homed any more (err {}/{}, {})",
                            i + 1,
                            a["err"],
                            a["exerr"],
                            a["error"].as_str().unwrap_or("")
                        ));
                    }
                }
                None => part
                    .tally
                    .note(format!("{prefix} before homing {}: no status", i + 1)),
            }
        }
        let csv = ctx.tmp.join(format!("{prefix}-{}.csv", i + 1));
        let run = if o.trace {
            traced_home(&ctx.b.motionctl, &prefix, &csv, o.timeout)?
        } else {
            drive::ctl_home(&ctx.b.motionctl, &prefix, &["X"], false, o.timeout)?
        };
        if run.ended.interrupted {
            interrupted = true;
            break;
        }
        let what = format!("{prefix} homing {}", i + 1);
        if !part.tally.add(&what, &run) {
            failed_in_block = true;
            keep_evidence(o, ctx, &prefix, i + 1, t_block, &run, &csv);
            if !daemon.running() {
                part.tally.note(format!("{prefix}: the daemon ended"));
                break;
            }
        }
        let _ = std::fs::remove_file(&csv);
    }
    let frames = spy.as_mut().map(Spy::finish);
    drop(spy);
    let ended = drive::stop_run(daemon, Duration::from_secs(30));
    if failed_in_block {
        let dir = o.out.join("soak-evidence");
        if let Some(r) = &frames {
            let _ = std::fs::create_dir_all(&dir);
            if let Err(e) = r.write_csv(&dir.join(format!("{prefix}.frames.csv"))) {
                eprintln!("soak: cannot write the spy's frames: {e}");
            }
        }
        let _ = std::fs::write(dir.join(format!("{prefix}.stderr")), &ended.stderr);
        let _ = std::fs::write(dir.join(format!("{prefix}.run.json")), &ended.stdout);
    }
    match drive::last_json(&ended.stdout) {
        Some(v) => {
            part.figures.add(&v);
            for w in v["warnings"].as_array().into_iter().flatten() {
                if let Some(w) = w.as_str() {
                    if !part.figures.warnings.iter().any(|x| x == w) {
                        part.figures.warnings.push(w.to_string());
                    }
                }
            }
        }
        None => part.tally.note(format!(
            "{prefix}: the daemon printed no report ({}; {})",
            ended.describe(),
            drive::tail(&ended.stderr, 5)
        )),
    }
    ctx.check_leftovers(&prefix);
    let _ = std::fs::remove_file(&cfg);
    Ok(interrupted)
}

/// One homing of X recorded by `motionctl trace X --home --out CSV`; its
/// result row from `motionctl status` once the trace has ended.
fn traced_home(
    motionctl: &Path,
    prefix: &str,
    csv: &Path,
    timeout: f64,
) -> Result<HomeRun, String> {
    let mut cmd = Command::new(motionctl);
    cmd.args([
        "--service-prefix",
        prefix,
        "trace",
        "X",
        "--home",
        "--json",
        "--out",
    ])
    .arg(csv)
    .args(["--timeout", &format!("{timeout}")]);
    let mut run = drive::home_run(
        &mut cmd,
        "motionctl trace",
        Duration::from_secs_f64(timeout + 30.0),
    )?;
    let status = drive::status(motionctl, prefix);
    let a = status.as_ref().map(|v| &v["axes"][0]);
    run.rows = match a {
        Some(a) if a.is_object() => vec![AxisResult {
            name: a["name"].as_str().unwrap_or("X").into(),
            pc: a["pc"].as_bool().unwrap_or(false),
            er: a["er"].as_bool().unwrap_or(false),
            err: a["err"].as_u64().unwrap_or(0) as u16,
            exerr: a["exerr"].as_u64().unwrap_or(0) as u16,
            homed: a["homed"].as_bool().unwrap_or(false),
            error: a["error"].as_str().map(str::to_string),
            duration_s: a["elapsed_s"].as_f64(),
            ..AxisResult::default()
        }],
        _ => Vec::new(),
    };
    if let Some(st) = status {
        let trace = run.json.take();
        run.json = Some(json!({"trace": trace, "status": st}));
    }
    Ok(run)
}

/// Keeps what tells why homing `i` of `prefix` failed: its row, when it
/// happened, `motionctl status` and `stats` right after, and its trace.
fn keep_evidence(
    o: &Opts,
    ctx: &Ctx,
    prefix: &str,
    i: u32,
    t_block: Instant,
    run: &HomeRun,
    csv: &Path,
) {
    let dir = o.out.join("soak-evidence");
    if std::fs::create_dir_all(&dir).is_err() {
        return;
    }
    let stats = Command::new(&ctx.b.motionctl)
        .args(["--service-prefix", prefix, "stats", "--json"])
        .output()
        .ok()
        .and_then(|x| serde_json::from_slice::<Value>(&x.stdout).ok());
    let status = drive::status(&ctx.b.motionctl, prefix);
    let v = json!({
        "prefix": prefix,
        "homing": i,
        "seconds_into_block": t_block.elapsed().as_secs_f64(),
        "seconds_this_homing": run.seconds,
        "rows": run.rows,
        "output": run.json,
        "ended": run.ended.describe(),
        "stderr_tail": drive::tail(&run.ended.stderr, 20),
        "status_after": status,
        "stats_after": stats,
        "loadavg": sys::loadavg(),
    });
    let _ = std::fs::write(
        dir.join(format!("{prefix}-h{i}.json")),
        serde_json::to_string_pretty(&v).unwrap_or_default() + "\n",
    );
    if csv.exists() {
        let _ = std::fs::copy(csv, dir.join(format!("{prefix}-h{i}.csv")));
    }
}

/// Removes a directory on drop.
struct RemoveDir(PathBuf);

impl Drop for RemoveDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
