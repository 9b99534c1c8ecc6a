//! What every homing of the soak shares: the binaries, the temporary
//! directory, the CPU for stress-ng and the spy, unique service prefixes,
//! and the shared memory runs left behind (reported, then cleaned).

use crate::cli::Opts;
use motion_bench::drive::{self, Binaries};
use motion_bench::machine::Supervisor;
use std::path::PathBuf;

/// The soak's state across parts and blocks.
pub struct Ctx {
    pub b: Binaries,
    /// Configs and traces of the runs.
    pub tmp: PathBuf,
    /// Not the cycle's CPU: stress-ng and the spy go there.
    pub other_cpu: usize,
    /// What runs left in /dev/shm (cleaned by the bench).
    pub leftovers: Vec<String>,
    /// ... and what of it could not be cleaned.
    pub not_cleaned: Vec<String>,
    seq: u32,
}

impl Ctx {
    pub fn new(b: Binaries, tmp: PathBuf, other_cpu: usize) -> Self {
        Ctx {
            b,
            tmp,
            other_cpu,
            leftovers: Vec::new(),
            not_cleaned: Vec::new(),
            seq: 0,
        }
    }

    /// A unique service prefix for this bench's next supervisor.
    pub fn prefix(&mut self, tag: &str) -> String {
        self.seq += 1;
        format!("mbs{}{tag}{}", std::process::id(), self.seq)
    }

    /// Reports what `prefix` left behind, then cleans it (see
    /// [`drive::clean_leftovers`]).
    pub fn check_leftovers(&mut self, prefix: &str) {
        let (found, remaining) = drive::clean_leftovers(prefix);
        if !found.is_empty() {
            eprintln!(
                "soak: WARNING: {prefix} left {} ({})",
                found.join(", "),
                if remaining.is_empty() {
                    "cleaned"
                } else {
                    "NOT all cleaned"
                }
            );
            self.leftovers.extend(found);
            self.not_cleaned.extend(remaining);
        }
    }
}

/// The `[supervisor]` section of every run: the soak's period, CPU and
/// priority under `prefix`.
pub fn sup(o: &Opts, prefix: &str) -> Supervisor {
    Supervisor {
        cycle_us: o.period_us,
        cpu: o.cpu,
        priority: o.priority,
        service_prefix: prefix.to_string(),
    }
}
