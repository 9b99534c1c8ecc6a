//! One slice of one variant: `motion-supervisor run --config T --duration S
//! --json --hlog H --service-prefix P` (with `--no-control-plane` for (a)),
//! the clients attached for (b) and (c) once the daemon answers, then what
//! it measured: its typed JSON report (exact min/max, counts, CPU use) and
//! its interval log (the histograms the percentiles are merged from). The
//! supervisor measures its own cycle; the bench only starts it and reads.

use crate::cli::Opts;
use crate::clients::{self, Clients};
use crate::variant::Variant;
use hdrhistogram::Histogram;
use motion_bench::drive::{self, Binaries};
use motion_bench::hist::Pct;
use motion_bench::machine::{self, Supervisor};
use motion_bench::proc::{self, Running};
use motion_bench::run_report;
use std::path::Path;
use std::time::{Duration, Instant};

/// What one slice measured.
pub struct Slice {
    pub len: f64,
    pub wakeup: Histogram<u64>,
    pub compute: Histogram<u64>,
    pub roundtrip: Histogram<u64>,
    pub cycles: u64,
    pub misses: u64,
    pub late: u64,
    /// Exact (JSON) distributions of the slice.
    pub json_wakeup: Pct,
    pub json_compute: Pct,
    pub json_roundtrip: Pct,
    /// The supervisor process (all its threads), share of one core over
    /// `wall_s`.
    pub cpu: Option<f64>,
    /// Its motion-io processes, summed, share of one core.
    pub io_cpu: Option<f64>,
    pub wall_s: f64,
    /// Seconds from the start to the clients attached (b, c).
    pub attach_s: Option<f64>,
    pub clients: Clients,
}

/// How a slice went.
pub enum Outcome {
    Done(Box<Slice>),
    /// The supervisor (or attaching to it) failed: the reason.
    Failed(String),
    Interrupted,
}

/// What every slice shares.
pub struct Plan<'a> {
    pub o: &'a Opts,
    pub b: &'a Binaries,
    /// Configs and interval logs of the runs.
    pub tmp: &'a Path,
    /// Makes the service prefixes unique to this bench.
    pub pid: u32,
}

/// Runs slice `i` of `v` for `len` s. Returns the outcome, the
/// supervisor's warnings and what its prefix left in /dev/shm (cleaned).
pub fn run(
    p: &Plan,
    v: Variant,
    i: usize,
    len: f64,
) -> Result<(Outcome, Vec<String>, Vec<String>), String> {
    let o = p.o;
    let prefix = format!("mbc{}{}{i}", p.pid, v.letter());
    let (toml, _) = machine::demo_with(&Supervisor {
        cycle_us: o.period_us,
        cpu: o.cpu,
        priority: o.priority,
        service_prefix: prefix.clone(),
    })?;
    let tag = format!("{}{i}", v.letter());
    let cfg = p.tmp.join(format!("{tag}.toml"));
    std::fs::write(&cfg, toml).map_err(|e| format!("{}: {e}", cfg.display()))?;
    let hlog = p.tmp.join(format!("{tag}.hlog"));
    let mut cmd = run_report::run_command(&p.b.supervisor, &cfg, len, &hlog, &prefix);
    if !v.serves() {
        cmd.arg("--no-control-plane");
    }
    let t0 = Instant::now();
    // its --duration starts after its own start-up: it cannot end before this
    let cut = t0 + Duration::from_secs_f64(len);
    let limit = Duration::from_secs_f64(len + 60.0);
    let mut sup = Running::spawn(&mut cmd, "motion-supervisor run", true, false)?;

    let mut clients = Clients::default();
    let mut attach_s = None;
    let mut attach_failed = None;
    if v.serves() {
        let ready = drive::wait_until_ready(
            &p.b.motionctl,
            &prefix,
            &mut sup,
            Duration::from_secs_f64(len.min(10.0)),
        );
        match ready {
            Ok(()) => {
                let plan = clients::Plan {
                    status_every: Duration::from_millis(o.status_every_ms),
                    stats_every: Duration::from_millis(o.stats_every_ms),
                    homing: v == Variant::Homing,
                };
                let mut a = clients::attach(&p.b.motionctl, &prefix, &plan, cut)?;
                attach_s = Some(t0.elapsed().as_secs_f64());
                while sup.running() && !proc::stop_requested() && t0.elapsed() < limit {
                    a.poll();
                    std::thread::sleep(Duration::from_millis(20));
                }
                clients = a.detach();
            }
            Err(e) => attach_failed = Some(format!("clients not attached: {e}")),
        }
    }
    let ended = sup.wait(limit.saturating_sub(t0.elapsed()), Duration::from_secs(10));
    let (found, remaining) = drive::clean_leftovers(&prefix);
    let mut warnings = Vec::new();
    if !remaining.is_empty() {
        warnings.push(format!(
            "{prefix}: NOT cleaned from /dev/shm: {}",
            remaining.join(", ")
        ));
    }
    if ended.interrupted || proc::stop_requested() {
        return Ok((Outcome::Interrupted, warnings, found));
    }
    if let Some(e) = attach_failed {
        return Ok((Outcome::Failed(e), warnings, found));
    }
    match parse(&ended, &hlog, len) {
        Ok((mut s, w)) => {
            warnings.extend(w);
            s.attach_s = attach_s;
            s.clients = clients;
            Ok((Outcome::Done(Box::new(s)), warnings, found))
        }
        Err(e) => Ok((Outcome::Failed(e), warnings, found)),
    }
}

/// Reads one run (`motion_bench::run_report`). Returns the slice and the
/// run's warnings.
fn parse(ended: &proc::Ended, hlog: &Path, len: f64) -> Result<(Slice, Vec<String>), String> {
    let m = run_report::read(ended, hlog)?;
    let report = m.report;
    let lat = report.latency;
    let io_cpu: Vec<f64> = report.cpu.io.iter().filter_map(|(_, c)| *c).collect();
    let s = Slice {
        len,
        wakeup: m.wakeup,
        compute: m.compute,
        roundtrip: m.roundtrip,
        cycles: lat.cycles,
        misses: lat.deadline_misses,
        late: lat.late_replies,
        json_wakeup: lat.wakeup_us,
        json_compute: lat.compute_us,
        json_roundtrip: lat.io_roundtrip_us,
        cpu: report.cpu.supervisor,
        io_cpu: (!io_cpu.is_empty()).then(|| io_cpu.iter().sum()),
        wall_s: report.cpu.wall_s,
        attach_s: None,
        clients: Clients::default(),
    };
    Ok((s, m.warnings))
}
