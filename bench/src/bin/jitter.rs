//! Jitter bench: the supervisor's real cycle (`motion-supervisor run`) side
//! by side with cyclictest, same period, priority and CPU, in alternating
//! slices so that both see the same host noise; with `--ethercat` also the
//! supervisor with the EtherCAT backend (over a veth pair to emulated
//! drives) in the same slices. See `bench/README.md`.

use hdrhistogram::Histogram;
use motion_bench::args::Args;
use motion_bench::cyclictest::{self, CtHistogram};
use motion_bench::drive::{self, Tally};
use motion_bench::ecat::{self, BusRun, EcatRig};
use motion_bench::hist::{self, new_hist, thousands, us, Pct, COLUMNS};
use motion_bench::machine::{self, Machine, Supervisor};
use motion_bench::proc::{self, Running};
use motion_bench::svg::{self, Series};
use motion_bench::sys;
use motion_supervisor::stats::percentiles as pct_of;
use serde_json::{json, Value};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant, SystemTime};

const USAGE: &str = "\
usage: jitter [--duration S] [--period-us N] [--slice S] [--priority P] [--cpu N]
              [--stress] [--out DIR] [--supervisor PATH] [--cyclictest PATH]
              [--no-cyclictest] [--hist-max-us N] [--ethercat] [--no-axes64]

Runs `motion-supervisor run` and `cyclictest` in alternating slices until each
has run --duration seconds, at the same period, SCHED_FIFO priority and CPU,
then prints their wake-up latencies side by side and writes
DIR/jitter-<period>us.{hlog,svg,json}. The supervisor runs twice per slice:
the demo machine (4 axes, idle) and a 64-axis machine that `motionctl home
--parallel` homes again and again while it is measured.

  --duration S       seconds per tool (default 60)
  --period-us N      cycle period, µs (default 1000)
  --slice S          seconds per slice (default 5)
  --priority P       SCHED_FIFO priority of both (default 80)
  --cpu N            CPU of both (default 1)
  --stress           stress-ng --cpu 1 on the other CPU for the whole bench
  --out DIR          output directory (default: bench/out of the source tree)
  --supervisor PATH  motion-supervisor binary (default: next to this binary;
                     build it with `cargo build --release --workspace --bins`)
  --cyclictest PATH  cyclictest binary (default: $PATH)
  --no-cyclictest    run the supervisor half only
  --hist-max-us N    cyclictest's histogram range, µs (default 20000; more
                     goes to its overflow count)
  --ethercat         also run the supervisor with motion-io --backend ethercat
                     in every slice: the demo machine's axes over a veth pair
                     to ecat-emu's emulated drives (root: ip netns, raw
                     sockets); reported next to the sim backend
  --no-axes64        skip the 64-axis machine (demo machine only)

Exit status: 0, or 1 if a tool failed to run or crashed, or the supervisor
missed more than 1 % of its deadlines; 2 on a command-line mistake; 130 if
interrupted. Percentiles never fail the run.";

/// `bench/out` of the source tree, wherever the bench is started from.
const DEFAULT_OUT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/out");

/// Share of missed deadlines above which the run fails.
const MAX_MISS_RATIO: f64 = 0.01;

struct Opts {
    duration: f64,
    period_us: u32,
    slice: f64,
    priority: i32,
    cpu: usize,
    stress: bool,
    out: PathBuf,
    supervisor: Option<PathBuf>,
    cyclictest: Option<PathBuf>,
    no_cyclictest: bool,
    hist_max_us: u64,
    ethercat: bool,
    axes64: bool,
}

fn parse_opts() -> Result<Option<Opts>, String> {
    let mut a = Args::from_env();
    if a.flag("--help") || a.flag("-h") {
        return Ok(None);
    }
    let o = Opts {
        duration: a.num("--duration", 60.0)?,
        period_us: a.num("--period-us", 1000)?,
        slice: a.num("--slice", 5.0)?,
        priority: a.num("--priority", 80)?,
        cpu: a.num("--cpu", 1)?,
        stress: a.flag("--stress"),
        out: a
            .value("--out")?
            .map_or_else(|| PathBuf::from(DEFAULT_OUT), PathBuf::from),
        supervisor: a.value("--supervisor")?.map(PathBuf::from),
        cyclictest: a.value("--cyclictest")?.map(PathBuf::from),
        no_cyclictest: a.flag("--no-cyclictest"),
        hist_max_us: a.num("--hist-max-us", 20_000)?,
        ethercat: a.flag("--ethercat"),
        axes64: !a.flag("--no-axes64"),
    };
    a.finish()?;
    if !(o.duration > 0.0 && o.duration.is_finite()) {
        return Err("--duration must be positive".into());
    }
    if !(o.slice >= 0.5 && o.slice.is_finite()) {
        return Err("--slice must be at least 0.5 s".into());
    }
    if !(1..=99).contains(&o.priority) {
        return Err("--priority must be within 1..=99".into());
    }
    if o.cpu >= sys::cpus() {
        return Err(format!(
            "--cpu {}: this machine has {} CPUs (0..={})",
            o.cpu,
            sys::cpus(),
            sys::cpus() - 1
        ));
    }
    if o.hist_max_us < 10 {
        return Err("--hist-max-us must be at least 10".into());
    }
    Ok(Some(o))
}

/// One supervisor slice.
struct OurSlice {
    start: Duration,
    len: Duration,
    wakeup: Histogram<u64>,
    compute: Histogram<u64>,
    roundtrip: Histogram<u64>,
    cycles: u64,
    misses: u64,
    late: u64,
    /// Exact (JSON) distributions of the slice.
    json_wakeup: Pct,
    json_compute: Pct,
    json_roundtrip: Pct,
}

/// One cyclictest slice.
struct CtSlice {
    start: Duration,
    len: Duration,
    hist: CtHistogram,
    hdr: Histogram<u64>,
}

struct Env {
    kernel: String,
    preemption: String,
    is_rt: bool,
    cpus: usize,
    throttling: String,
}

fn main() {
    std::process::exit(real_main());
}

fn real_main() -> i32 {
    let o = match parse_opts() {
        Ok(Some(o)) => o,
        Ok(None) => {
            println!("{USAGE}");
            return 0;
        }
        Err(e) => {
            eprintln!("jitter: {e}\n\n{USAGE}");
            return 2;
        }
    };
    proc::install_stop_handler();
    match run(&o) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("jitter: FAILED: {e}");
            1
        }
    }
}

fn find_supervisor(o: &Opts) -> Result<PathBuf, String> {
    let p = match &o.supervisor {
        Some(p) => p.clone(),
        None => sys::sibling_exe("motion-supervisor").ok_or_else(|| {
            let dir = std::env::current_exe()
                .ok()
                .and_then(|e| e.parent().map(Path::to_path_buf))
                .unwrap_or_default();
            format!(
                "motion-supervisor not found next to this binary (in {}); build it first: \
                 `cargo build --release --workspace --bins` (with the same CARGO_TARGET_DIR), \
                 or pass --supervisor PATH",
                dir.display()
            )
        })?,
    };
    if !sys::is_executable(&p) {
        return Err(format!("{} is not an executable file", p.display()));
    }
    let io = std::env::var_os("MOTION_IO_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|| p.with_file_name("motion-io"));
    if !sys::is_executable(&io) {
        return Err(format!(
            "motion-io not found at {} (the supervisor starts it from there; build it with \
             `cargo build --release --workspace --bins` or set MOTION_IO_BIN)",
            io.display()
        ));
    }
    Ok(p)
}

fn run(o: &Opts) -> Result<i32, String> {
    let supervisor = find_supervisor(o)?;
    let cyclictest = if o.no_cyclictest {
        eprintln!("jitter: --no-cyclictest: running the supervisor half only");
        None
    } else {
        match o
            .cyclictest
            .clone()
            .or_else(|| sys::find_in_path("cyclictest"))
        {
            Some(p) => Some(p),
            None => {
                eprintln!(
                    "jitter: WARNING: cyclictest not found (install rt-tests: \
                     `apt-get install -y rt-tests`); SKIPPING the cyclictest half, \
                     the supervisor is measured alone"
                );
                None
            }
        }
    };
    let cyclictest = match (cyclictest, sys::can_use_fifo(o.priority)) {
        (Some(_), Err(e)) => {
            eprintln!(
                "jitter: WARNING: no real-time scheduling for this user ({e}); cyclictest \
                 cannot run like that: SKIPPING the cyclictest half (the supervisor warns \
                 and runs SCHED_OTHER)"
            );
            None
        }
        (c, _) => c,
    };
    let other_cpu = if o.cpu == 0 { 1 } else { 0 };
    let stress_ng =
        if o.stress {
            if sys::cpus() < 2 {
                return Err("--stress needs a second CPU".into());
            }
            Some(sys::find_in_path("stress-ng").ok_or(
                "--stress: stress-ng not found (apt-get install -y stress-ng)".to_string(),
            )?)
        } else {
            None
        };

    let env = {
        let (preemption, is_rt) = sys::preemption();
        Env {
            kernel: sys::kernel(),
            preemption,
            is_rt,
            cpus: sys::cpus(),
            throttling: sys::rt_throttling(),
        }
    };
    let pid = std::process::id();
    let tmp = std::env::temp_dir().join(format!("motion-bench-jitter-{pid}"));
    std::fs::create_dir_all(&tmp).map_err(|e| format!("cannot create {}: {e}", tmp.display()))?;
    let _tmp_guard = RemoveDir(tmp.clone());
    std::fs::create_dir_all(&o.out)
        .map_err(|e| format!("cannot create {}: {e}", o.out.display()))?;

    let slices = (o.duration / o.slice - 1e-9).ceil().max(1.0) as usize;
    let slice_len = |i: usize| (o.duration - i as f64 * o.slice).min(o.slice);
    let period_s = f64::from(o.period_us) * 1e-6;

    eprintln!(
        "jitter: {} s per tool at {} µs, {} slice(s) of ≤ {} s, SCHED_FIFO {} on CPU {}{}",
        o.duration,
        o.period_us,
        slices,
        o.slice,
        o.priority,
        o.cpu,
        if o.stress {
            format!(", stress-ng on CPU {other_cpu}")
        } else {
            String::new()
        }
    );
    eprintln!("jitter: supervisor {}", supervisor.display());
    if let Some(c) = &cyclictest {
        eprintln!("jitter: cyclictest {}", c.display());
    }
    if !env.is_rt {
        eprintln!(
            "jitter: kernel is not PREEMPT_RT ({}): the numbers are upper bounds",
            env.preemption
        );
    }
    let mut other_rt: BTreeSet<String> = BTreeSet::new();
    let mut note_other_rt = |when: &str| {
        for t in sys::other_rt_tasks() {
            if other_rt.insert(t.to_string()) {
                eprintln!(
                    "jitter: WARNING: another real-time thread is running ({when}): {t} — \
                     it competes with both tools; the numbers are not representative"
                );
            }
        }
    };
    note_other_rt("before the bench");

    // --ethercat: the veth pair and the emulated drives, for the whole bench
    let rig = if o.ethercat {
        let demo = motion_config::parse(motion_config::DEMO_TOML)
            .map_err(|p| format!("deploy/demo.toml: {p:?}"))?;
        // below motion-io (priority − 10), whose answer to the supervisor
        // is what the cycle measures; the emulator plays hardware that
        // would take no CPU at all
        let emu_priority = (o.priority - 15).clamp(1, 99);
        let rig = EcatRig::start(&demo, other_cpu, emu_priority)
            .map_err(|e| format!("--ethercat: {e}"))?;
        eprintln!(
            "jitter: EtherCAT: motion-io --backend ethercat on {} ↔ veth ↔ ecat-emu ({} drives, \
             SCHED_FIFO {emu_priority} on CPU {other_cpu})",
            rig.interface(),
            rig.drives
        );
        Some(rig)
    } else {
        None
    };

    let t0 = Instant::now();
    let t0_wall = SystemTime::now();
    let mut failures: Vec<String> = Vec::new();
    let mut warnings: BTreeSet<String> = BTreeSet::new();

    // stress-ng, bounded by its own timeout and killed (as a group) at the end
    let mut stress = match &stress_ng {
        None => None,
        Some(bin) => {
            let bound = (3.0 * o.duration + 20.0 * slices as f64 + 60.0).ceil() as u64;
            let mut c = Command::new(bin);
            c.args([
                "--cpu",
                "1",
                "--taskset",
                &other_cpu.to_string(),
                "--timeout",
                &format!("{bound}s"),
                "--quiet",
            ]);
            let r = Running::spawn(&mut c, "stress-ng", true, true)?;
            eprintln!(
                "jitter: stress-ng --cpu 1 --taskset {other_cpu} --timeout {bound}s (pid {})",
                r.pid()
            );
            std::thread::sleep(Duration::from_millis(300));
            Some(r)
        }
    };

    let mut ours: Vec<OurSlice> = Vec::new();
    let mut ours_ecat: Vec<OurSlice> = Vec::new();
    let mut ours64: Vec<OurSlice> = Vec::new();
    let mut homing64 = Homing64::default();
    let motionctl = supervisor.with_file_name("motionctl");
    if o.axes64 && !sys::is_executable(&motionctl) {
        return Err(format!(
            "motionctl not found at {} (the 64-axis machine is homed with it; build it with \
             `cargo build --release --workspace --bins`, or pass --no-axes64)",
            motionctl.display()
        ));
    }
    let mut bus_runs: Vec<BusRun> = Vec::new();
    let mut ct: Vec<CtSlice> = Vec::new();
    let mut interrupted = false;
    let mut ct_command = String::new();

    'slices: for i in 0..slices {
        let len = slice_len(i);
        // --- the supervisor
        if proc::stop_requested() {
            interrupted = true;
            break;
        }
        let prefix = format!("mbj{pid}s{i}");
        let (toml, _) = machine::demo_with(&Supervisor {
            cycle_us: o.period_us,
            cpu: o.cpu,
            priority: o.priority,
            service_prefix: prefix.clone(),
        })?;
        let hlog_path = tmp.join(format!("ours{i}.hlog"));
        let start = t0.elapsed();
        let ended = supervisor_run(
            &supervisor,
            &tmp,
            &format!("slice{i}"),
            &toml,
            &prefix,
            len,
            &hlog_path,
        )?;
        if ended.interrupted {
            interrupted = true;
            break;
        }
        match our_slice(&ended, &hlog_path, start, len) {
            Ok((s, w)) => {
                eprintln!(
                    "jitter: slice {}/{} ours:       {:>6} cycles, wake-up p99 {:>7} µs, max {:>7} µs, {} deadline miss(es), {} late repl(ies)",
                    i + 1,
                    slices,
                    s.cycles,
                    us(s.json_wakeup.p99),
                    us(s.json_wakeup.max),
                    s.misses,
                    s.late
                );
                warnings.extend(w);
                ours.push(s);
            }
            Err(e) => {
                failures.push(format!("slice {}: motion-supervisor: {e}", i + 1));
                break 'slices;
            }
        }
        leftover_shm(&prefix, &mut warnings);

        // --- the supervisor with 64 axes, homing in parallel again and again
        if o.axes64 {
            if proc::stop_requested() {
                interrupted = true;
                break;
            }
            let prefix = format!("mbj{pid}a{i}");
            let (toml, _) = Machine::Axes64.with(&Supervisor {
                cycle_us: o.period_us,
                cpu: o.cpu,
                priority: o.priority,
                service_prefix: prefix.clone(),
            })?;
            let hlog_path = tmp.join(format!("axes64_{i}.hlog"));
            let start = t0.elapsed();
            let (ended, h) = supervisor_run_homing(
                &supervisor,
                &motionctl,
                &tmp,
                &format!("axes64_{i}"),
                &toml,
                &prefix,
                len,
                &hlog_path,
            )?;
            if ended.interrupted {
                interrupted = true;
                break;
            }
            match our_slice(&ended, &hlog_path, start, len) {
                Ok((s, w)) => {
                    eprintln!(
                        "jitter: slice {}/{} 64 axes:    {:>6} cycles, wake-up p99 {:>7} µs, max {:>7} µs, {} deadline miss(es), {} late repl(ies); {} homing(s) of 64 axes: {} ok, {} failed, {} cut off by the slice's end",
                        i + 1,
                        slices,
                        s.cycles,
                        us(s.json_wakeup.p99),
                        us(s.json_wakeup.max),
                        s.misses,
                        s.late,
                        h.started,
                        h.ok,
                        h.failed,
                        h.cut_off
                    );
                    warnings.extend(w.into_iter().map(|w| format!("64 axes: {w}")));
                    ours64.push(s);
                    homing64.merge(h);
                }
                Err(e) => {
                    failures.push(format!("slice {}: motion-supervisor (64 axes): {e}", i + 1));
                    break 'slices;
                }
            }
            leftover_shm(&prefix, &mut warnings);
        }

        // --- the supervisor with the EtherCAT backend
        if let Some(rig) = &rig {
            if proc::stop_requested() {
                interrupted = true;
                break;
            }
            let prefix = format!("mbj{pid}e{i}");
            let (toml, _) = machine::demo_with(&Supervisor {
                cycle_us: o.period_us,
                cpu: o.cpu,
                priority: o.priority,
                service_prefix: prefix.clone(),
            })?;
            let (toml, _) = ecat::on_ethercat(&toml, rig.interface())?;
            let hlog_path = tmp.join(format!("ecat{i}.hlog"));
            let start = t0.elapsed();
            let ended = supervisor_run(
                &supervisor,
                &tmp,
                &format!("ecat{i}"),
                &toml,
                &prefix,
                len,
                &hlog_path,
            )?;
            if ended.interrupted {
                interrupted = true;
                break;
            }
            let bus = ecat::bus_run(&ended.stderr);
            match our_slice(&ended, &hlog_path, start, len) {
                Ok((s, w)) => {
                    eprintln!(
                        "jitter: slice {}/{} EtherCAT:   {:>6} cycles, wake-up p99 {:>7} µs, max {:>7} µs, {} deadline miss(es), {} late repl(ies); bus round trip {}",
                        i + 1,
                        slices,
                        s.cycles,
                        us(s.json_wakeup.p99),
                        us(s.json_wakeup.max),
                        s.misses,
                        s.late,
                        bus.map_or("not reported".to_string(), |b| format!(
                            "p50 {} / p99 {} / max {} µs, {} lost frame(s)",
                            us(b.p50),
                            us(b.p99),
                            us(b.max),
                            b.lost
                        ))
                    );
                    warnings.extend(w.into_iter().map(|w| format!("EtherCAT: {w}")));
                    ours_ecat.push(s);
                    if let Some(b) = bus {
                        bus_runs.push(b);
                    } else {
                        warnings.insert(
                            "EtherCAT: motion-io reported no bus summary in a slice".into(),
                        );
                    }
                }
                Err(e) => {
                    failures.push(format!(
                        "slice {}: motion-supervisor (EtherCAT): {e}",
                        i + 1
                    ));
                    break 'slices;
                }
            }
            leftover_shm(&prefix, &mut warnings);
        }

        // --- cyclictest
        if let Some(ct_bin) = &cyclictest {
            if proc::stop_requested() {
                interrupted = true;
                break;
            }
            let loops = ((len / period_s).round() as u64).max(1);
            let hist_path = tmp.join(format!("ct{i}.hist"));
            let mut cmd = Command::new(ct_bin);
            let args = [
                "-m".to_string(),
                "-p".into(),
                o.priority.to_string(),
                "-t".into(),
                "1".into(),
                "-a".into(),
                o.cpu.to_string(),
                "-i".into(),
                o.period_us.to_string(),
                "-l".into(),
                loops.to_string(),
                "-q".into(),
                "-h".into(),
                o.hist_max_us.to_string(),
                format!("--histfile={}", hist_path.display()),
            ];
            ct_command = format!(
                "cyclictest {}",
                args[..args.len() - 1].join(" ") + " --histfile=FILE"
            );
            cmd.args(&args);
            let start = t0.elapsed();
            let ended = Running::spawn(&mut cmd, "cyclictest", true, false)?
                .wait(Duration::from_secs_f64(len + 30.0), Duration::from_secs(3));
            if ended.interrupted {
                interrupted = true;
                break;
            }
            match ct_slice(&ended, &hist_path, start, loops as f64 * period_s) {
                Ok(s) => {
                    eprintln!(
                        "jitter: slice {}/{} cyclictest: {:>6} samples, wake-up p99 {:>7} µs, max {:>7} µs",
                        i + 1,
                        slices,
                        s.hist.samples(),
                        us(s.hdr.value_at_quantile(0.99) as f64 / 1000.0),
                        us(s.hist.max_us as f64)
                    );
                    ct.push(s);
                }
                Err(e) => {
                    failures.push(format!("slice {}: cyclictest: {e}", i + 1));
                    break 'slices;
                }
            }
        }
        note_other_rt("during the bench");
    }
    if proc::stop_requested() {
        interrupted = true;
    }

    // --- stress-ng ends here, whatever happened
    if let Some(mut s) = stress.take() {
        let still = s.running();
        s.terminate(Duration::from_secs(3));
        if !still && !interrupted {
            failures.push("stress-ng ended before the bench did (see its output)".into());
        }
    }
    let wall = t0.elapsed();

    if ours.is_empty() {
        for f in &failures {
            eprintln!("jitter: FAILED: {f}");
        }
        if interrupted {
            eprintln!("jitter: interrupted (signal {})", proc::stop_signal());
            return Ok(130);
        }
        return Err(failures.join("; "));
    }

    // --- merge
    let mut ours_wake = new_hist();
    let mut ours_compute = new_hist();
    let mut ours_rt = new_hist();
    for s in &ours {
        hist::merge(&mut ours_wake, &s.wakeup);
        hist::merge(&mut ours_compute, &s.compute);
        hist::merge(&mut ours_rt, &s.roundtrip);
    }
    let w_ours = exact(&ours, pct_of(&ours_wake), |s| s.json_wakeup);
    let c_ours = exact(&ours, pct_of(&ours_compute), |s| s.json_compute);
    let r_ours = exact(&ours, pct_of(&ours_rt), |s| s.json_roundtrip);
    let cycles: u64 = ours.iter().map(|s| s.cycles).sum();
    let misses: u64 = ours.iter().map(|s| s.misses).sum();
    let late: u64 = ours.iter().map(|s| s.late).sum();
    let miss_ratio = misses as f64 / cycles.max(1) as f64;
    let ours_secs: f64 = ours.iter().map(|s| s.len.as_secs_f64()).sum();

    // the same for the EtherCAT backend's slices
    let mut e_wake = new_hist();
    let mut e_compute = new_hist();
    let mut e_rt = new_hist();
    for s in &ours_ecat {
        hist::merge(&mut e_wake, &s.wakeup);
        hist::merge(&mut e_compute, &s.compute);
        hist::merge(&mut e_rt, &s.roundtrip);
    }
    let have_ecat = !ours_ecat.is_empty();
    let w_ecat = exact(&ours_ecat, pct_of(&e_wake), |s| s.json_wakeup);
    let c_ecat = exact(&ours_ecat, pct_of(&e_compute), |s| s.json_compute);
    let r_ecat = exact(&ours_ecat, pct_of(&e_rt), |s| s.json_roundtrip);
    let e_cycles: u64 = ours_ecat.iter().map(|s| s.cycles).sum();
    let e_misses: u64 = ours_ecat.iter().map(|s| s.misses).sum();
    let e_late: u64 = ours_ecat.iter().map(|s| s.late).sum();
    let e_miss_ratio = e_misses as f64 / e_cycles.max(1) as f64;
    let e_secs: f64 = ours_ecat.iter().map(|s| s.len.as_secs_f64()).sum();
    let bus = bus_summary(&bus_runs);

    // the same for the 64-axis machine's slices
    let mut a_wake = new_hist();
    let mut a_compute = new_hist();
    let mut a_rt = new_hist();
    for s in &ours64 {
        hist::merge(&mut a_wake, &s.wakeup);
        hist::merge(&mut a_compute, &s.compute);
        hist::merge(&mut a_rt, &s.roundtrip);
    }
    let have_64 = !ours64.is_empty();
    let w_64 = exact(&ours64, pct_of(&a_wake), |s| s.json_wakeup);
    let c_64 = exact(&ours64, pct_of(&a_compute), |s| s.json_compute);
    let r_64 = exact(&ours64, pct_of(&a_rt), |s| s.json_roundtrip);
    let a_cycles: u64 = ours64.iter().map(|s| s.cycles).sum();
    let a_misses: u64 = ours64.iter().map(|s| s.misses).sum();
    let a_late: u64 = ours64.iter().map(|s| s.late).sum();
    let a_miss_ratio = a_misses as f64 / a_cycles.max(1) as f64;
    let a_secs: f64 = ours64.iter().map(|s| s.len.as_secs_f64()).sum();

    let mut ct_hdr = new_hist();
    let mut ct_total = CtHistogram::default();
    for s in &ct {
        hist::merge(&mut ct_hdr, &s.hdr);
        ct_total.overflows += s.hist.overflows;
        ct_total.max_us = ct_total.max_us.max(s.hist.max_us);
    }
    let w_ct = pct_of(&ct_hdr);
    let ct_ge_period: u64 = ct
        .iter()
        .map(|s| s.hist.at_or_above(u64::from(o.period_us)))
        .sum();
    let ct_secs: f64 = ct.iter().map(|s| s.len.as_secs_f64()).sum();
    let have_ct = !ct.is_empty();

    if miss_ratio > MAX_MISS_RATIO {
        failures.push(format!(
            "the supervisor missed {} of {} deadlines ({:.2} % > {:.0} %)",
            misses,
            cycles,
            miss_ratio * 100.0,
            MAX_MISS_RATIO * 100.0
        ));
    }
    if have_ecat && e_miss_ratio > MAX_MISS_RATIO {
        failures.push(format!(
            "the supervisor (EtherCAT backend) missed {} of {} deadlines ({:.2} % > {:.0} %)",
            e_misses,
            e_cycles,
            e_miss_ratio * 100.0,
            MAX_MISS_RATIO * 100.0
        ));
    }
    if have_64 && a_miss_ratio > MAX_MISS_RATIO {
        failures.push(format!(
            "the supervisor (64 axes homing) missed {} of {} deadlines ({:.2} % > {:.0} %)",
            a_misses,
            a_cycles,
            a_miss_ratio * 100.0,
            MAX_MISS_RATIO * 100.0
        ));
    }
    if o.axes64 && !have_64 && failures.is_empty() && !interrupted {
        failures.push("the 64-axis machine produced no slice".into());
    }
    if o.ethercat && !have_ecat && failures.is_empty() && !interrupted {
        failures.push("the EtherCAT backend produced no slice".into());
    }
    if cyclictest.is_some() && !have_ct && failures.is_empty() && !interrupted {
        failures.push("cyclictest produced no samples".into());
    }

    // --- report
    let mut t = String::new();
    let line = |t: &mut String, s: String| {
        t.push_str(&s);
        t.push('\n');
    };
    line(
        &mut t,
        format!(
            "== jitter: period {} µs ({:.0} Hz), SCHED_FIFO {} on CPU {}, {:.1} s per tool in {} slice(s){}",
            o.period_us,
            1e6 / f64::from(o.period_us),
            o.priority,
            o.cpu,
            ours_secs,
            ours.len(),
            if o.stress {
                format!(", stress-ng --cpu 1 on CPU {other_cpu}")
            } else {
                ", no load".into()
            }
        ),
    );
    line(
        &mut t,
        format!(
            "kernel {} | preemption: {} | {} CPUs | RT throttling {} | load {}",
            env.kernel,
            env.preemption,
            env.cpus,
            env.throttling,
            sys::loadavg()
        ),
    );
    if !env.is_rt {
        line(
            &mut t,
            "not a PREEMPT_RT kernel: latencies are upper bounds, compare the two rows (same run, same noise)".into(),
        );
    }
    line(&mut t, String::new());
    let header = |name: &str| {
        let mut s = format!("{name:<22}");
        for c in COLUMNS {
            s += &format!("{c:>9}");
        }
        s
    };
    let row = |name: &str, p: &Pct, n: Option<u64>| {
        let mut s = format!("{name:<22}");
        for v in p.values() {
            s += &format!("{:>9}", us(v));
        }
        if let Some(n) = n {
            s += &format!("   {} samples", thousands(n));
        }
        s
    };
    line(&mut t, header("wake-up latency (µs)"));
    line(
        &mut t,
        row("ours, demo (idle)", &w_ours, Some(w_ours.count)),
    );
    if have_64 {
        line(&mut t, row("ours, 64 axes homing", &w_64, Some(w_64.count)));
    }
    if have_ecat {
        line(
            &mut t,
            row("ours, EtherCAT backend", &w_ecat, Some(w_ecat.count)),
        );
    }
    if have_ct {
        line(&mut t, row("cyclictest", &w_ct, Some(w_ct.count)));
        let mut s = format!("{:<22}", "ratio demo/cyclictest");
        for r in w_ours.ratio(&w_ct) {
            s += &format!("{:>9}", hist::ratio(r));
        }
        line(&mut t, s);
        if have_64 {
            let mut s = format!("{:<22}", "ratio 64 axes/cyclic.");
            for r in w_64.ratio(&w_ct) {
                s += &format!("{:>9}", hist::ratio(r));
            }
            line(&mut t, s);
        }
        if have_ecat {
            let mut s = format!("{:<22}", "ratio EtherCAT/cyclic.");
            for r in w_ecat.ratio(&w_ct) {
                s += &format!("{:>9}", hist::ratio(r));
            }
            line(&mut t, s);
        }
    } else {
        line(&mut t, format!("{:<22}(not run)", "cyclictest"));
    }
    line(&mut t, String::new());
    line(
        &mut t,
        format!(
            "deadline misses   ours, demo: {} of {} cycles ({:.3} %, summed over {} slices; limit {:.0} %)",
            misses,
            thousands(cycles),
            miss_ratio * 100.0,
            ours.len(),
            MAX_MISS_RATIO * 100.0
        ),
    );
    if have_64 {
        line(
            &mut t,
            format!(
                "                  ours, 64 axes homing: {} of {} cycles ({:.3} %)",
                a_misses,
                thousands(a_cycles),
                a_miss_ratio * 100.0
            ),
        );
    }
    if have_ecat {
        line(
            &mut t,
            format!(
                "                  EtherCAT backend: {} of {} cycles ({:.3} %)",
                e_misses,
                thousands(e_cycles),
                e_miss_ratio * 100.0
            ),
        );
    }
    if have_ct {
        line(
            &mut t,
            format!(
                "                  cyclictest: not counted (skips missed periods); samples ≥ period ({} µs): {}",
                o.period_us, ct_ge_period
            ),
        );
    }
    line(&mut t, String::new());
    line(&mut t, header("ours, other (µs)"));
    line(&mut t, row("compute, demo", &c_ours, None));
    line(&mut t, row("I/O round trip, demo", &r_ours, None));
    if have_64 {
        line(&mut t, row("compute, 64 axes", &c_64, None));
        line(&mut t, row("round trip, 64 axes", &r_64, None));
    }
    if have_ecat {
        line(&mut t, row("compute, EtherCAT", &c_ecat, None));
        line(&mut t, row("round trip, EtherCAT", &r_ecat, None));
        match &bus {
            Some(b) => {
                let mut s = format!("{:<22}", "EtherCAT bus round trip");
                for v in [b.min, b.p50, b.p99, b.p999] {
                    s += &format!("{:>9}", us(v));
                }
                s += &format!("{:>9}{:>9}", "-", us(b.max));
                line(&mut t, s);
                line(
                    &mut t,
                    format!(
                        "  (motion-io's bus thread: frame out → inputs back over veth, {} bus cycles, {} lost frame(s); \
                         p50/p99/p99.9 = the highest of the {} slices)",
                        thousands(b.cycles),
                        b.lost,
                        bus_runs.len()
                    ),
                );
            }
            None => line(
                &mut t,
                "EtherCAT bus round trip: not reported by motion-io".into(),
            ),
        }
    }
    line(
        &mut t,
        format!(
            "late I/O replies (no answer within half a period): demo {late} of {}{}{}",
            thousands(cycles),
            if have_64 {
                format!("; 64 axes: {a_late} of {}", thousands(a_cycles))
            } else {
                String::new()
            },
            if have_ecat {
                format!("; EtherCAT backend: {e_late} of {}", thousands(e_cycles))
            } else {
                String::new()
            }
        ),
    );
    if have_64 {
        line(&mut t, homing64.line(a_secs));
        for d in homing64.tally.details.iter().take(10) {
            line(&mut t, format!("  {d}"));
        }
    }
    line(
        &mut t,
        format!(
            "percentiles from the supervisor's interval logs ({} of {} cycles); min/max exact from its JSON",
            thousands(ours_wake.len()),
            thousands(cycles)
        ),
    );
    if have_ct {
        line(
            &mut t,
            format!(
                "cyclictest: {} (1 µs bins, truncated; {} overflow(s) ≥ {} µs counted at its max)",
                ct_command, ct_total.overflows, o.hist_max_us
            ),
        );
    }
    if !other_rt.is_empty() {
        line(
            &mut t,
            format!(
                "WARNING: other real-time threads ran during the bench: {}",
                other_rt.iter().cloned().collect::<Vec<_>>().join("; ")
            ),
        );
    }
    for w in &warnings {
        line(&mut t, format!("supervisor warning: {w}"));
    }
    print!("{t}");

    // --- files
    let base = o.out.join(format!("jitter-{}us", o.period_us));
    let hlog_path = base.with_extension("hlog");
    let svg_path = base.with_extension("svg");
    let json_path = base.with_extension("json");
    let mut intervals: Vec<(&str, Duration, Duration, &Histogram<u64>)> = Vec::new();
    for s in &ours_ecat {
        intervals.push(("ours_ethercat", s.start, s.len, &s.wakeup));
    }
    for s in &ours64 {
        intervals.push(("ours_axes64", s.start, s.len, &s.wakeup));
    }
    for (i, s) in ours.iter().enumerate() {
        intervals.push(("ours", s.start, s.len, &s.wakeup));
        if let Some(c) = ct.get(i) {
            intervals.push(("cyclictest", c.start, c.len, &c.hdr));
        }
    }
    intervals.sort_by_key(|i| i.1);
    let comments = vec![
        format!(
            "motion-bench jitter: wake-up latency, ns; period {} us, SCHED_FIFO {} on CPU {}",
            o.period_us, o.priority, o.cpu
        ),
        "tags: ours = motion-supervisor run (wake-up), demo machine idle; ours_axes64 = the same with 64 axes homing in parallel again and again; ours_ethercat = the same with motion-io --backend ethercat (--ethercat), cyclictest = cyclictest (1 us bins, recorded at the bin's lower edge)".into(),
        format!("kernel {} ({})", env.kernel, env.preemption),
    ];
    if let Err(e) = hist::write_interval_log(&hlog_path, &comments, t0_wall, &intervals) {
        failures.push(e);
    }
    let title = format!(
        "Wake-up latency, period {} µs: motion-supervisor vs cyclictest, {:.0} s each",
        o.period_us, ours_secs
    );
    let sub1 = format!(
        "Linux {} · {} · {} CPUs",
        env.kernel, env.preemption, env.cpus
    );
    let sub2 = format!(
        "both SCHED_FIFO {} on CPU {} · {} · {}",
        o.priority,
        o.cpu,
        if o.stress {
            "stress-ng on the other CPU"
        } else {
            "no load"
        },
        if have_ct {
            "cyclictest in 1 µs bins"
        } else {
            "cyclictest not run"
        }
    );
    let mut series = vec![Series {
        name: "ours, demo machine (idle)",
        colour: "#1f6fd1",
        hist: &ours_wake,
    }];
    if have_64 {
        series.push(Series {
            name: "ours, 64 axes homing",
            colour: "#9467bd",
            hist: &a_wake,
        });
    }
    if have_ecat {
        series.push(Series {
            name: "ours, EtherCAT backend",
            colour: "#2ca02c",
            hist: &e_wake,
        });
    }
    if have_ct {
        series.push(Series {
            name: "cyclictest",
            colour: "#d62728",
            hist: &ct_hdr,
        });
    }
    let plot = svg::latency_plot(
        &title,
        &[&sub1, &sub2],
        &series,
        Some(f64::from(o.period_us)),
    );
    if let Err(e) = std::fs::write(&svg_path, plot) {
        failures.push(format!("cannot write {}: {e}", svg_path.display()));
    }

    let ratio_json = |a: &Pct, b: &Pct| -> Value {
        let r = a.ratio(b);
        let keys = ["min", "p50", "p99", "p999", "p9999", "max"];
        let mut m = serde_json::Map::new();
        for (k, v) in keys.iter().zip(r) {
            m.insert(
                k.to_string(),
                v.map_or(Value::Null, |x| json!((x * 100.0).round() / 100.0)),
            );
        }
        Value::Object(m)
    };
    let report = json!({
        "period_us": o.period_us,
        "priority": o.priority,
        "cpu": o.cpu,
        "duration_s_per_tool": o.duration,
        "slice_s": o.slice,
        "stress": o.stress,
        "wall_s": wall.as_secs_f64(),
        "environment": {
            "kernel": env.kernel,
            "preemption": env.preemption,
            "preempt_rt": env.is_rt,
            "cpus": env.cpus,
            "rt_throttling": env.throttling,
            "other_rt_threads": other_rt.iter().cloned().collect::<Vec<_>>(),
        },
        "ours": {
            "machine": "demo (deploy/demo.toml, 4 axes, idle)",
            "seconds": ours_secs,
            "slices": ours.len(),
            "cycles": cycles,
            "deadline_misses": misses,
            "deadline_miss_ratio": miss_ratio,
            "late_replies": late,
            "hlog_samples": ours_wake.len(),
            "wakeup_us": serde_json::to_value(w_ours).unwrap_or_default(),
            "compute_us": serde_json::to_value(c_ours).unwrap_or_default(),
            "io_roundtrip_us": serde_json::to_value(r_ours).unwrap_or_default(),
            "warnings": warnings.iter().cloned().collect::<Vec<_>>(),
        },
        "ours_axes64": if have_64 { json!({
            "machine": "64 axes (motion_bench::machine::axes64_with), motionctl home --parallel again and again",
            "seconds": a_secs,
            "slices": ours64.len(),
            "cycles": a_cycles,
            "deadline_misses": a_misses,
            "deadline_miss_ratio": a_miss_ratio,
            "late_replies": a_late,
            "hlog_samples": a_wake.len(),
            "wakeup_us": serde_json::to_value(w_64).unwrap_or_default(),
            "compute_us": serde_json::to_value(c_64).unwrap_or_default(),
            "io_roundtrip_us": serde_json::to_value(r_64).unwrap_or_default(),
            "homing": homing64.json(),
        }) } else { json!({"skipped": true}) },
        "ours_ethercat": if have_ecat { json!({
            "seconds": e_secs,
            "slices": ours_ecat.len(),
            "cycles": e_cycles,
            "deadline_misses": e_misses,
            "deadline_miss_ratio": e_miss_ratio,
            "late_replies": e_late,
            "wakeup_us": serde_json::to_value(w_ecat).unwrap_or_default(),
            "compute_us": serde_json::to_value(c_ecat).unwrap_or_default(),
            "io_roundtrip_us": serde_json::to_value(r_ecat).unwrap_or_default(),
            "bus_roundtrip_us_per_slice": bus_runs.iter().map(|b| json!({
                "cycles": b.cycles, "min": b.min, "p50": b.p50, "p99": b.p99,
                "p999": b.p999, "max": b.max, "lost_frames": b.lost,
            })).collect::<Vec<_>>(),
        }) } else { json!({"skipped": true}) },
        "cyclictest": if have_ct { json!({
            "command": ct_command,
            "seconds": ct_secs,
            "slices": ct.len(),
            "wakeup_us": serde_json::to_value(w_ct).unwrap_or_default(),
            "deadline_misses": Value::Null,
            "deadline_misses_note": "not counted (cyclictest skips missed periods)",
            "samples_at_or_above_period": ct_ge_period,
            "histogram_overflows": ct_total.overflows,
        }) } else { json!({"skipped": true}) },
        "ratio_ours_over_cyclictest": if have_ct { ratio_json(&w_ours, &w_ct) } else { Value::Null },
        "ratio_axes64_over_cyclictest": if have_ct && have_64 { ratio_json(&w_64, &w_ct) } else { Value::Null },
        "files": { "hlog": hlog_path, "svg": svg_path },
        "status": {
            "ok": failures.is_empty() && !interrupted,
            "interrupted": interrupted,
            "failures": failures,
        },
    });
    if let Err(e) = std::fs::write(
        &json_path,
        serde_json::to_string_pretty(&report).unwrap_or_default() + "\n",
    ) {
        failures.push(format!("cannot write {}: {e}", json_path.display()));
    }
    println!(
        "files: {}, {}, {}",
        hlog_path.display(),
        svg_path.display(),
        json_path.display()
    );

    if interrupted {
        eprintln!(
            "jitter: interrupted (signal {}): results above are partial",
            proc::stop_signal()
        );
        return Ok(130);
    }
    if failures.is_empty() {
        println!("jitter: OK");
        Ok(0)
    } else {
        for f in &failures {
            println!("jitter: FAILED: {f}");
        }
        Ok(1)
    }
}

/// Parses one supervisor run: its JSON and its hlog. Returns the slice and
/// the run's warnings.
fn our_slice(
    ended: &proc::Ended,
    hlog: &Path,
    start: Duration,
    len: f64,
) -> Result<(OurSlice, Vec<String>), String> {
    let tail = || {
        let e = ended.stderr.trim();
        if e.is_empty() {
            String::new()
        } else {
            format!("; its stderr: {}", last_lines(e, 8))
        }
    };
    if !ended.success() {
        return Err(format!("{}{}", ended.describe(), tail()));
    }
    // The supervisor's own typed report (motion_report::RunReport).
    let report: motion_report::RunReport = ended
        .stdout
        .lines()
        .rev()
        .find_map(|l| serde_json::from_str(l.trim()).ok())
        .ok_or_else(|| format!("no run report on its stdout{}", tail()))?;
    let lat = report.latency;
    let mut warnings: Vec<String> = report.warnings.clone();
    if let Some(rt) = &report.rt {
        warnings.extend(rt.warnings.iter().cloned());
    }
    let policy = report.rt.as_ref().map(|r| r.policy.as_str());
    if policy != Some("SCHED_FIFO") {
        warnings.push(format!(
            "the cycle did not run SCHED_FIFO (rt: {:?})",
            report.rt
        ));
    }
    let intervals = hist::read_interval_log_file(hlog)?;
    let s = OurSlice {
        start,
        len: Duration::from_secs_f64(len),
        wakeup: hist::sum_tag(&intervals, "wakeup"),
        compute: hist::sum_tag(&intervals, "compute"),
        roundtrip: hist::sum_tag(&intervals, "roundtrip"),
        cycles: lat.cycles,
        misses: lat.deadline_misses,
        late: lat.late_replies,
        json_wakeup: lat.wakeup_us,
        json_compute: lat.compute_us,
        json_roundtrip: lat.io_roundtrip_us,
    };
    if s.cycles == 0 {
        return Err(format!("it measured no cycles{}", tail()));
    }
    Ok((s, warnings))
}

fn ct_slice(
    ended: &proc::Ended,
    hist_path: &Path,
    start: Duration,
    len: f64,
) -> Result<CtSlice, String> {
    let out = || {
        let e = format!("{}\n{}", ended.stdout.trim(), ended.stderr.trim());
        let e = e.trim();
        if e.is_empty() {
            String::new()
        } else {
            format!("; its output: {}", last_lines(e, 8))
        }
    };
    if !ended.success() {
        return Err(format!("{}{}", ended.describe(), out()));
    }
    let text = std::fs::read_to_string(hist_path)
        .map_err(|e| format!("no histogram file {} ({e}){}", hist_path.display(), out()))?;
    let hist = cyclictest::parse(&text)?;
    if hist.samples() == 0 {
        return Err(format!("an empty histogram{}", out()));
    }
    let hdr = hist.to_hdr();
    Ok(CtSlice {
        start,
        len: Duration::from_secs_f64(len),
        hist,
        hdr,
    })
}

fn last_lines(s: &str, n: usize) -> String {
    let lines: Vec<&str> = s.lines().collect();
    lines[lines.len().saturating_sub(n)..].join(" | ")
}

/// Shared memory the supervisor (or its motion-io, or a motionctl) left
/// behind: reported, then removed if no process of the prefix lives.
fn leftover_shm(prefix: &str, warnings: &mut BTreeSet<String>) {
    let (found, remaining) = drive::clean_leftovers(prefix);
    if !found.is_empty() {
        warnings.insert(format!(
            "left in /dev/shm after a run (then cleaned by the bench{}): {}",
            if remaining.is_empty() {
                ""
            } else {
                ", NOT all"
            },
            found.join(", ")
        ));
    }
}

/// Removes a directory on drop.
struct RemoveDir(PathBuf);

impl Drop for RemoveDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs `motion-supervisor run` on `toml` for `len` s with an interval log
/// at `hlog`, output captured.
fn supervisor_run(
    supervisor: &Path,
    tmp: &Path,
    tag: &str,
    toml: &str,
    prefix: &str,
    len: f64,
    hlog: &Path,
) -> Result<proc::Ended, String> {
    let cfg_path = tmp.join(format!("{tag}.toml"));
    std::fs::write(&cfg_path, toml).map_err(|e| format!("{}: {e}", cfg_path.display()))?;
    let mut cmd = Command::new(supervisor);
    cmd.arg("run")
        .arg("--config")
        .arg(&cfg_path)
        .arg("--duration")
        .arg(format!("{len}"))
        .arg("--json")
        .arg("--hlog")
        .arg(hlog)
        .arg("--service-prefix")
        .arg(prefix);
    Ok(Running::spawn(&mut cmd, "motion-supervisor", true, false)?
        .wait(Duration::from_secs_f64(len + 60.0), Duration::from_secs(10)))
}

/// Percentiles of `p` (merged interval logs) with min and max taken exactly
/// from the slices' JSON.
fn exact(slices: &[OurSlice], p: Pct, f: fn(&OurSlice) -> Pct) -> Pct {
    let v: Vec<Pct> = slices.iter().map(f).filter(|p| p.count > 0).collect();
    let mut p = p;
    if !v.is_empty() {
        p.min = v.iter().map(|p| p.min).fold(f64::INFINITY, f64::min);
        p.max = v.iter().map(|p| p.max).fold(0.0, f64::max);
    }
    p
}

/// The bus round trips of all slices in one row: min and max over all,
/// p50 / p99 / p99.9 the highest of the slices (motion-io reports
/// percentiles per run, not its histogram).
fn bus_summary(runs: &[BusRun]) -> Option<BusRun> {
    let first = runs.first()?;
    Some(runs.iter().fold(
        BusRun {
            cycles: 0,
            lost: 0,
            ..*first
        },
        |a, b| BusRun {
            cycles: a.cycles + b.cycles,
            min: a.min.min(b.min),
            p50: a.p50.max(b.p50),
            p99: a.p99.max(b.p99),
            p999: a.p999.max(b.p999),
            max: a.max.max(b.max),
            lost: a.lost + b.lost,
        },
    ))
}

/// The homings of the 64-axis machine during its slices.
#[derive(Default)]
struct Homing64 {
    /// `motionctl home --parallel` commands started.
    started: u64,
    /// ... in which every axis homed (PC, homed, no error).
    ok: u64,
    /// ... in which some axis did not, while the supervisor ran on.
    failed: u64,
    /// ... ended by the end of the slice (the supervisor stops every axis).
    cut_off: u64,
    /// Per axis, the homings that were not cut off.
    tally: Tally,
    /// Seconds from a homing's start to its end (complete ones).
    durations: Vec<f64>,
}

impl Homing64 {
    fn merge(&mut self, h: Homing64) {
        self.started += h.started;
        self.ok += h.ok;
        self.failed += h.failed;
        self.cut_off += h.cut_off;
        self.tally.merge(&h.tally);
        self.durations.extend(h.durations);
    }

    fn line(&self, secs: f64) -> String {
        let mean = if self.durations.is_empty() {
            0.0
        } else {
            self.durations.iter().sum::<f64>() / self.durations.len() as f64
        };
        format!(
            "64 axes: {} parallel homing(s) in {:.0} s ({:.1} s each): {} all homed, {} with a failed axis, {} cut off by a slice's end; \
             axis homings {}: {} ok, {} ERR 12/40 (feedback lost), {} other error(s), {} not homed",
            self.started,
            secs,
            mean,
            self.ok,
            self.failed,
            self.cut_off,
            self.tally.axis_homings,
            self.tally.ok,
            self.tally.feedback_lost,
            self.tally.other_errors,
            self.tally.not_homed
        )
    }

    fn json(&self) -> Value {
        json!({
            "started": self.started,
            "all_homed": self.ok,
            "with_failed_axis": self.failed,
            "cut_off_by_slice_end": self.cut_off,
            "axes": self.tally,
            "mean_duration_s": if self.durations.is_empty() { 0.0 }
                else { self.durations.iter().sum::<f64>() / self.durations.len() as f64 },
        })
    }
}

/// Runs `motion-supervisor run` on the 64-axis `toml` for `len` s (as
/// [`supervisor_run`]) and, while it runs, homes every axis in parallel
/// with `motionctl home --parallel`, one homing after the other.
#[allow(clippy::too_many_arguments)]
fn supervisor_run_homing(
    supervisor: &Path,
    motionctl: &Path,
    tmp: &Path,
    tag: &str,
    toml: &str,
    prefix: &str,
    len: f64,
    hlog: &Path,
) -> Result<(proc::Ended, Homing64), String> {
    let cfg_path = tmp.join(format!("{tag}.toml"));
    std::fs::write(&cfg_path, toml).map_err(|e| format!("{}: {e}", cfg_path.display()))?;
    let mut cmd = Command::new(supervisor);
    cmd.arg("run")
        .arg("--config")
        .arg(&cfg_path)
        .arg("--duration")
        .arg(format!("{len}"))
        .arg("--json")
        .arg("--hlog")
        .arg(hlog)
        .arg("--service-prefix")
        .arg(prefix);
    let t0 = Instant::now();
    let mut r = Running::spawn(&mut cmd, "motion-supervisor", true, false)?;
    let mut h = Homing64::default();
    if drive::wait_until_ready(motionctl, prefix, &mut r, Duration::from_secs_f64(len)).is_ok() {
        while r.running() && !proc::stop_requested() && t0.elapsed().as_secs_f64() < len {
            let started = Instant::now();
            h.started += 1;
            let run = drive::ctl_home(motionctl, prefix, &[], true, len + 10.0)?;
            let all_ok = !run.rows.is_empty() && run.rows.iter().all(|x| x.succeeded());
            if all_ok {
                h.ok += 1;
                h.tally.add(&format!("{prefix} homing {}", h.started), &run);
                h.durations.push(started.elapsed().as_secs_f64());
            } else if (!r.running() || t0.elapsed().as_secs_f64() >= len - 0.5)
                && run.rows.iter().all(|x| {
                    x.succeeded() || (x.er && x.err == 12 && x.exerr == 1) || (!x.er && !x.homed)
                })
            {
                // the supervisor's --duration ended it: every axis stopped
                // (ERR 12/1), the homed ones unhomed; any other code counts
                h.cut_off += 1;
            } else {
                h.failed += 1;
                h.tally.add(&format!("{prefix} homing {}", h.started), &run);
            }
        }
    }
    let left = Duration::from_secs_f64(len + 60.0).saturating_sub(t0.elapsed());
    Ok((r.wait(left, Duration::from_secs(10)), h))
}
