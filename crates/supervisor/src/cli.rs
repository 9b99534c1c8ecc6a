//! The command line (fixed names; docs/commands.md): `run`, `home`, `check`, parsed with
//! clap. Every value is checked by the same rules as the config file.

use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "motion-supervisor",
    version,
    about = "Real-time CIP Motion homing supervisor: a pinned SCHED_FIFO cycle homes every axis \
             and exchanges zero-copy frames with drive-I/O processes over iceoryx2.",
    after_help = "Without --config the built-in default machine (deploy/demo.toml) is used.\n\
                  Exit codes: 0 success; 1 homing did not succeed / a run-time failure; \
                  2 bad configuration or argument; 128+N ended by signal N."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// The daemon: the real-time cycle with its control and status services
    /// until SIGINT/SIGTERM (or --duration); then every axis is stopped and
    /// the latency summary printed.
    Run(RunArgs),
    /// Commissioning run: start, spawn the I/O processes, home the axes (all
    /// by default, in home order), print one row per axis and the latency
    /// summary; exit 0 only if every axis ended homed with PC set.
    Home(HomeArgs),
    /// Validate the config and the real-time environment.
    Check(CheckArgs),
}

#[derive(Debug, Clone, Args)]
pub struct Common {
    /// Machine configuration (TOML).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// iceoryx2 service prefix; overrides [supervisor] service_prefix.
    #[arg(long, value_name = "P", value_parser = prefix)]
    pub service_prefix: Option<String>,
    /// Where the session file and iceoryx2's files live; overrides
    /// [supervisor] runtime_dir (default /run/motion for root).
    #[arg(long, value_name = "DIR", value_parser = runtime_dir)]
    pub runtime_dir: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct RunArgs {
    #[command(flatten)]
    pub common: Common,
    /// Stop after S seconds.
    #[arg(long, value_name = "S", value_parser = seconds)]
    pub duration: Option<f64>,
    /// Print the final report as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Write HdrHistogram interval logs of the three latencies.
    #[arg(long, value_name = "FILE")]
    pub hlog: Option<PathBuf>,
    /// Extra argument for every spawned motion-io (repeatable).
    #[arg(long = "io-arg", value_name = "ARG", allow_hyphen_values = true)]
    pub io_args: Vec<String>,
    /// Benchmarks only: run without the control and status services, to
    /// measure what they cost the cycle (bench/README.md).
    #[arg(long, hide = true)]
    pub no_control_plane: bool,
}

#[derive(Debug, Args)]
pub struct HomeArgs {
    #[command(flatten)]
    pub common: Common,
    /// Axis to home (repeatable); default: every axis, in home order.
    #[arg(long = "axis", value_name = "NAME", value_parser = axis_name)]
    pub axes: Vec<String>,
    /// Print the report as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Start every named axis at once instead of in home order.
    #[arg(long)]
    pub parallel: bool,
    /// Stop whatever still homes after S seconds.
    #[arg(long, value_name = "S", default_value = "600", value_parser = seconds)]
    pub timeout: f64,
}

#[derive(Debug, Args)]
pub struct CheckArgs {
    #[command(flatten)]
    pub common: Common,
    /// Print the problems as one JSON object.
    #[arg(long)]
    pub json: bool,
}

use motion_config::args::{axis as axis_name, runtime_dir, seconds, service_prefix as prefix};

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Result<Cli, clap::Error> {
        Cli::try_parse_from(std::iter::once("motion-supervisor").chain(s.split_whitespace()))
    }

    #[test]
    fn commands() {
        let Command::Home(h) = p("home --axis X --axis=Z --json").unwrap().command else {
            panic!()
        };
        assert_eq!(h.axes, ["X", "Z"]);
        assert!(h.json && !h.parallel);
        assert_eq!(h.timeout, 600.0);
        let Command::Run(r) = p("run --duration 60 --config m.toml").unwrap().command else {
            panic!()
        };
        assert_eq!(r.duration, Some(60.0));
        assert!(p("check --json").is_ok());
        assert!(p("run --duration -1").is_err());
        assert!(p("fly").is_err());
        assert!(p("home --axis").is_err());
        // A flag is never taken as a file name.
        assert!(p("home --config --json").is_err());
    }

    #[test]
    fn hostile_values_are_refused() {
        for bad in [
            "home --timeout 1e308",
            "home --timeout 1e19",
            "home --timeout nan",
            "run --service-prefix ../../tmp/x",
            "run --service-prefix a/b",
            "home --axis \u{1b}[31m",
            "run --runtime-dir relative",
        ] {
            assert!(p(bad).is_err(), "{bad}");
        }
        assert!(p("run --service-prefix a_b").is_ok());
    }

    /// Fuzzed: any argument vector is parsed or refused, never a
    /// panic (`motion_config::cli_fuzz`).
    #[test]
    fn any_argument_vector_is_parsed_or_refused_without_panic() {
        motion_config::cli_fuzz::any_argument_vector_is_parsed_or_refused::<Cli>(
            "motion-supervisor",
        );
    }
}
