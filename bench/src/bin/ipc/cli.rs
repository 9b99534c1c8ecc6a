//! The bench's command line (the echo peer has its own, in [`crate::echo`]).
//! Every check is made before any peer is started, so that a mistake is a
//! usage error (exit 2), not a half-run bench.

use crate::mode::{self, Mode};
use clap::{CommandFactory, Parser};
use motion_bench::flags::Cycle;
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "ipc",
    about = "Round trip command → feedback through iceoryx2, one message per period, with \
             (a) motion-io waiting on the event, (b) motion-io --spin, and (c) a bare \
             iceoryx2 echo of the same payload sizes (event-waiting and spinning).",
    after_help = "The measuring thread plays the cycle: --cpu, --priority, --period-us (one \
                  message per period, 20..=100000 µs); event-waiting peers run at priority \
                  P-10 (so P is within 11..=99), spinning peers SCHED_OTHER. The bare echo peer \
                  is this binary re-run as `ipc --role echo --prefix P [--cpu N] [--priority P \
                  | --spin]` (see `ipc --role echo --help`).\n\n\
                  Exit status: 0, or 1 if a mode failed or motion-io was not found; 2 on a \
                  command-line mistake; 130 if interrupted."
)]
pub struct Opts {
    /// Measured messages per mode.
    #[arg(long, value_name = "N", default_value_t = 10_000,
          value_parser = clap::value_parser!(u64).range(1..))]
    pub count: u64,
    #[command(flatten)]
    pub cycle: Cycle,
    /// CPU of the peer (default: the other one, 0; 1 with --cpu 0).
    #[arg(long = "peer-cpu", value_name = "N", value_parser = motion_config::args::cpu)]
    peer_cpu_arg: Option<usize>,
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
    /// Parses the process's command line with the checks that involve two
    /// flags or the peers, exiting as clap does.
    pub fn parse_checked() -> Self {
        let o = Opts::parse();
        if let Err(e) = o.check() {
            Opts::command()
                .error(clap::error::ErrorKind::ValueValidation, e)
                .exit();
        }
        o
    }

    fn check(&self) -> Result<(), String> {
        let (p, period) = (self.cycle.priority, self.cycle.period_us);
        if !(11..=99).contains(&p) {
            return Err(format!(
                "--priority {p}: must be within 11..=99 (peers run at P-10)"
            ));
        }
        if !(20..=100_000).contains(&period) {
            return Err(format!("--period-us {period}: must be within 20..=100000"));
        }
        if self.peer_cpu_arg.is_none() {
            motion_config::args::cpu(&self.peer_cpu().to_string()).map_err(|e| {
                format!(
                    "--peer-cpu (its default with --cpu {}): {e}",
                    self.cycle.cpu
                )
            })?;
        }
        Ok(())
    }

    /// The peer's CPU: `--peer-cpu`, else another one than `--cpu`.
    pub fn peer_cpu(&self) -> usize {
        self.peer_cpu_arg.unwrap_or(self.cycle.other_cpu())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(args: &str) -> Result<Opts, clap::Error> {
        Opts::try_parse_from(std::iter::once("ipc").chain(args.split_whitespace()))
    }

    #[test]
    fn flags_and_checks() {
        Opts::command().debug_assert();
        let o = parse("--cpu 0").unwrap();
        assert_eq!(
            (o.count, o.warmup, o.peer_cpu(), o.cpu_dma_latency),
            (10_000, 200, 1, 0)
        );
        assert_eq!((o.modes, o.io), (Mode::ALL.to_vec(), None));
        let o = parse("--cpu=0 --count=5 --modes bare-spin,io-event --io /x").unwrap();
        assert_eq!((o.count, o.modes), (5, vec![Mode::BareSpin, Mode::IoEvent]));
        assert_eq!(mode::parse(" io-spin "), Ok(Mode::IoSpin));
        assert!(parse("--cpu=0 --peer-cpu 0 --cpu-dma-latency -1").is_ok());
        for args in ["--priority 10", "--period-us 19", "--period-us 100001"] {
            let o = parse(&format!("{args} --cpu 0")).unwrap();
            let flag = args.split(' ').next().unwrap();
            assert!(o.check().unwrap_err().contains(flag), "{args}");
        }
        for args in ["--count 0", "--modes io-event,nope", "--modes="] {
            let e = parse(&format!("{args} --cpu 0")).unwrap_err();
            let flag = args.split([' ', '=']).next().unwrap();
            assert!(e.to_string().contains(flag), "{args}: {e}");
        }
        assert!(parse("--cpu=0 --role echo").is_err());
        assert!(parse("--cpu=0 --modes io-event --modes bare-spin").is_err());
    }
}
