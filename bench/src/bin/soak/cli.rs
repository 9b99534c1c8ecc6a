//! The command line: how many homings, how (daemon or one `home` each),
//! under which load, and what to record; the shared groups come from
//! `motion_bench::flags`.

use clap::{Parser, ValueEnum};
use motion_bench::flags::{Cycle, Files};

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Via {
    /// One `motion-supervisor run` daemon per block; each homing is a
    /// `motionctl home X --json` (and a `motionctl status` before the next
    /// one checks that X is still homed).
    Daemon,
    /// Each homing is its own `motion-supervisor home --json` (start, spawn
    /// motion-io, home, stop).
    Home,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Which {
    /// The one-axis switch machine.
    One,
    /// The 64-axis machine.
    Axes64,
}

#[derive(Debug, Parser)]
#[command(
    name = "soak",
    about = "Counts spurious homing failures: N one-axis switch homings at default settings \
             (a share of them with stress-ng on the other CPU) and parallel homings of a \
             64-axis machine.",
    after_help = "Exit status: 0 when it ran to its end (whatever the counts: they are figures, \
                  not assertions), 1 if a supervisor could not be run, 2 on a command-line \
                  mistake, 130 if interrupted (partial counts are printed and written)."
)]
pub struct Opts {
    /// One-axis homings in all (0: skip that part).
    #[arg(long, default_value_t = 500)]
    pub homings: u32,
    /// Share of the one-axis homings run with `stress-ng --cpu 1` on the
    /// other CPU (in whole blocks, interleaved with unloaded blocks).
    #[arg(long, default_value_t = 0.5)]
    pub stress_share: f64,
    /// How the one-axis homings are run.
    #[arg(long, value_enum, default_value = "daemon")]
    pub via: Via,
    /// One-axis homings per block (one daemon per block with --via daemon;
    /// stress-ng is switched per block).
    #[arg(long, default_value_t = 50)]
    pub block: u32,
    /// Parallel homings of the 64-axis machine (each a fresh
    /// `motion-supervisor home --parallel --json`; 0: skip that part).
    #[arg(long, default_value_t = 20)]
    pub runs64: u32,
    /// Run the 64-axis homings with stress-ng on the other CPU too.
    #[arg(long)]
    pub stress64: bool,
    #[command(flatten)]
    pub cycle: Cycle,
    /// Seconds one homing may take before it counts as failed.
    #[arg(long, default_value_t = 60.0, value_parser = motion_config::args::seconds)]
    pub timeout: f64,
    #[command(flatten)]
    pub files: Files,
    /// With --via daemon: record every one-axis homing with `motionctl trace
    /// X --home` (every cycle: phase, commanded and actual motion, fresh
    /// feedback or not) instead of `motionctl home X`, the result read from
    /// `motionctl status`; the traces of failed homings are kept in
    /// OUT/soak-evidence/.
    #[arg(long)]
    pub trace: bool,
    /// With --via daemon: a spy subscriber (on the other CPU, SCHED_FIFO 70)
    /// records every command and feedback frame of each block with their
    /// send times; blocks with a failed homing get them in
    /// OUT/soak-evidence/PREFIX.frames.csv.
    #[arg(long)]
    pub spy: bool,
    /// Print the config of a machine (with this run's settings) and exit.
    #[arg(long, value_enum)]
    pub print_config: Option<Which>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn defaults() {
        Opts::command().debug_assert();
        let o = Opts::try_parse_from(["soak", "--cpu", "0"]).unwrap();
        assert_eq!((o.homings, o.block, o.runs64), (500, 50, 20));
        assert_eq!((o.via, o.stress_share, o.timeout), (Via::Daemon, 0.5, 60.0));
        assert!(!o.stress64 && !o.trace && !o.spy && o.print_config.is_none());
    }
}
