//! One slice of one variant: `motion-supervisor run` on the demo machine
//! (with `--no-control-plane` for (a)), the clients attached for (b) and (c)
//! once the daemon answers, then what it measured (`motion_bench::slice`).

use crate::cli::Opts;
use crate::clients::{self, Clients};
use crate::variant::Variant;
use motion_bench::drive::{self, Binaries};
use motion_bench::machine;
use motion_bench::proc;
use motion_bench::slice::{self, Slice};
use std::path::Path;
use std::time::{Duration, Instant};

/// A slice that ran, with its clients.
pub struct Done {
    pub slice: Slice,
    /// Seconds from the start to the clients attached (b, c).
    pub attach_s: Option<f64>,
    pub clients: Clients,
}

/// How a slice went.
pub enum Outcome {
    Done(Box<Done>),
    /// The supervisor (or attaching to it) failed: the reason.
    Failed(String),
    Interrupted,
}

/// Runs slice `i` of `v` for `len` s. Returns the outcome, the
/// supervisor's warnings and what its prefix left in /dev/shm (cleaned).
pub fn run(
    (o, b, tmp): (&Opts, &Binaries, &Path),
    v: Variant,
    i: usize,
    len: f64,
) -> Result<(Outcome, Vec<String>, Vec<String>), String> {
    let prefix = format!("mbc{}{}{i}", std::process::id(), v.letter());
    let (toml, _) = machine::demo_with(&o.cycle.supervisor(&prefix))?;
    let tag = format!("{}{i}", v.letter());
    let extra: &[&str] = if v.serves() {
        &[]
    } else {
        &["--no-control-plane"]
    };
    let t0 = Instant::now();
    // its --duration starts after its own start-up: it cannot end before this
    let cut = t0 + Duration::from_secs_f64(len);
    let limit = Duration::from_secs_f64(len + 60.0);
    let (mut sup, hlog) = slice::start(b, tmp, (&tag, &toml, &prefix), len, extra)?;
    let (mut clients, mut attach_s, mut attach_failed) = (Clients::default(), None, None);
    if v.serves() {
        let wait = Duration::from_secs_f64(len.min(10.0));
        match drive::wait_until_ready(&b.motionctl, &prefix, &mut sup, wait) {
            Ok(()) => {
                let plan = clients::Plan {
                    status_every: Duration::from_millis(o.status_every_ms),
                    stats_every: Duration::from_millis(o.stats_every_ms),
                    homing: v == Variant::Homing,
                };
                let mut a = clients::attach(&b.motionctl, &prefix, &plan, cut)?;
                attach_s = Some(t0.elapsed().as_secs_f64());
                while sup.running() && !proc::stop_requested() && t0.elapsed() < limit {
                    a.poll();
                    std::thread::sleep(Duration::from_millis(5));
                }
                clients = a.detach();
            }
            Err(e) => attach_failed = Some(format!("clients not attached: {e}")),
        }
    }
    let ended = sup.wait(limit.saturating_sub(t0.elapsed()), Duration::from_secs(10));
    let (found, remaining) = drive::clean_leftovers(&prefix);
    let mut warnings = Vec::new();
    if !remaining.is_empty() {
        let left = remaining.join(", ");
        warnings.push(format!("{prefix}: NOT cleaned from /dev/shm: {left}"));
    }
    let outcome = if ended.interrupted || proc::stop_requested() {
        Outcome::Interrupted
    } else if let Some(e) = attach_failed {
        Outcome::Failed(e)
    } else {
        match slice::read(&ended, &hlog, Duration::ZERO, len) {
            Ok((slice, w)) => {
                warnings.extend(w);
                Outcome::Done(Box::new(Done {
                    slice,
                    attach_s,
                    clients,
                }))
            }
            Err(e) => Outcome::Failed(e),
        }
    };
    Ok((outcome, warnings, found))
}
