//! Command line: `run`, `home`, `check` (interface.md), hand-parsed.

use std::path::PathBuf;

pub const USAGE: &str = "\
usage:
  motion-supervisor run   [--config FILE] [--duration S] [--json] [--hlog FILE]
                          [--service-prefix P] [--io-arg ARG]...
  motion-supervisor home  [--config FILE] [--axis NAME]... [--json] [--parallel]
                          [--timeout S] [--service-prefix P]
  motion-supervisor check [--config FILE]

Without --config the built-in default machine (deploy/demo.toml) is used.
  run     the daemon: the real-time cycle until SIGINT/SIGTERM (or --duration),
          then every axis stopped; prints the latency summary
  home    start, spawn the I/O process, home the axes (all by default, one after
          the other in config order; --parallel: all at once), print one row per
          axis and the latency summary; exit 0 only if every axis set PC
  check   validate the config and the real-time environment
";

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Common {
    pub config: Option<PathBuf>,
    pub service_prefix: Option<String>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Cli {
    Run {
        common: Common,
        duration_s: Option<f64>,
        json: bool,
        hlog: Option<PathBuf>,
        io_args: Vec<String>,
    },
    Home {
        common: Common,
        axes: Vec<String>,
        json: bool,
        parallel: bool,
        timeout_s: f64,
    },
    Check {
        common: Common,
    },
    Help,
}

pub fn parse(args: &[String]) -> Result<Cli, String> {
    let Some(cmd) = args.first() else {
        return Err("missing command".into());
    };
    let mut common = Common::default();
    let mut duration_s = None;
    let mut json = false;
    let mut hlog = None;
    let mut io_args = Vec::new();
    let mut axes = Vec::new();
    let mut parallel = false;
    let mut timeout_s = 600.0;
    let mut it = args[1..].iter();
    while let Some(a) = it.next() {
        let mut value = |name: &str| {
            it.next()
                .cloned()
                .ok_or_else(|| format!("{name} needs a value"))
        };
        let number = |name: &str, v: String| {
            v.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite() && *x > 0.0)
                .ok_or_else(|| format!("{name}: '{v}' is not a positive number"))
        };
        match a.as_str() {
            "--config" => common.config = Some(PathBuf::from(value("--config")?)),
            "--service-prefix" => common.service_prefix = Some(value("--service-prefix")?),
            "--json" if cmd != "check" => json = true,
            "--duration" if cmd == "run" => {
                duration_s = Some(number("--duration", value("--duration")?)?)
            }
            "--hlog" if cmd == "run" => hlog = Some(PathBuf::from(value("--hlog")?)),
            "--io-arg" if cmd == "run" => io_args.push(value("--io-arg")?),
            "--axis" if cmd == "home" => axes.push(value("--axis")?),
            "--parallel" if cmd == "home" => parallel = true,
            "--timeout" if cmd == "home" => timeout_s = number("--timeout", value("--timeout")?)?,
            "-h" | "--help" => return Ok(Cli::Help),
            other => return Err(format!("unknown argument '{other}' for '{cmd}'")),
        }
    }
    match cmd.as_str() {
        "run" => Ok(Cli::Run {
            common,
            duration_s,
            json,
            hlog,
            io_args,
        }),
        "home" => Ok(Cli::Home {
            common,
            axes,
            json,
            parallel,
            timeout_s,
        }),
        "check" => Ok(Cli::Check { common }),
        "-h" | "--help" | "help" => Ok(Cli::Help),
        other => Err(format!("unknown command '{other}'")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Result<Cli, String> {
        parse(&s.split_whitespace().map(String::from).collect::<Vec<_>>())
    }

    #[test]
    fn commands() {
        assert_eq!(
            p("home --axis X --axis Z --json").unwrap(),
            Cli::Home {
                common: Common::default(),
                axes: vec!["X".into(), "Z".into()],
                json: true,
                parallel: false,
                timeout_s: 600.0
            }
        );
        assert!(matches!(
            p("run --duration 60 --config m.toml").unwrap(),
            Cli::Run { duration_s: Some(d), .. } if d == 60.0
        ));
        assert!(p("check --json").is_err());
        assert!(p("run --duration -1").is_err());
        assert!(p("fly").is_err());
        assert!(p("home --axis").is_err());
    }
}
