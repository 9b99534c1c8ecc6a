//! Command line: hand-rolled (no argument-parser dependency), every mistake
//! answered with the usage text and exit code 2.

use std::fmt;
use std::path::PathBuf;

/// Usage text printed on a command-line mistake and for `--help`.
pub const USAGE: &str = "\
usage: motion-io [--config FILE] [--backend sim] [--service-prefix P]
                 [--exit-with-supervisor] [--spin] [--cpu N] [--priority P] [--quiet]

The drive-I/O process of motion-supervisor: takes one command frame per cycle
over iceoryx2, applies it to the drives and answers with a feedback frame.

  --config FILE           machine configuration (TOML, the supervisor's);
                          default: the built-in demo machine (deploy/demo.toml)
  --backend NAME          drive backend; only \"sim\" exists (default): one
                          simulated plant per [[axis]] of the config
  --service-prefix P      iceoryx2 service prefix; overrides [supervisor] service_prefix
  --exit-with-supervisor  exit once the supervisor is gone (after the watchdog
                          stopped every axis) instead of waiting for a new one;
                          set by the supervisor when it spawns motion-io
  --spin                  busy-poll for commands instead of sleeping on the
                          wake-up event (lowest latency; burns one CPU, use with --cpu)
  --cpu N                 pin this process to CPU N
  --priority P            run SCHED_FIFO at priority P (1..=99); default SCHED_OTHER
  --quiet                 print only errors and watchdog messages
  -h, --help              this text";

/// Drive backends `--backend` accepts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BackendKind {
    /// One `motion_plant::Plant` per configured axis.
    Sim,
}

impl BackendKind {
    /// All backends, with their command-line spelling.
    pub const ALL: &'static [(&'static str, BackendKind)] = &[("sim", BackendKind::Sim)];
}

/// Parsed command line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Options {
    pub config: Option<PathBuf>,
    pub backend: BackendKind,
    pub service_prefix: Option<String>,
    pub exit_with_supervisor: bool,
    pub spin: bool,
    pub cpu: Option<usize>,
    pub priority: Option<i32>,
    pub quiet: bool,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            config: None,
            backend: BackendKind::Sim,
            service_prefix: None,
            exit_with_supervisor: false,
            spin: false,
            cpu: None,
            priority: None,
            quiet: false,
        }
    }
}

/// What the command line asks for.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Parsed {
    Run(Options),
    Help,
}

/// A command-line mistake, worded for the user (the usage text follows it).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CliError(pub String);

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

fn value<I: Iterator<Item = String>>(flag: &str, it: &mut I) -> Result<String, CliError> {
    match it.next() {
        Some(v) if !v.starts_with("--") => Ok(v),
        _ => Err(CliError(format!("{flag} needs a value"))),
    }
}

fn number<T: std::str::FromStr>(flag: &str, v: &str, what: &str) -> Result<T, CliError> {
    v.parse()
        .map_err(|_| CliError(format!("{flag} {v:?}: expected {what}")))
}

fn once<T>(slot: &mut Option<T>, flag: &str, v: T) -> Result<(), CliError> {
    if slot.is_some() {
        return Err(CliError(format!("{flag} given twice")));
    }
    *slot = Some(v);
    Ok(())
}

/// Parses the arguments after the program name. `--flag=value` and
/// `--flag value` are both accepted.
pub fn parse<I: IntoIterator<Item = String>>(args: I) -> Result<Parsed, CliError> {
    let mut o = Options::default();
    let mut backend = None;
    // split `--flag=value` into two arguments
    let mut split = Vec::new();
    for a in args {
        match a.split_once('=') {
            Some((flag, v)) if flag.starts_with("--") => {
                split.push(flag.to_string());
                split.push(v.to_string());
            }
            _ => split.push(a),
        }
    }
    let mut it = split.into_iter();
    while let Some(arg) = it.next() {
        match arg.as_str() {
            "-h" | "--help" => return Ok(Parsed::Help),
            "--config" => {
                let v = value(&arg, &mut it)?;
                once(&mut o.config, &arg, PathBuf::from(v))?;
            }
            "--backend" => {
                let v = value(&arg, &mut it)?;
                let kind = BackendKind::ALL
                    .iter()
                    .find(|(name, _)| *name == v)
                    .map(|(_, k)| *k)
                    .ok_or_else(|| {
                        let known: Vec<_> = BackendKind::ALL.iter().map(|(n, _)| *n).collect();
                        CliError(format!(
                            "--backend {v:?}: unknown backend (available: {})",
                            known.join(", ")
                        ))
                    })?;
                once(&mut backend, &arg, kind)?;
            }
            "--service-prefix" => {
                let v = value(&arg, &mut it)?;
                if v.is_empty() {
                    return Err(CliError("--service-prefix must not be empty".into()));
                }
                once(&mut o.service_prefix, &arg, v)?;
            }
            "--cpu" => {
                let v = value(&arg, &mut it)?;
                let n = number(&arg, &v, "a CPU number (0, 1, ...)")?;
                once(&mut o.cpu, &arg, n)?;
            }
            "--priority" => {
                let v = value(&arg, &mut it)?;
                let p: i32 = number(&arg, &v, "a SCHED_FIFO priority 1..=99")?;
                if !(1..=99).contains(&p) {
                    return Err(CliError(format!(
                        "--priority {p}: SCHED_FIFO priorities are 1..=99"
                    )));
                }
                once(&mut o.priority, &arg, p)?;
            }
            "--exit-with-supervisor" => o.exit_with_supervisor = true,
            "--spin" => o.spin = true,
            "--quiet" => o.quiet = true,
            other if other.starts_with('-') => {
                return Err(CliError(format!("unknown option {other:?}")))
            }
            other => return Err(CliError(format!("unexpected argument {other:?}"))),
        }
    }
    if let Some(b) = backend {
        o.backend = b;
    }
    Ok(Parsed::Run(o))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(args: &[&str]) -> Result<Parsed, CliError> {
        parse(args.iter().map(|s| s.to_string()))
    }

    fn run(args: &[&str]) -> Options {
        match p(args).unwrap() {
            Parsed::Run(o) => o,
            Parsed::Help => panic!("help"),
        }
    }

    #[test]
    fn defaults() {
        assert_eq!(run(&[]), Options::default());
        assert_eq!(Options::default().backend, BackendKind::Sim);
    }

    #[test]
    fn every_flag() {
        let o = run(&[
            "--config",
            "m.toml",
            "--backend",
            "sim",
            "--service-prefix=cell1",
            "--exit-with-supervisor",
            "--spin",
            "--cpu",
            "1",
            "--priority=70",
            "--quiet",
        ]);
        assert_eq!(
            o,
            Options {
                config: Some(PathBuf::from("m.toml")),
                backend: BackendKind::Sim,
                service_prefix: Some("cell1".into()),
                exit_with_supervisor: true,
                spin: true,
                cpu: Some(1),
                priority: Some(70),
                quiet: true,
            }
        );
        assert_eq!(p(&["--quiet", "-h"]).unwrap(), Parsed::Help);
    }

    #[test]
    fn mistakes() {
        for (args, needle) in [
            (&["--backend", "ethercat"][..], "unknown backend"),
            (&["--config"][..], "needs a value"),
            (&["--config", "--quiet"][..], "needs a value"),
            (&["--cpu", "x"][..], "expected a CPU number"),
            (&["--cpu", "-1"][..], "expected a CPU number"),
            (&["--priority", "0"][..], "1..=99"),
            (&["--priority", "100"][..], "1..=99"),
            (&["--service-prefix="][..], "must not be empty"),
            (&["--frobnicate"][..], "unknown option"),
            (&["extra"][..], "unexpected argument"),
            (&["--cpu", "1", "--cpu", "2"][..], "given twice"),
        ] {
            let e = p(args).unwrap_err();
            assert!(e.0.contains(needle), "{args:?}: {e}");
        }
    }
}
