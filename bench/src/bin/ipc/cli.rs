//! The bench's command line (the echo peer has its own, in [`crate::echo`]).
//! Every check is made before any peer is started, so that a mistake is a
//! usage error (exit 2), not a half-run bench.

use crate::mode::{self, Mode};
use clap::Parser;
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "ipc",
    about = "Round trip command → feedback through iceoryx2, one message per period, with \
             (a) motion-io waiting on the event, (b) motion-io --spin, and (c) a bare \
             iceoryx2 echo of the same payload sizes (event-waiting and spinning).",
    after_help = "The bare echo peer is this binary re-run as `ipc --role echo --prefix P \
                  [--cpu N] [--priority P | --spin]` (see `ipc --role echo --help`).\n\n\
                  Exit status: 0, or 1 if a mode failed or motion-io was not found; 2 on a \
                  command-line mistake; 130 if interrupted."
)]
pub struct Opts {
    /// Measured messages per mode.
    #[arg(long, value_name = "N", default_value_t = 10_000,
          value_parser = clap::value_parser!(u64).range(1..))]
    pub count: u64,
    /// One message per period, µs.
    #[arg(long, value_name = "N", default_value_t = 1000,
          value_parser = clap::value_parser!(u32).range(20..=100_000))]
    pub period_us: u32,
    /// CPU of the measuring thread, SCHED_FIFO.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = motion_bench::cli::cpu)]
    pub cpu: usize,
    /// CPU of the peer (default: the other one, 0; 1 with --cpu 0).
    #[arg(long = "peer-cpu", value_name = "N", value_parser = motion_bench::cli::cpu)]
    peer_cpu_arg: Option<usize>,
    /// SCHED_FIFO priority of the measuring thread; event-waiting peers run
    /// at P-10, spinning peers SCHED_OTHER.
    #[arg(long, value_name = "P", default_value_t = 80, value_parser = priority,
          allow_negative_numbers = true)]
    pub priority: i32,
    /// Answered messages before measuring.
    #[arg(long, value_name = "N", default_value_t = 200)]
    pub warmup: u64,
    /// Comma-separated subset of io-event,bare-event,io-spin,bare-spin.
    #[arg(long, value_name = "LIST", value_parser = mode::parse, value_delimiter = ',',
          action = clap::ArgAction::Set, default_value = "io-event,bare-event,io-spin,bare-spin")]
    pub modes: Vec<Mode>,
    /// motion-io binary (default: next to this binary, or $MOTION_IO_BIN).
    #[arg(long, value_name = "PATH")]
    pub io: Option<PathBuf>,
    /// Hold /dev/cpu_dma_latency at US during the bench, as the supervisor
    /// does (negative: leave it alone).
    #[arg(
        long,
        value_name = "US",
        default_value_t = 0,
        allow_negative_numbers = true
    )]
    pub cpu_dma_latency: i32,
}

impl Opts {
    /// Parses the process's command line; also checks the default
    /// `--peer-cpu`, which depends on `--cpu`, exiting as clap does.
    pub fn parse_checked() -> Self {
        let o = Opts::parse();
        if let Err(e) = o.check() {
            use clap::CommandFactory;
            Opts::command()
                .error(clap::error::ErrorKind::ValueValidation, e)
                .exit();
        }
        o
    }

    fn check(&self) -> Result<(), String> {
        if self.peer_cpu_arg.is_none() {
            let n = motion_bench::sys::cpus();
            if self.peer_cpu() >= n {
                return Err(format!(
                    "--peer-cpu {} (its default with --cpu {}): this machine has {n} CPUs",
                    self.peer_cpu(),
                    self.cpu
                ));
            }
        }
        Ok(())
    }

    /// The peer's CPU: `--peer-cpu`, else another one than `--cpu`.
    pub fn peer_cpu(&self) -> usize {
        self.peer_cpu_arg
            .unwrap_or(if self.cpu == 0 { 1 } else { 0 })
    }
}

/// `--priority`: 11..=99, since event-waiting peers run at P-10.
fn priority(s: &str) -> Result<i32, String> {
    let p: i32 = s.parse().map_err(|_| "not a valid number".to_string())?;
    if (11..=99).contains(&p) {
        Ok(p)
    } else {
        Err("must be within 11..=99 (peers run at P-10)".into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    fn parse(args: &[&str]) -> Result<Opts, clap::Error> {
        Opts::try_parse_from(std::iter::once("ipc").chain(args.iter().copied()))
    }

    /// The default `--cpu 1` exists; on one CPU only `--cpu 0` parses.
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
        assert_eq!(
            (o.count, o.period_us, o.cpu, o.priority),
            (10_000, 1000, 1, 80)
        );
        assert_eq!(o.peer_cpu(), 0);
        assert_eq!(o.warmup, 200);
        assert_eq!(o.modes, Mode::ALL.to_vec());
        assert_eq!(o.io, None);
        assert_eq!(o.cpu_dma_latency, 0);
        assert!(o.check().is_ok());
    }

    #[test]
    fn every_flag() {
        if !two_cpus() {
            return;
        }
        let o = parse(&[
            "--count=5",
            "--period-us",
            "250",
            "--cpu",
            "0",
            "--priority",
            "11",
            "--warmup",
            "0",
            "--modes",
            "bare-spin, io-event",
            "--io",
            "/x/motion-io",
            "--cpu-dma-latency",
            "-1",
        ])
        .unwrap();
        assert_eq!((o.count, o.period_us, o.cpu, o.priority), (5, 250, 0, 11));
        assert_eq!(o.peer_cpu(), 1);
        assert_eq!(o.warmup, 0);
        assert_eq!(o.modes, vec![Mode::BareSpin, Mode::IoEvent]);
        assert_eq!(o.io, Some(PathBuf::from("/x/motion-io")));
        assert_eq!(o.cpu_dma_latency, -1);
        assert_eq!(parse(&["--peer-cpu", "1"]).unwrap().peer_cpu(), 1);
    }

    #[test]
    fn out_of_range_values_name_their_flag() {
        if !two_cpus() {
            return;
        }
        for (args, flag) in [
            (&["--count", "0"][..], "--count"),
            (&["--period-us", "19"], "--period-us"),
            (&["--period-us", "100001"], "--period-us"),
            (&["--priority", "10"], "--priority"),
            (&["--priority", "100"], "--priority"),
            (&["--modes", "io-event,nope"], "--modes"),
            (&["--modes", ""], "--modes"),
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
        for flag in ["--cpu", "--peer-cpu"] {
            let e = parse(&[flag, &beyond]).unwrap_err();
            assert!(e.to_string().contains(flag), "{e}");
        }
    }

    #[test]
    fn unknown_and_repeated_flags_are_errors() {
        assert!(parse(&["--role", "echo"]).is_err());
        assert!(parse(&["--count", "1", "--count", "2"]).is_err());
        assert!(parse(&["--modes", "io-event", "--modes", "bare-spin"]).is_err());
    }
}
