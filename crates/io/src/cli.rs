//! Command line, parsed with clap: every value checked by the same rules as
//! the config file; a mistake is answered with the usage and exit code 2.

use clap::{Parser, ValueEnum};
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
    }

    /// Issue 8, fuzzed: any argument vector (the real subcommands and flags
    /// in any order and combination, hostile values, arbitrary and
    /// non-UTF-8 strings) is parsed or refused, never a panic (clap's
    /// debug-build checks of the definition included).
    #[test]
    fn any_argument_vector_is_parsed_or_refused_without_panic() {
        use clap::CommandFactory;
        use proptest::prelude::*;
        use proptest::test_runner::{Config, TestRunner};
        use std::ffi::OsString;
        use std::os::unix::ffi::OsStringExt;

        fn words(c: &clap::Command, out: &mut Vec<String>) {
            for a in c.get_arguments() {
                out.extend(a.get_long().map(|l| format!("--{l}")));
                out.extend(a.get_short().map(|s| format!("-{s}")));
            }
            for s in c.get_subcommands() {
                out.push(s.get_name().to_string());
                words(s, out);
            }
        }
        #[rustfmt::skip]
        const VALUES: &[&str] = &[
            "", "-", "--", "=", "0", "-1", "1", "99", "1e308", "-1e308", "nan", "inf", "-inf",
            "18446744073709551616", "0x10", "../../etc/passwd", "/dev/zero", "/tmp", "a/b",
            "\u{1b}[31m", "X", "all", "--help", "--version", "-h", "\u{0}",
        ];
        let mut known = Vec::new();
        words(&Options::command(), &mut known);
        assert!(known.len() > 3, "{known:?}");
        // Mostly behind a real subcommand, to get past the first word.
        let mut first: Vec<String> = Options::command()
            .get_subcommands()
            .map(|s| s.get_name().to_string())
            .collect();
        first.push(String::new());
        let token = prop_oneof![
            4 => prop::sample::select(known.clone()).prop_map(OsString::from),
            2 => prop::sample::select(VALUES).prop_map(OsString::from),
            1 => (prop::sample::select(known), prop::sample::select(VALUES))
                .prop_map(|(k, v)| OsString::from(format!("{k}={v}"))),
            1 => ".{0,16}".prop_map(OsString::from),
            1 => prop::collection::vec(any::<u8>(), 0..8).prop_map(OsString::from_vec),
        ];
        let mut runner = TestRunner::new(Config {
            cases: 512,
            failure_persistence: None,
            ..Config::default()
        });
        runner
            .run(
                &(
                    prop::sample::select(first),
                    prop::collection::vec(token, 0..10),
                ),
                |(sub, args)| {
                    let sub = (!sub.is_empty()).then(|| OsString::from(sub));
                    let argv = std::iter::once(OsString::from("motion-io"))
                        .chain(sub)
                        .chain(args);
                    match Options::try_parse_from(argv) {
                        Ok(c) => drop(format!("{c:?}")),
                        Err(e) => drop(e.render().to_string()),
                    }
                    Ok(())
                },
            )
            .unwrap();
    }
}
