//! Command line, parsed with clap: every value checked by the same rules as
//! the config file; a mistake is answered with the usage and exit code 2.

use clap::{Parser, Subcommand, ValueEnum};
use motion_config::args::{cpu, interface, io, runtime_dir, service_prefix};
use std::path::PathBuf;

/// Drive backends `--backend` accepts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BackendKind {
    /// One simulated plant per axis of the config (switch, markers, hard
    /// stops, torque).
    Sim,
    /// CiA 402 drives on an EtherCAT bus (ethercrab on a real-time bus
    /// thread, bus cycle = the supervisor's cycle): `--interface` or the
    /// [[io]] section's `interface`.
    Ethercat,
}

impl BackendKind {
    /// The backend an I/O process of the config asks for.
    pub fn of(b: motion_config::IoBackend) -> BackendKind {
        match b {
            motion_config::IoBackend::Sim => BackendKind::Sim,
            motion_config::IoBackend::Ethercat => BackendKind::Ethercat,
        }
    }
}

/// The drive-I/O process of motion-supervisor: takes one command frame per
/// cycle over iceoryx2, applies it to the drives and answers with a feedback
/// frame. It joins the supervisor through its session file (same user),
/// follows it across restarts, and stops every axis when commands stop.
#[derive(Clone, Debug, Parser)]
#[command(
    name = "motion-io",
    version,
    after_help = "Exit codes: 0 after SIGINT/SIGTERM or when the supervisor is gone \
                  (--exit-with-supervisor); 1 on an IPC failure or no supervisor within 10 s \
                  (--exit-with-supervisor); 2 on a command-line or config mistake."
)]
pub struct Options {
    /// Machine configuration (TOML, the supervisor's); default: the built-in
    /// demo machine (deploy/demo.toml).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Drive backend; default: the I/O process's `backend` in the config
    /// (`sim` without [[io]] sections).
    #[arg(long, value_enum)]
    pub backend: Option<BackendKind>,
    /// EtherCAT: the network interface of the bus; overrides the [[io]]
    /// section's `interface`.
    #[arg(long, value_name = "IF", value_parser = interface)]
    pub interface: Option<String>,
    /// Attach as this I/O process ([[io]] name) and serve only its axes;
    /// default: the config's only I/O process.
    #[arg(long = "io", value_name = "NAME", value_parser = io)]
    pub io: Option<String>,
    /// iceoryx2 service prefix; overrides [supervisor] service_prefix.
    #[arg(long, value_name = "P", value_parser = service_prefix)]
    pub service_prefix: Option<String>,
    /// The supervisor's runtime directory (its session file); overrides
    /// [supervisor] runtime_dir.
    #[arg(long, value_name = "DIR", value_parser = runtime_dir)]
    pub runtime_dir: Option<PathBuf>,
    /// Exit once the supervisor is gone (after the watchdog stopped every
    /// axis) instead of waiting for a new one; set by the supervisor when it
    /// spawns motion-io.
    #[arg(long)]
    pub exit_with_supervisor: bool,
    /// Busy-poll for commands instead of sleeping on the wake-up event
    /// (lowest latency; burns one CPU, use with --cpu).
    #[arg(long)]
    pub spin: bool,
    /// Pin this process to CPU N (EtherCAT: also its bus thread).
    #[arg(long, value_name = "N", value_parser = cpu)]
    pub cpu: Option<usize>,
    /// Run SCHED_FIFO at priority P; default SCHED_OTHER (EtherCAT: the bus
    /// thread runs at P, default 70).
    #[arg(long, value_name = "P", value_parser = clap::value_parser!(i32).range(1..=99))]
    pub priority: Option<i32>,
    /// Print only errors and watchdog messages.
    #[arg(long)]
    pub quiet: bool,
    #[command(subcommand)]
    pub command: Option<Sub>,
}

/// What `motion-io` does besides serving the supervisor.
#[derive(Clone, Debug, Subcommand)]
pub enum Sub {
    /// List every SubDevice on an EtherCAT bus — position, name, identity,
    /// DC, the CiA 402 objects it has, touch probe, homing methods (0x60E3),
    /// the PDO mapping in force — and which homing sequences each can serve
    /// (controller-side and drive-side), then a config skeleton of the bus.
    /// It only reads (PRE-OP, then INIT) and needs CAP_NET_RAW; no
    /// supervisor and no config are involved.
    Scan {
        /// The network interface of the bus.
        #[arg(long, value_name = "IF", value_parser = interface)]
        interface: String,
        /// One JSON object on stdout (`{"interface", "subdevices": [...],
        /// "config"}`; on failure `{"errors": [...]}`).
        #[arg(long)]
        json: bool,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Result<Options, clap::Error> {
        Options::try_parse_from(std::iter::once("motion-io").chain(s.split_whitespace()))
    }

    #[test]
    fn flags_and_values() {
        let o = p("--config=m.toml --io bus0 --spin --priority 70").unwrap();
        assert_eq!(o.io.as_deref(), Some("bus0"));
        assert!(o.spin && o.priority == Some(70));
        assert!(p("--backend ethercab").is_err());
        let o = p("--backend ethercat --interface veth0").unwrap();
        assert_eq!(o.backend, Some(BackendKind::Ethercat));
        assert_eq!(o.interface.as_deref(), Some("veth0"));
        assert_eq!(p("").unwrap().backend, None, "the config decides");
        assert!(p("--interface a/b").is_err());
        assert!(p("--interface 0123456789abcdef").is_err());
        assert!(p("--priority 0").is_err());
        assert!(p("--cpu 99").is_err());
        assert!(p("--service-prefix a/b").is_err());
        assert!(p("--config").is_err());
        assert!(p("--io").is_err());
        let o = p("scan --interface eth1 --json").unwrap();
        assert!(
            matches!(o.command, Some(Sub::Scan { ref interface, json: true }) if interface == "eth1")
        );
        assert!(p("scan").is_err(), "the interface is required");
        assert!(p("scan --interface a/b").is_err());
    }

    /// Fuzzed: any argument vector is parsed or refused, never a
    /// panic (`motion_config::cli_fuzz`).
    #[test]
    fn any_argument_vector_is_parsed_or_refused_without_panic() {
        motion_config::cli_fuzz::any_argument_vector_is_parsed_or_refused::<Options>("motion-io");
    }
}
