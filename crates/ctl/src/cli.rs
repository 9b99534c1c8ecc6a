//! `motionctl`'s command line (interface.md), parsed with clap.

use clap::{Args, Parser, Subcommand};
use motion_config::args::{axis, runtime_dir, seconds, service_prefix};
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "motionctl",
    version,
    about = "The operator's tool for a running motion-supervisor: home, stop, unhome, status, \
             stats, trace.",
    after_help = "The supervisor is found by its service prefix: --service-prefix, else the \
                  config's [supervisor] service_prefix (--config), else \"motion\".\n\n\
                  Exit codes:\n  0  done (home: every named axis homed with PC set)\n  \
                  1  refused, or homing did not succeed\n  2  bad argument or config\n  \
                  3  no supervisor running under the prefix (or it stopped answering)\n  \
                  130/143  interrupted by SIGINT/SIGTERM (home: the axes were stopped)"
)]
pub struct Cli {
    #[command(flatten)]
    pub target: Target,
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Clone, Args)]
pub struct Target {
    /// The machine configuration (its service prefix and runtime directory).
    #[arg(long, global = true, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// The supervisor's service prefix.
    #[arg(long, global = true, value_name = "P", value_parser = service_prefix)]
    pub service_prefix: Option<String>,
    /// The supervisor's runtime directory (its session file).
    #[arg(long, global = true, value_name = "DIR", value_parser = runtime_dir)]
    pub runtime_dir: Option<PathBuf>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Every axis and I/O process: phase, bits, positions, inputs.
    Status(StatusArgs),
    /// Home the named axes (all: every axis, in home order) and follow them.
    Home(HomeArgs),
    /// Stop the named axes (all: every axis).
    Stop(AxesArgs),
    /// Clear HomedStatus of the named axes (all: every axis).
    Unhome(AxesArgs),
    /// Latency statistics since start (or since the last reset).
    Stats(StatsArgs),
    /// Record every cycle of the next homing of AXIS: CSV, and a plot of
    /// velocity against position with the events marked.
    Trace(TraceArgs),
}

#[derive(Debug, Args)]
pub struct StatusArgs {
    #[arg(long)]
    pub json: bool,
    /// Keep showing it (10 times a second) until interrupted.
    #[arg(long)]
    pub watch: bool,
}

#[derive(Debug, Args)]
pub struct HomeArgs {
    /// Axes to home; none: every axis, in home order.
    #[arg(value_name = "AXIS", value_parser = axis)]
    pub axes: Vec<String>,
    #[arg(long)]
    pub json: bool,
    /// Return once the request is accepted, without following the homing.
    #[arg(long)]
    pub no_wait: bool,
    /// Stop whatever still homes after S seconds.
    #[arg(long, value_name = "S", value_parser = seconds)]
    pub timeout: Option<f64>,
    /// Start every named axis at once instead of in home order.
    #[arg(long)]
    pub parallel: bool,
}

#[derive(Debug, Args)]
pub struct AxesArgs {
    /// Axes; none: every axis.
    #[arg(value_name = "AXIS", value_parser = axis)]
    pub axes: Vec<String>,
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct StatsArgs {
    #[arg(long)]
    pub json: bool,
    /// Start the "since reset" statistics again (after showing them).
    #[arg(long)]
    pub reset: bool,
    /// Show the statistics since the last reset instead of since start.
    #[arg(long)]
    pub since_reset: bool,
    /// Also write the HdrHistogram interval log of the same span to FILE.
    #[arg(long, value_name = "FILE")]
    pub hlog: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct TraceArgs {
    #[arg(value_name = "AXIS", value_parser = axis)]
    pub axis: String,
    /// Where the CSV goes.
    #[arg(long, value_name = "FILE.csv")]
    pub out: PathBuf,
    /// Also draw velocity against position (SVG).
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Start the homing of AXIS right after arming the trace (else wait for
    /// someone else to start it).
    #[arg(long)]
    pub home: bool,
    /// Give up after S seconds.
    #[arg(long, value_name = "S", default_value = "600", value_parser = seconds)]
    pub timeout: f64,
    #[arg(long)]
    pub json: bool,
}

impl Command {
    pub fn json(&self) -> bool {
        match self {
            Command::Status(a) => a.json,
            Command::Home(a) => a.json,
            Command::Stop(a) | Command::Unhome(a) => a.json,
            Command::Stats(a) => a.json,
            Command::Trace(a) => a.json,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 8, fuzzed: any argument vector is parsed or refused, never a
    /// panic (`motion_config::cli_fuzz`).
    #[test]
    fn any_argument_vector_is_parsed_or_refused_without_panic() {
        motion_config::cli_fuzz::any_argument_vector_is_parsed_or_refused::<Cli>("motionctl");
    }
}
