//! Jitter bench: the supervisor's real cycle (`motion-supervisor run`) side
//! by side with cyclictest, same period, priority and CPU, in alternating
//! slices so that both see the same host noise; with `--ethercat` also the
//! supervisor with the EtherCAT backend (over a veth pair to emulated
//! drives) in the same slices. See `bench/README.md`.
//!
//! The sequence: find the tools, set the stage (EtherCAT rig, stress-ng),
//! run the [`slices`], merge and judge them ([`report`]), print, write the
//! [`files`].

mod bus;
mod cli;
mod files;
mod report;
mod slices;

use clap::Parser;
use cli::Opts;
use motion_bench::bins::{self, Binaries};
use motion_bench::ecat::EcatRig;
use motion_bench::host;
use motion_bench::outcome::{self, Bench};
use motion_bench::proc::{self, Running};
use std::path::PathBuf;
use std::time::{Duration, Instant, SystemTime};

fn main() {
    let o = Opts::parse();
    outcome::main("jitter", || run(&o))
}

fn run(o: &Opts) -> Result<i32, String> {
    let bins = Binaries::find(o.files.supervisor.as_deref())?;
    let cyclictest = cyclictest(o);
    if o.stress && host::cpus() < 2 {
        return Err("--stress needs a second CPU".into());
    }
    let out = o.files.out("");
    let mut b = Bench::start("jitter", Some(&out))?;
    let (cy, slices) = (&o.cycle, o.slicing.count());
    let on = match o.stress {
        true => format!(", stress-ng on CPU {}", cy.other_cpu()),
        false => String::new(),
    };
    eprintln!(
        "jitter: {} s per tool at {} µs, {slices} slice(s) of ≤ {} s, SCHED_FIFO {} on CPU {}{on}",
        o.slicing.duration, cy.period_us, o.slicing.slice, cy.priority, cy.cpu
    );
    eprintln!("jitter: supervisor {}", bins.supervisor.display());
    if let Some(c) = &cyclictest {
        eprintln!("jitter: cyclictest {}", c.display());
    }
    b.warn_not_rt();
    let rig = o.ethercat.then(|| ethercat_rig(o)).transpose()?;
    let (t0, t0_wall) = (Instant::now(), SystemTime::now());
    let stress = o.stress.then(|| start_stress(o, slices)).transpose()?;
    let plan = slices::Plan {
        o,
        slices,
        tmp: &b.tmp,
        t0,
        bins: &bins,
        rig: rig.as_ref(),
        cyclictest: cyclictest.as_deref(),
    };
    let mut c = slices::run(&plan, &mut b.other_rt)?;
    let mut failures = std::mem::take(&mut c.failures);
    stop_stress(stress, c.interrupted, &mut failures);
    let wall = t0.elapsed().as_secs_f64();
    if c.ours[0].is_empty() {
        return b.nothing_measured(c.interrupted, &failures);
    }
    let m = report::Summary::of(&c, cy.period_us);
    m.judge(o, cyclictest.is_some(), c.interrupted, &mut failures);
    print!("{}", report::text(o, &b, &m, &c));
    let base = out.join(format!("jitter-{}us", cy.period_us));
    let [hlog, svg, json] = ["hlog", "svg", "json"].map(|e| base.with_extension(e));
    let written = [
        files::hlog(&hlog, o, &b, t0_wall, &c),
        files::svg(&svg, o, &b, &m),
    ];
    failures.extend(written.into_iter().filter_map(Result::err));
    let ctx = (o, &b, &m, &c);
    if let Err(e) = files::json(&json, ctx, wall, [&hlog, &svg], &failures) {
        failures.push(e);
    }
    Ok(b.end(&[&hlog, &svg, &json], c.interrupted, &failures, true))
}

/// cyclictest, or None (with a warning saying why) when its half is
/// skipped: `--no-cyclictest`, not installed, or no SCHED_FIFO for this
/// user (cyclictest refuses to run without it).
fn cyclictest(o: &Opts) -> Option<PathBuf> {
    if o.no_cyclictest {
        eprintln!("jitter: --no-cyclictest: running the supervisor half only");
        return None;
    }
    let found = o
        .cyclictest
        .clone()
        .or_else(|| bins::find_in_path("cyclictest"));
    let Some(bin) = found else {
        eprintln!(
            "jitter: WARNING: cyclictest not found (install rt-tests: `apt-get install -y \
             rt-tests`); SKIPPING the cyclictest half, the supervisor is measured alone"
        );
        return None;
    };
    if let Err(e) = motion_rt::fifo_allowed(o.cycle.priority) {
        eprintln!(
            "jitter: WARNING: no real-time scheduling for this user ({e}); cyclictest cannot run \
             like that: SKIPPING the cyclictest half (the supervisor warns and runs SCHED_OTHER)"
        );
        return None;
    }
    Some(bin)
}

/// `--stress`: stress-ng loading the other CPU for the whole bench, bounded
/// by its own timeout well beyond the bench's expected length (so it cannot
/// outlive a bench that dies) and killed as a group at the end.
fn start_stress(o: &Opts, slices: usize) -> Result<Running, String> {
    let bound = (3.0 * o.slicing.duration + 20.0 * slices as f64 + 60.0).ceil() as u64;
    let cpu = o.cycle.other_cpu();
    let r = proc::stress(cpu, Duration::from_secs(bound)).map_err(|e| format!("--stress: {e}"))?;
    let pid = r.pid();
    eprintln!("jitter: stress-ng --cpu 1 --taskset {cpu} --timeout {bound}s (pid {pid})");
    Ok(r)
}

/// Ends stress-ng, whatever happened; a failure if it had ended by itself
/// (the bench did not run under the load it claims), unless interrupted.
fn stop_stress(stress: Option<Running>, interrupted: bool, failures: &mut Vec<String>) {
    if let Some(mut s) = stress {
        let still = s.running();
        s.terminate(Duration::from_secs(3));
        if !still && !interrupted {
            failures.push("stress-ng ended before the bench did (see its output)".into());
        }
    }
}

/// `--ethercat`: the veth pair and the emulated drives, for the whole bench.
fn ethercat_rig(o: &Opts) -> Result<EcatRig, String> {
    let demo = motion_config::parse(motion_config::DEMO_TOML)
        .map_err(|p| format!("deploy/demo.toml: {p:?}"))?;
    // below motion-io (priority − 10), whose answer to the supervisor is
    // what the cycle measures; the emulator plays hardware that would take
    // no CPU at all
    let (cpu, priority) = (o.cycle.other_cpu(), (o.cycle.priority - 15).clamp(1, 99));
    let rig = EcatRig::start(&demo, cpu, priority).map_err(|e| format!("--ethercat: {e}"))?;
    eprintln!(
        "jitter: EtherCAT: motion-io --backend ethercat on {} ↔ veth ↔ ecat-emu ({} drives, \
         SCHED_FIFO {priority} on CPU {cpu})",
        rig.interface(),
        rig.drives
    );
    Ok(rig)
}
