//! The command line: what to measure, for how long, where, and with which
//! binaries; the shared groups come from `motion_bench::flags`.

use clap::Parser;
use motion_bench::flags::{Cycle, Files, Slicing};
use std::path::PathBuf;

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
    // --duration per tool, in slices of 5 s by default (at least 0.5)
    #[command(flatten)]
    pub slicing: Slicing<5000, 500>,
    #[command(flatten)]
    pub cycle: Cycle,
    #[command(flatten)]
    pub files: Files,
    /// stress-ng --cpu 1 on the other CPU for the whole bench.
    #[arg(long)]
    pub stress: bool,
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

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    fn parse(args: &str) -> Result<Opts, clap::Error> {
        Opts::try_parse_from(std::iter::once("jitter").chain(args.split_whitespace()))
    }

    #[test]
    fn the_ci_command_line_and_every_flag() {
        Opts::command().debug_assert();
        let ci = "--duration 10 --slice 2.5 --period-us 1000 --out bench/out/ci --no-cyclictest";
        let o = parse(&format!("{ci} --cpu 0")).unwrap();
        let (s, c) = (&o.slicing, &o.cycle);
        assert_eq!((s.duration, s.slice, c.period_us), (10.0, 2.5, 1000));
        assert_eq!(o.files.out(""), PathBuf::from("bench/out/ci"));
        assert!(o.no_cyclictest && o.axes64 && !o.stress && !o.ethercat);
        assert_eq!((o.hist_max_us, o.cyclictest), (20_000, None));
        let o = parse("--cpu=0 --stress --cyclictest=/c --hist-max-us 10").unwrap();
        assert!(o.stress && o.cyclictest == Some("/c".into()) && o.hist_max_us == 10);
        let o = parse("--cpu=0 --ethercat --no-axes64").unwrap();
        assert!(o.ethercat && !o.axes64);
        for args in ["--duration 0", "--slice 0.4", "--hist-max-us 9"] {
            let e = parse(&format!("{args} --cpu 0")).unwrap_err();
            assert!(
                e.to_string().contains(args.split(' ').next().unwrap()),
                "{args}: {e}"
            );
        }
        assert!(parse("--cpu 0 --duration 1 --duration 2").is_err());
    }
}
