//! Running `motion-supervisor run` for one slice and reading what it
//! measured: its typed JSON report (exact figures, warnings) and its
//! interval log (the histograms the percentiles are merged from). The
//! supervisor measures its own cycle; the bench only starts it and reads.

use hdrhistogram::Histogram;
use motion_bench::drive;
use motion_bench::hist::{self, Pct};
use motion_bench::proc::{self, Running};
use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// One supervisor slice.
pub struct OurSlice {
    pub start: Duration,
    pub len: Duration,
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
}

/// Writes `toml` to `tmp/{tag}.toml` and returns the `motion-supervisor
/// run` command on it for `len` s, with its JSON report on stdout and an
/// interval log at `hlog`, under the service prefix `prefix`.
pub fn run_command(
    supervisor: &Path,
    tmp: &Path,
    tag: &str,
    toml: &str,
    prefix: &str,
    len: f64,
    hlog: &Path,
) -> Result<Command, String> {
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
    Ok(cmd)
}

/// Runs `motion-supervisor run` on `toml` for `len` s with an interval log
/// at `hlog`, output captured.
pub fn run(
    supervisor: &Path,
    tmp: &Path,
    tag: &str,
    toml: &str,
    prefix: &str,
    len: f64,
    hlog: &Path,
) -> Result<proc::Ended, String> {
    let mut cmd = run_command(supervisor, tmp, tag, toml, prefix, len, hlog)?;
    Ok(Running::spawn(&mut cmd, "motion-supervisor", true, false)?
        .wait(Duration::from_secs_f64(len + 60.0), Duration::from_secs(10)))
}

/// Parses one supervisor run: its JSON and its hlog. Returns the slice and
/// the run's warnings.
pub fn our_slice(
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

/// The last `n` lines of a tool's output, on one line, for an error message.
pub fn last_lines(s: &str, n: usize) -> String {
    let lines: Vec<&str> = s.lines().collect();
    lines[lines.len().saturating_sub(n)..].join(" | ")
}

/// Shared memory the supervisor (or its motion-io, or a motionctl) left
/// behind: reported, then removed if no process of the prefix lives.
pub fn leftover_shm(prefix: &str, warnings: &mut BTreeSet<String>) {
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
