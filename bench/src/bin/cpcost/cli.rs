//! The command line: how long each variant runs, in which slices, whether
//! the homing variant runs too, how often the clients ask, and where the
//! results go; the shared groups come from `motion_bench::flags`.

use clap::Parser;
use motion_bench::flags::{Cycle, Files, Slicing};

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
    // --duration per variant, in slices of 10 s by default (at least 2: the
    // clients attach once the daemon answers)
    #[command(flatten)]
    pub slicing: Slicing<10000, 2000>,
    #[command(flatten)]
    pub cycle: Cycle,
    #[command(flatten)]
    pub files: Files,
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
}

impl Opts {
    /// Seconds of slice `i`; the last one at least 2 s (the clients must
    /// attach).
    pub fn slice_len(&self, i: usize) -> f64 {
        self.slicing.len(i).max(2.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    fn parse(args: &str) -> Result<Opts, clap::Error> {
        let args = ["cpcost", "--cpu", "0"]
            .into_iter()
            .chain(args.split_whitespace());
        Opts::try_parse_from(args)
    }

    #[test]
    fn flags_and_slices() {
        Opts::command().debug_assert();
        let o = parse("").unwrap();
        let s = &o.slicing;
        assert_eq!(
            (s.duration, s.slice, s.count(), o.slice_len(5)),
            (60.0, 10.0, 6, 10.0)
        );
        assert_eq!(
            (o.status_every_ms, o.stats_every_ms, o.homing),
            (100, 1000, false)
        );
        let o = parse("--duration=25 --homing --status-every-ms 50").unwrap();
        assert_eq!(
            (o.slicing.count(), o.slice_len(1), o.slice_len(2)),
            (3, 10.0, 5.0)
        );
        assert!(o.homing && o.status_every_ms == 50);
        for args in ["--slice 1.5", "--status-every-ms 5", "--stats-every-ms 0"] {
            let e = parse(args).unwrap_err();
            assert!(
                e.to_string().contains(args.split(' ').next().unwrap()),
                "{args}: {e}"
            );
        }
    }
}
