//! A `motion-supervisor run` as the benches start and read it: the command
//! (`--json` report on stdout, `--hlog` interval log), and what it measured
//! — its typed report (exact min/max, counts, CPU use, warnings) and its
//! histograms. The supervisor measures its own cycle; a bench only starts
//! it and reads, all of them the same way.

use crate::drive;
use crate::hist;
use crate::proc::Ended;
use hdrhistogram::Histogram;
use std::path::Path;
use std::process::Command;

/// `motion-supervisor run --config CONFIG --duration LEN --json --hlog HLOG
/// --service-prefix PREFIX`.
pub fn run_command(
    supervisor: &Path,
    config: &Path,
    len: f64,
    hlog: &Path,
    prefix: &str,
) -> Command {
    let mut cmd = Command::new(supervisor);
    cmd.arg("run")
        .arg("--config")
        .arg(config)
        .arg("--duration")
        .arg(format!("{len}"))
        .arg("--json")
        .arg("--hlog")
        .arg(hlog)
        .arg("--service-prefix")
        .arg(prefix);
    cmd
}

/// What one run measured.
pub struct Measured {
    pub report: motion_report::RunReport,
    pub wakeup: Histogram<u64>,
    pub compute: Histogram<u64>,
    pub roundtrip: Histogram<u64>,
    /// The run's warnings, its real-time set-up's, and one if the cycle did
    /// not run SCHED_FIFO.
    pub warnings: Vec<String>,
}

/// Reads a finished run: it must have succeeded, printed its report and
/// measured cycles; errors carry the end of its stderr.
pub fn read(ended: &Ended, hlog: &Path) -> Result<Measured, String> {
    let tail = || {
        let e = ended.stderr.trim();
        if e.is_empty() {
            String::new()
        } else {
            format!("; its stderr: {}", drive::tail(e, 8))
        }
    };
    if !ended.success() {
        return Err(format!("{}{}", ended.describe(), tail()));
    }
    let report: motion_report::RunReport = ended
        .stdout
        .lines()
        .rev()
        .find_map(|l| serde_json::from_str(l.trim()).ok())
        .ok_or_else(|| format!("no run report on its stdout{}", tail()))?;
    if report.latency.cycles == 0 {
        return Err(format!("it measured no cycles{}", tail()));
    }
    let mut warnings = report.warnings.clone();
    if let Some(rt) = &report.rt {
        warnings.extend(rt.warnings.iter().cloned());
    }
    if report.rt.as_ref().map(|r| r.policy.as_str()) != Some("SCHED_FIFO") {
        warnings.push(format!(
            "the cycle did not run SCHED_FIFO (rt: {:?})",
            report.rt
        ));
    }
    let intervals = hist::read_interval_log_file(hlog)?;
    Ok(Measured {
        wakeup: hist::sum_tag(&intervals, "wakeup"),
        compute: hist::sum_tag(&intervals, "compute"),
        roundtrip: hist::sum_tag(&intervals, "roundtrip"),
        report,
        warnings,
    })
}
