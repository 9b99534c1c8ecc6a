//! The command line: what to measure, for how long, where, and with which
//! binaries. Each value is checked here, so that a mistake is a usage error
//! (exit 2) before anything is started.

use clap::Parser;
use std::path::PathBuf;

/// `bench/out` of the source tree, wherever the bench is started from.
const DEFAULT_OUT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/out");

#[derive(Debug, Parser)]
#[command(
    name = "jitter",
    about = "Wake-up latency of the supervisor's real cycle side by side with cyclictest.",
    long_about = "Runs `motion-supervisor run` and `cyclictest` in alternating slices until \
                  each has run --duration seconds, at the same period, SCHED_FIFO priority and \
                  CPU, then prints their wake-up latencies side by side and writes \
                  DIR/jitter-<period>us.{hlog,svg,json}. The supervisor runs twice per slice: \
                  the demo machine (4 axes, idle) and a 64-axis machine that `motionctl home \
                  --parallel` homes again and again while it is measured.",
    after_help = "Exit status: 0, or 1 if a tool failed to run or crashed, or the supervisor \
                  missed more than 1 % of its deadlines; 2 on a command-line mistake; 130 if \
                  interrupted. Percentiles never fail the run."
)]
pub struct Opts {
    /// Seconds per tool.
    #[arg(long, value_name = "S", default_value_t = 60.0, value_parser = positive_secs,
          allow_negative_numbers = true)]
    pub duration: f64,
    /// Cycle period, µs.
    #[arg(long, value_name = "N", default_value_t = 1000)]
    pub period_us: u32,
    /// Seconds per slice (at least 0.5).
    #[arg(long, value_name = "S", default_value_t = 5.0, value_parser = slice_secs,
          allow_negative_numbers = true)]
    pub slice: f64,
    /// SCHED_FIFO priority of both.
    #[arg(long, value_name = "P", default_value_t = 80,
          value_parser = clap::value_parser!(i32).range(1..=99), allow_negative_numbers = true)]
    pub priority: i32,
    /// CPU of both.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = motion_bench::cli::cpu)]
    pub cpu: usize,
    /// stress-ng --cpu 1 on the other CPU for the whole bench.
    #[arg(long)]
    pub stress: bool,
    /// Output directory (default: bench/out of the source tree).
    #[arg(long, value_name = "DIR", default_value = DEFAULT_OUT, hide_default_value = true)]
    pub out: PathBuf,
    /// motion-supervisor binary (default: next to this binary; build it with
    /// `cargo build --release --workspace --bins`).
    #[arg(long, value_name = "PATH")]
    pub supervisor: Option<PathBuf>,
    /// cyclictest binary (default: $PATH).
    #[arg(long, value_name = "PATH")]
    pub cyclictest: Option<PathBuf>,
    /// Run the supervisor half only.
    #[arg(long)]
    pub no_cyclictest: bool,
    /// cyclictest's histogram range, µs (more goes to its overflow count).
    #[arg(long, value_name = "N", default_value_t = 20_000,
          value_parser = clap::value_parser!(u64).range(10..))]
    pub hist_max_us: u64,
    /// Also run the supervisor with motion-io --backend ethercat in every
    /// slice: the demo machine's axes over a veth pair to ecat-emu's
    /// emulated drives (root: ip netns, raw sockets); reported next to the
    /// sim backend.
    #[arg(long)]
    pub ethercat: bool,
    /// Skip the 64-axis machine (demo machine only).
    #[arg(long = "no-axes64", action = clap::ArgAction::SetFalse)]
    pub axes64: bool,
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

/// `--slice`: at least 0.5 s.
fn slice_secs(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| "not a valid number".to_string())?;
    if v >= 0.5 && v.is_finite() {
        Ok(v)
    } else {
        Err("must be at least 0.5 s".into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    fn parse(args: &[&str]) -> Result<Opts, clap::Error> {
        Opts::try_parse_from(std::iter::once("jitter").chain(args.iter().copied()))
    }

    /// The default `--cpu 1` exists (as on CI); on one CPU only an explicit
    /// `--cpu 0` parses.
    fn two_cpus() -> bool {
        motion_bench::sys::cpus() >= 2
    }

    #[test]
    fn the_command_is_well_formed() {
        Opts::command().debug_assert();
    }

    #[test]
    fn defaults() {
        if !two_cpus() {
            return;
        }
        let o = parse(&[]).unwrap();
        assert_eq!(o.duration, 60.0);
        assert_eq!(o.period_us, 1000);
        assert_eq!(o.slice, 5.0);
        assert_eq!(o.priority, 80);
        assert_eq!(o.cpu, 1);
        assert!(!o.stress && !o.no_cyclictest && !o.ethercat);
        assert!(o.axes64);
        assert_eq!(o.out, PathBuf::from(DEFAULT_OUT));
        assert_eq!(o.supervisor, None);
        assert_eq!(o.cyclictest, None);
        assert_eq!(o.hist_max_us, 20_000);
    }

    #[test]
    fn the_ci_command_line() {
        if !two_cpus() {
            return;
        }
        let o = parse(&[
            "--duration",
            "10",
            "--slice",
            "2.5",
            "--period-us",
            "1000",
            "--out",
            "bench/out/ci",
            "--no-cyclictest",
        ])
        .unwrap();
        assert_eq!((o.duration, o.slice, o.period_us), (10.0, 2.5, 1000));
        assert_eq!(o.out, PathBuf::from("bench/out/ci"));
        assert!(o.no_cyclictest);
    }

    #[test]
    fn every_flag_and_the_equals_form() {
        let o = parse(&[
            "--duration=1",
            "--period-us=250",
            "--priority",
            "90",
            "--cpu",
            "0",
            "--stress",
            "--supervisor",
            "/s",
            "--cyclictest=/c",
            "--hist-max-us",
            "10",
            "--ethercat",
            "--no-axes64",
        ])
        .unwrap();
        assert_eq!(
            (o.duration, o.period_us, o.priority, o.cpu),
            (1.0, 250, 90, 0)
        );
        assert!(o.stress && o.ethercat && !o.axes64);
        assert_eq!(o.supervisor, Some(PathBuf::from("/s")));
        assert_eq!(o.cyclictest, Some(PathBuf::from("/c")));
        assert_eq!(o.hist_max_us, 10);
    }

    #[test]
    fn out_of_range_values_name_their_flag() {
        if !two_cpus() {
            return;
        }
        for (args, flag) in [
            (&["--duration", "0"][..], "--duration"),
            (&["--duration", "-1"], "--duration"),
            (&["--duration", "inf"], "--duration"),
            (&["--slice", "0.4"], "--slice"),
            (&["--priority", "0"], "--priority"),
            (&["--priority", "100"], "--priority"),
            (&["--priority", "-5"], "--priority"),
            (&["--hist-max-us", "9"], "--hist-max-us"),
            (&["--period-us", "x"], "--period-us"),
        ] {
            let e = parse(args).unwrap_err();
            assert_eq!(
                e.kind(),
                clap::error::ErrorKind::ValueValidation,
                "{args:?}"
            );
            assert!(e.to_string().contains(flag), "{args:?}: {e}");
        }
        let beyond = motion_bench::sys::cpus().to_string();
        let e = parse(&["--cpu", &beyond]).unwrap_err();
        assert!(e.to_string().contains("--cpu"), "{e}");
    }

    #[test]
    fn unknown_repeated_and_valueless_flags_are_errors() {
        assert!(parse(&["--bogus"]).is_err());
        assert!(parse(&["--duration", "1", "--duration", "2"]).is_err());
        assert!(parse(&["--out"]).is_err());
        assert!(parse(&["stray"]).is_err());
    }
}
