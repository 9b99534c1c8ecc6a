//! Running `motion-supervisor run` for one slice and reading what it
//! measured: its typed JSON report (exact figures, warnings) and its
//! interval log (the histograms the percentiles are merged from). The
//! supervisor measures its own cycle; the bench only starts it and reads.

use hdrhistogram::Histogram;
use motion_bench::drive;
use motion_bench::hist::Pct;
use motion_bench::proc::{self, Running};
use motion_bench::run_report;
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
    Ok(run_report::run_command(
        supervisor, &cfg_path, len, hlog, prefix,
    ))
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

/// Parses one supervisor run (`motion_bench::run_report`). Returns the
/// slice and the run's warnings.
pub fn our_slice(
    ended: &proc::Ended,
    hlog: &Path,
    start: Duration,
    len: f64,
) -> Result<(OurSlice, Vec<String>), String> {
    let m = run_report::read(ended, hlog)?;
    let lat = m.report.latency;
    let s = OurSlice {
        start,
        len: Duration::from_secs_f64(len),
        wakeup: m.wakeup,
        compute: m.compute,
        roundtrip: m.roundtrip,
        cycles: lat.cycles,
        misses: lat.deadline_misses,
        late: lat.late_replies,
        json_wakeup: lat.wakeup_us,
        json_compute: lat.compute_us,
        json_roundtrip: lat.io_roundtrip_us,
    };
    Ok((s, m.warnings))
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
