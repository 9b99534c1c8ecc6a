//! A timed daemon run as the slice benches make it — `motion-supervisor run
//! --duration S --json --hlog F` — and what it measured, read back: its
//! typed report and its interval log summed per tag. The supervisor
//! measures its own cycle; a bench only starts it and reads, every bench
//! the same way.

use std::path::{Path, PathBuf};

use hdrhistogram::Histogram;
use motion_report::RunReport;
use motion_supervisor::hlog;

use crate::bins::Binaries;
use crate::drive::{run_command, write_config};
use crate::proc::{tail, Ended, Running};

/// Starts the daemon of the machine `toml` (written to `dir/TAG.toml`)
/// under `prefix` for `len` s, its intervals logged to `dir/TAG.hlog`, with
/// the `extra` arguments; returns it and the log's path.
pub fn start(
    b: &Binaries,
    dir: &Path,
    (tag, toml, prefix): (&str, &str, &str),
    len: f64,
    extra: &[&str],
) -> Result<(Running, PathBuf), String> {
    let (cfg, log) = (
        write_config(dir, tag, toml)?,
        dir.join(format!("{tag}.hlog")),
    );
    let mut cmd = run_command(b, &cfg, prefix);
    cmd.args(["--duration", &len.to_string(), "--hlog"])
        .arg(&log);
    let run = Running::spawn(cmd.args(extra), "motion-supervisor run", true, false)?;
    Ok((run, log))
}

/// What a finished run measured.
#[derive(Debug)]
pub struct Measured {
    /// Its report: the exact counts, min and max, CPU use, warnings.
    pub report: RunReport,
    /// Wake-up, compute and I/O round trip of every cycle (its log).
    pub wakeup: Histogram<u64>,
    pub compute: Histogram<u64>,
    pub roundtrip: Histogram<u64>,
}

impl Measured {
    /// The supervisor process (all its threads): share of one core over
    /// the run.
    pub fn cpu(&self) -> Option<f64> {
        self.report.cpu.supervisor
    }

    /// Its motion-io processes, summed: share of one core over the run.
    pub fn io_cpu(&self) -> Option<f64> {
        let io: Vec<f64> = self.report.cpu.io.iter().filter_map(|(_, c)| *c).collect();
        (!io.is_empty()).then(|| io.iter().sum())
    }
}

/// Reads a finished run: it must have succeeded, printed its report and
/// measured cycles; errors carry the end of its stderr. Returns what it
/// measured and the warnings of the run and of its real-time set-up (one
/// more if the cycle did not run SCHED_FIFO).
pub fn read(ended: &Ended, log: &Path) -> Result<(Measured, Vec<String>), String> {
    let tail = match ended.stderr.trim() {
        "" => String::new(),
        e => format!("; its stderr: {}", tail(e, 8)),
    };
    if !ended.success() {
        return Err(format!("{}{tail}", ended.describe()));
    }
    let report: RunReport = (ended.stdout.lines().rev())
        .find_map(|l| serde_json::from_str(l.trim()).ok())
        .ok_or_else(|| format!("no run report on its stdout{tail}"))?;
    if report.latency.cycles == 0 {
        return Err(format!("it measured no cycles{tail}"));
    }
    let rt = &report.rt;
    let mut warnings = report.warnings.clone();
    warnings.extend(rt.iter().flat_map(|r| r.warnings.iter().cloned()));
    if rt.as_ref().map(|r| r.policy.as_str()) != Some("SCHED_FIFO") {
        warnings.push(format!("the cycle did not run SCHED_FIFO (rt: {rt:?})"));
    }
    let iv = hlog::read(log)?;
    let [wakeup, compute, roundtrip] =
        ["wakeup", "compute", "roundtrip"].map(|t| hlog::sum(&iv, t));
    let m = Measured {
        report,
        wakeup,
        compute,
        roundtrip,
    };
    Ok((m, warnings))
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion_supervisor::stats::HistSet;
    use std::os::unix::process::ExitStatusExt;
    use std::process::ExitStatus;
    use std::time::SystemTime;

    fn ended(code: i32, stdout: &str) -> Ended {
        Ended {
            status: Some(ExitStatus::from_raw(code << 8)),
            stdout: stdout.into(),
            stderr: "x: started\nx: stopped\n".into(),
            timed_out: false,
            interrupted: false,
        }
    }

    #[test]
    fn a_run_reads_back_from_its_report_and_log() {
        let mut set = HistSet::new();
        set.wakeup.saturating_record(5_000);
        set.compute.saturating_record(2_000);
        (set.cycles, set.start_ns, set.end_ns) = (1, 1_000, 1_000_000);
        let mut lines = hlog::IntervalLines::new(4);
        let log = std::env::temp_dir().join(format!("mh-runs-{}.hlog", std::process::id()));
        std::fs::write(
            &log,
            [&hlog::header(SystemTime::now()), lines.add(&set).unwrap()].concat(),
        )
        .unwrap();
        let mut report = RunReport::default();
        (report.latency.cycles, report.cpu.supervisor) = (1, Some(0.25));
        report.cpu.io = vec![("io".into(), Some(0.5)), ("bus".into(), Some(0.25))];
        let json = serde_json::to_string(&report).unwrap();
        let (m, warnings) = read(&ended(0, &format!("{json}\n")), &log).unwrap();
        assert_eq!(
            (m.wakeup.len(), m.compute.len(), m.roundtrip.len()),
            (1, 1, 0)
        );
        assert_eq!((m.cpu(), m.io_cpu()), (Some(0.25), Some(0.75)));
        assert!(
            warnings[0].starts_with("the cycle did not run SCHED_FIFO"),
            "{warnings:?}"
        );
        let e = read(&ended(1, &json), &log).err().unwrap();
        assert_eq!(e, "exit code 1; its stderr: x: started | x: stopped");
        report.latency.cycles = 0;
        let json = serde_json::to_string(&report).unwrap();
        assert!(read(&ended(0, &json), &log)
            .unwrap_err()
            .starts_with("it measured no cycles"));
        assert!(read(&ended(0, "{}"), &log)
            .unwrap_err()
            .starts_with("no run report"));
        std::fs::remove_file(&log).unwrap();
    }
}
