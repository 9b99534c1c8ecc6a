//! The slices: one `motion-supervisor run` of one variant on the demo
//! machine (with `--no-control-plane` for (a)), the clients attached for
//! (b) and (c) once the daemon answers, then what it measured
//! (`motion_bench::runs`); the variants alternate, odd slices in reverse
//! order (neither variant always follows the other).

use crate::cli::Opts;
use crate::variant::Variant;
use motion_bench::bins::Binaries;
use motion_bench::clients::{self, Clients};
use motion_bench::outcome::Bench;
use motion_bench::slice::Slice;
use motion_bench::table::us;
use motion_bench::{drive, runs};
use motion_bench::{machine, proc};
use std::collections::BTreeSet;
use std::time::{Duration, Instant};

/// A slice that ran, with its clients.
pub struct Done {
    pub variant: Variant,
    pub slice: Slice,
    /// Seconds from the start to the clients attached (b, c).
    pub attach_s: Option<f64>,
    pub clients: Clients,
}

/// What the slices left.
#[derive(Default)]
pub struct Ran {
    pub done: Vec<Done>,
    pub failures: Vec<String>,
    /// The supervisors' warnings (each once).
    pub warnings: BTreeSet<String>,
    /// Runs that left files in /dev/shm (cleaned by the bench), files left.
    pub leftovers: (usize, usize),
    pub interrupted: bool,
}

/// The alternating slices, until a failure or a stop request.
pub fn run(o: &Opts, bins: &Binaries, b: &mut Bench, variants: &[Variant]) -> Result<Ran, String> {
    let (mut r, n) = (Ran::default(), o.slicing.count());
    for i in 0..n {
        let mut order = variants.to_vec();
        if i % 2 == 1 {
            order.reverse();
        }
        for v in order {
            r.interrupted |= proc::stop_requested();
            if r.interrupted || !one(o, (bins, &*b), (v, i, n), &mut r)? {
                return Ok(r);
            }
        }
        b.other_rt.note("during the bench");
    }
    Ok(r)
}

/// Slice `i` of `n` of `v`, into `r`; false: the slices end (interrupted,
/// or the supervisor or attaching to it failed).
fn one(
    o: &Opts,
    (b, bench): (&Binaries, &Bench),
    (v, i, n): (Variant, usize, usize),
    r: &mut Ran,
) -> Result<bool, String> {
    let len = o.slice_len(i);
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
    let (mut sup, hlog) = runs::start(b, &bench.tmp, (&tag, &toml, &prefix), len, extra)?;
    let (mut clients, mut attach_s, mut failed) = (Clients::default(), None, None);
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
            Err(e) => failed = Some(format!("clients not attached: {e}")),
        }
    }
    let ended = sup.wait(limit.saturating_sub(t0.elapsed()), Duration::from_secs(10));
    let (found, remaining) = drive::clean_leftovers(&prefix);
    if !found.is_empty() {
        r.leftovers = (r.leftovers.0 + 1, r.leftovers.1 + found.len());
    }
    if !remaining.is_empty() {
        let left = remaining.join(", ");
        r.warnings
            .insert(format!("{prefix}: NOT cleaned from /dev/shm: {left}"));
    }
    if ended.interrupted || proc::stop_requested() {
        r.interrupted = true;
        return Ok(false);
    }
    let read = match failed {
        Some(e) => Err(e),
        None => runs::read(&ended, &hlog),
    };
    let (m, warnings) = match read {
        Ok(x) => x,
        Err(e) => {
            let (k, label) = (i + 1, v.label());
            r.failures
                .push(format!("slice {k} {label}: motion-supervisor: {e}"));
            return Ok(false);
        }
    };
    r.warnings.extend(warnings);
    let slice = Slice {
        start: Duration::ZERO,
        len,
        m,
    };
    let d = Done {
        variant: v,
        slice,
        attach_s,
        clients,
    };
    progress(i, n, &d);
    r.done.push(d);
    Ok(true)
}

/// One line per slice on stderr.
fn progress(i: usize, n: usize, d: &Done) {
    let (v, l, c) = (d.variant, &d.slice.m.report.latency, &d.clients);
    let cpu = d
        .slice
        .m
        .cpu()
        .map_or("-".into(), |c| format!("{:.1} %", c * 100.0));
    let requests = match v.serves() {
        true => format!(
            "; {} request(s), {} failed, {} cut off",
            c.made(),
            c.failed(),
            c.cut_off()
        ),
        false => String::new(),
    };
    eprintln!(
        "cpcost: slice {}/{n} {:<22} {:>6} cycles, wake-up p99 {:>6} µs, compute p50/p99 {}/{} µs, {} miss(es), CPU {cpu}{requests}",
        i + 1,
        v.label(),
        l.cycles,
        us(l.wakeup_us.p99),
        us(l.compute_us.p50),
        us(l.compute_us.p99),
        l.deadline_misses
    );
}
