//! The flags the benches share, written once as clap argument groups that
//! each bench's command line flattens in. Values are checked as they are
//! parsed (the CPU with `motion_config::args`, as the supervisor checks its
//! own), so a mistake is a usage error (exit 2) before anything starts.

use crate::machine::Supervisor;
use clap::Args;
use std::path::{Path, PathBuf};

/// `--period-us`, `--cpu`, `--priority`: the cycle a bench runs.
#[derive(Clone, Debug, Args)]
pub struct Cycle {
    /// Cycle period, µs.
    #[arg(long, value_name = "N", default_value_t = 1000)]
    pub period_us: u32,
    /// CPU of the real-time thread (the cycle, and motion-io by default).
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = motion_config::args::cpu)]
    pub cpu: usize,
    /// SCHED_FIFO priority of the real-time thread.
    #[arg(long, value_name = "P", default_value_t = 80, allow_negative_numbers = true,
          value_parser = clap::value_parser!(i32).range(1..=99))]
    pub priority: i32,
}

impl Cycle {
    /// Another CPU than the cycle's: for stress-ng, the spy, the peers.
    pub fn other_cpu(&self) -> usize {
        usize::from(self.cpu == 0)
    }

    /// The `[supervisor]` section of a run of this cycle under `prefix`.
    pub fn supervisor(&self, prefix: &str) -> Supervisor {
        Supervisor {
            cycle_us: self.period_us,
            cpu: self.cpu,
            priority: self.priority,
            service_prefix: prefix.to_string(),
        }
    }
}

/// `--out`, `--supervisor`: where the results go, which binaries run.
#[derive(Clone, Debug, Args)]
pub struct Files {
    /// Output directory (default: bench/out of the source tree; for cpcost
    /// bench/out/cpcost).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// motion-supervisor binary (default: next to this binary; motion-io and
    /// motionctl next to it; build them with `cargo build --release
    /// --workspace --bins`).
    #[arg(long, value_name = "PATH")]
    pub supervisor: Option<PathBuf>,
}

impl Files {
    /// `--out`, else `bench/out/SUB` of the source tree, wherever the bench
    /// is started from.
    pub fn out(&self, sub: &str) -> PathBuf {
        let default = || Path::new(env!("CARGO_MANIFEST_DIR")).join("out").join(sub);
        self.out.clone().unwrap_or_else(default)
    }
}

/// `--duration`, `--slice`: the variants of a slice bench run in
/// alternating slices (so that all meet the same host noise) until each has
/// run its duration. `SLICE_MS` is the default slice, `MIN_MS` the shortest.
#[derive(Clone, Debug, Args)]
pub struct Slicing<const SLICE_MS: u32, const MIN_MS: u32> {
    /// Seconds each variant runs.
    #[arg(long, value_name = "S", default_value_t = 60.0, allow_negative_numbers = true,
          value_parser = motion_config::args::seconds)]
    pub duration: f64,
    #[arg(long, value_name = "S", default_value_t = f64::from(SLICE_MS) / 1e3,
          help = format!("Seconds per slice (at least {}; the last one shorter)", f64::from(MIN_MS) / 1e3),
          allow_negative_numbers = true, value_parser = seconds_at_least(f64::from(MIN_MS) / 1e3))]
    pub slice: f64,
}

impl<const SLICE_MS: u32, const MIN_MS: u32> Slicing<SLICE_MS, MIN_MS> {
    /// Slices of `--slice` s that make up `--duration`.
    pub fn count(&self) -> usize {
        (self.duration / self.slice - 1e-9).ceil().max(1.0) as usize
    }

    /// Seconds of slice `i`.
    pub fn len(&self, i: usize) -> f64 {
        (self.duration - i as f64 * self.slice).min(self.slice)
    }
}

/// A number of seconds of at least `min`.
fn seconds_at_least(min: f64) -> impl Fn(&str) -> Result<f64, String> + Clone {
    move |s| match s.parse::<f64>() {
        Ok(v) if v >= min && v.is_finite() => Ok(v),
        _ => Err(format!("must be a number of seconds, at least {min}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Debug, Parser)]
    struct T {
        #[command(flatten)]
        c: Cycle,
        #[command(flatten)]
        f: Files,
        #[command(flatten)]
        s: Slicing<5000, 500>,
    }

    fn parse(args: &str) -> Result<T, clap::Error> {
        T::try_parse_from(std::iter::once("t").chain(args.split_whitespace()))
    }

    #[test]
    fn defaults_values_and_mistakes() {
        let t = parse("--cpu 0").unwrap();
        let c = &t.c;
        assert_eq!(
            (c.period_us, c.cpu, c.priority, c.other_cpu()),
            (1000, 0, 80, 1)
        );
        assert!(t.f.out("x").ends_with("bench/out/x") && t.f.supervisor.is_none());
        assert_eq!((t.s.duration, t.s.slice), (60.0, 5.0));
        let t = parse("--cpu=0 --period-us=250 --priority 90 --out /o").unwrap();
        assert_eq!(
            (t.c.period_us, t.c.priority, t.f.out("x")),
            (250, 90, "/o".into())
        );
        assert_eq!(t.c.supervisor("p").service_prefix, "p");
        for args in [
            "--priority 0",
            "--priority 100",
            "--period-us x",
            "--cpu 4096",
        ] {
            let (e, flag) = (parse(args).unwrap_err(), args.split(' ').next().unwrap());
            assert_eq!(e.kind(), clap::error::ErrorKind::ValueValidation, "{args}");
            assert!(e.to_string().contains(flag), "{args}: {e}");
        }
        assert!(parse("--cpu 0 --cpu 0").is_err() && parse("stray").is_err());
        let s = parse("--cpu=0 --duration 12 --slice=5").unwrap().s;
        assert_eq!((s.count(), s.len(0), s.len(2)), (3, 5.0, 2.0));
        for bad in ["--slice 0.4", "--duration 0", "--duration -1"] {
            assert!(parse(&format!("{bad} --cpu=0")).is_err(), "{bad}");
        }
    }
}
