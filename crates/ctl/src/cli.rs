//! `motionctl`'s command line (fixed names; docs/commands.md), parsed with clap.

use crate::spec_args::SpecArgs;
use clap::{Args, Parser, Subcommand};
use motion_config::args::{axis, runtime_dir, seconds, service_prefix};
use motion_control::{JogSpec, MoveSpec};
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "motionctl",
    version,
    about = "The operator's tool for a running motion-supervisor: home, stop, unhome, status, \
             stats, trace; enable, disable, reset, jog, move, stream.",
    after_help = "The supervisor is found by its service prefix: --service-prefix, else the \
                  config's [supervisor] service_prefix (--config), else \"motion\".\n\n\
                  Exit codes:\n  0  done (home: every named axis homed with PC set; move: \
                  every axis at its target; jog, stream: ended without an axis fault)\n  \
                  1  refused, or the operation did not succeed\n  2  bad argument or config\n  \
                  3  no supervisor running under the prefix (or it stopped answering)\n  \
                  130/143  interrupted by SIGINT/SIGTERM (the axes were stopped)"
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
    /// MSO: enable the drives of the named axes (all: every axis), holding
    /// position.
    Enable(AxesArgs),
    /// MSF: disable the drives of the named axes (all: every axis); a
    /// moving axis is stopped first.
    Disable(AxesArgs),
    /// MAFR: clear the axis faults of the named axes (all: every axis) and
    /// ask their drives for a fault reset. Never enables, never moves.
    Reset(AxesArgs),
    /// MAJ, hold to run: jog AXIS (or a gantry) while this command runs;
    /// Ctrl-C/SIGTERM, --for, `stop`, a limit or a fault end it.
    Jog(JogArgs),
    /// MAM: a trapezoidal move of AXIS (or a gantry) to P or by D; waits
    /// like `home` (exit 0 only when it ended at the target).
    Move(MoveArgs),
    /// Play a CSV file of timed setpoints ("t,p1[,p2...]": s, units; one
    /// column per AXIS, in order) through the supervised setpoint stream.
    ///
    /// Rows may be far apart: a setpoint goes out at least every 5 ms,
    /// filled in on the line between rows; the last row is held until the
    /// axes are on it, then they are released. An axis stops with ERR 1019 /
    /// EXERR 5 when no setpoint has arrived for its stream_timeout_ms
    /// (default 50; keep it at 10 or more for this command), however far
    /// ahead the last one lay. Each axis follows the rows within its
    /// max_speed and stream_acceleration on the supervisor's own clock; a
    /// file it cannot follow within them stops it (1019 / 3 or 4).
    Stream(StreamArgs),
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
pub struct JogArgs {
    /// The axis or gantry to jog.
    #[arg(value_name = "AXIS", value_parser = axis)]
    pub axis: String,
    /// The jog's parameters (the engine's `JogSpec`): --speed V [--accel
    /// A] [--decel D].
    #[command(flatten)]
    pub jog: SpecArgs<JogSpec>,
    /// Stop after S seconds.
    #[arg(long = "for", value_name = "S", value_parser = seconds)]
    pub for_s: Option<f64>,
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct MoveArgs {
    /// The axis or gantry to move.
    #[arg(value_name = "AXIS", value_parser = axis)]
    pub axis: String,
    /// The move's parameters (the engine's `MoveSpec`): (--to P | --by D)
    /// [--speed V] [--accel A] [--decel D] and its switches.
    #[command(flatten)]
    pub spec: SpecArgs<MoveSpec>,
    /// Return once the move is accepted, without following it.
    #[arg(long)]
    pub no_wait: bool,
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct StreamArgs {
    /// The axes (or gantries) of the file's columns, in order.
    #[arg(value_name = "AXIS", required = true, value_parser = axis)]
    pub axes: Vec<String>,
    /// Rows "t,p1[,p2...]": time in s (increasing), one position per AXIS.
    #[arg(long, value_name = "FILE")]
    pub csv: PathBuf,
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
            Command::Stop(a)
            | Command::Unhome(a)
            | Command::Enable(a)
            | Command::Disable(a)
            | Command::Reset(a) => a.json,
            Command::Jog(a) => a.json,
            Command::Move(a) => a.json,
            Command::Stream(a) => a.json,
            Command::Stats(a) => a.json,
            Command::Trace(a) => a.json,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fuzzed: any argument vector is parsed or refused, never a
    /// panic (`motion_config::cli_fuzz`).
    #[test]
    fn any_argument_vector_is_parsed_or_refused_without_panic() {
        motion_config::cli_fuzz::any_argument_vector_is_parsed_or_refused::<Cli>("motionctl");
    }
}
