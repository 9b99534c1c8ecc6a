//! The command line: how long each variant runs, in which slices, at which
//! period, priority and CPU, whether the homing variant runs too, how often
//! the clients ask, and where the results go. Each value is checked here, so
//! that a mistake is a usage error (exit 2) before anything is started.

use clap::Parser;
use std::path::PathBuf;

/// `bench/out/cpcost` of the source tree, wherever the bench is started from.
const DEFAULT_OUT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/out/cpcost");

#[derive(Debug, Parser)]
#[command(
    name = "cpcost",
    about = "What the control plane (control + status services and their threads) costs the \
             real-time cycle: `motion-supervisor run` with and without it, clients attached.",
    long_about = "Runs `motion-supervisor run` on the demo machine (4 axes, idle) in alternating \
                  slices until each variant has run --duration seconds: (a) with \
                  --no-control-plane (no control or status service), (b) with the control plane \
                  and the clients of a deployed machine attached: one `motionctl status --watch` \
                  (an HMI) for the whole slice, `motionctl status --json` every \
                  --status-every-ms (a PLC polling), `motionctl stats --json` every \
                  --stats-every-ms; with --homing also (c): (b) plus `motionctl home X --json` \
                  back to back. Prints wake-up, compute and I/O round trip per variant, the \
                  ratio (b)/(a), deadline misses, the supervisor's CPU use and the client \
                  requests made and failed; writes DIR/cpcost.json.",
    after_help = "Exit status: 0, or 1 if a supervisor failed to run or crashed, missed more \
                  than 1 % of its deadlines, or a client request failed while the supervisor \
                  ran; 2 on a command-line mistake; 130 if interrupted (partial results are \
                  still printed and written). Percentiles never fail the run."
)]
pub struct Opts {
    /// Seconds per variant.
    #[arg(long, value_name = "S", default_value_t = 60.0, value_parser = positive_secs,
          allow_negative_numbers = true)]
    pub duration: f64,
    /// Seconds per slice (at least 2: the clients attach once the daemon
    /// answers).
    #[arg(long, value_name = "S", default_value_t = 10.0, value_parser = slice_secs,
          allow_negative_numbers = true)]
    pub slice: f64,
    /// Cycle period, µs.
    #[arg(long, value_name = "N", default_value_t = 1000)]
    pub period_us: u32,
    /// SCHED_FIFO priority of the cycle.
    #[arg(long, value_name = "P", default_value_t = 80,
          value_parser = clap::value_parser!(i32).range(1..=99), allow_negative_numbers = true)]
    pub priority: i32,
    /// CPU of the cycle.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = motion_bench::cli::cpu)]
    pub cpu: usize,
    /// Also run variant (c): (b) plus `motionctl home X --json` again and
    /// again (the cycle then computes a homing: compare it with (b)).
    #[arg(long)]
    pub homing: bool,
    /// Period of the PLC-like `motionctl status --json` poller, ms.
    #[arg(long, value_name = "MS", default_value_t = 100,
          value_parser = clap::value_parser!(u64).range(10..=60_000))]
    pub status_every_ms: u64,
    /// Period of `motionctl stats --json`, ms.
    #[arg(long, value_name = "MS", default_value_t = 1000,
          value_parser = clap::value_parser!(u64).range(10..=60_000))]
    pub stats_every_ms: u64,
    /// Output directory (default: bench/out/cpcost of the source tree).
    #[arg(long, value_name = "DIR", default_value = DEFAULT_OUT, hide_default_value = true)]
    pub out: PathBuf,
    /// motion-supervisor binary (default: next to this binary; motion-io and
    /// motionctl next to it; build them with `cargo build --release
    /// --workspace --bins`).
    #[arg(long, value_name = "PATH")]
    pub supervisor: Option<PathBuf>,
}

/// `--duration`: a positive, finite number of seconds.
fn positive_secs(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| "not a valid number".to_string())?;
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err("must be positive".into())
    }
}

/// `--slice`: at least 2 s.
fn slice_secs(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| "not a valid number".to_string())?;
    if v >= 2.0 && v.is_finite() {
        Ok(v)
    } else {
        Err("must be at least 2 s".into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    fn parse(args: &[&str]) -> Result<Opts, clap::Error> {
        Opts::try_parse_from(std::iter::once("cpcost").chain(args.iter().copied()))
    }

    #[test]
    fn the_command_is_well_formed() {
        Opts::command().debug_assert();
    }

    #[test]
    fn defaults() {
        // the default --cpu 1 needs a second CPU
        if motion_bench::sys::cpus() < 2 {
            return;
        }
        let o = parse(&[]).unwrap();
        assert_eq!((o.duration, o.slice), (60.0, 10.0));
        assert_eq!((o.period_us, o.priority, o.cpu), (1000, 80, 1));
        assert_eq!((o.status_every_ms, o.stats_every_ms), (100, 1000));
        assert!(!o.homing);
        assert_eq!(o.out, PathBuf::from(DEFAULT_OUT));
        assert_eq!(o.supervisor, None);
    }

    #[test]
    fn every_flag() {
        let o = parse(&[
            "--duration=10",
            "--slice",
            "2.5",
            "--period-us",
            "250",
            "--priority",
            "90",
            "--cpu",
            "0",
            "--homing",
            "--status-every-ms",
            "50",
            "--stats-every-ms=500",
            "--out",
            "/tmp/x",
            "--supervisor",
            "/s",
        ])
        .unwrap();
        assert_eq!((o.duration, o.slice, o.period_us), (10.0, 2.5, 250));
        assert_eq!((o.priority, o.cpu), (90, 0));
        assert!(o.homing);
        assert_eq!((o.status_every_ms, o.stats_every_ms), (50, 500));
        assert_eq!(o.out, PathBuf::from("/tmp/x"));
        assert_eq!(o.supervisor, Some(PathBuf::from("/s")));
    }

    #[test]
    fn out_of_range_values_name_their_flag() {
        for (args, flag) in [
            (&["--duration", "0", "--cpu", "0"][..], "--duration"),
            (&["--duration", "-1", "--cpu", "0"], "--duration"),
            (&["--slice", "1.5", "--cpu", "0"], "--slice"),
            (&["--priority", "100", "--cpu", "0"], "--priority"),
            (
                &["--status-every-ms", "5", "--cpu", "0"],
                "--status-every-ms",
            ),
            (&["--stats-every-ms", "0", "--cpu", "0"], "--stats-every-ms"),
        ] {
            let e = parse(args).unwrap_err();
            assert_eq!(
                e.kind(),
                clap::error::ErrorKind::ValueValidation,
                "{args:?}"
            );
            assert!(e.to_string().contains(flag), "{args:?}: {e}");
        }
        assert!(parse(&["--bogus"]).is_err());
        assert!(parse(&["stray"]).is_err());
    }
}
