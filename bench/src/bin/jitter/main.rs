//! Jitter bench: the supervisor's real cycle (`motion-supervisor run`) side
//! by side with cyclictest, same period, priority and CPU, in alternating
//! slices so that both see the same host noise; with `--ethercat` also the
//! supervisor with the EtherCAT backend (over a veth pair to emulated
//! drives) in the same slices. See `bench/README.md`.
//!
//! This file is the sequence — find the tools, set the stage (temporary
//! directory, EtherCAT rig, stress-ng), run the slices, merge, judge,
//! report — and the modules are its steps:
//!
//! * [`cli`] the command line; [`tools`] the programs it runs; [`host`] the
//!   machine it runs on; [`stress`] the `--stress` load;
//! * [`slices`] the alternating slices, running [`supervisor`] (with
//!   [`homing64`] for the 64-axis machine) and [`cyclictest_slice`];
//! * [`summary`] the slices merged and the verdict;
//! * [`table`] the printed report, [`hlog`], [`plot`] and [`json`] the files.

mod cli;
mod cyclictest_slice;
mod hlog;
mod homing64;
mod json;
mod plot;
mod slices;
mod stress;
mod summary;
mod supervisor;
mod table;
mod tools;

use clap::Parser;
use cli::Opts;
use motion_bench::ecat::EcatRig;
use motion_bench::host::{Env, OtherRt};
use motion_bench::proc;
use std::path::PathBuf;
use std::time::{Instant, SystemTime};

fn main() {
    let o = Opts::parse();
    proc::install_stop_handler();
    std::process::exit(match run(&o) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("jitter: FAILED: {e}");
            1
        }
    });
}

fn run(o: &Opts) -> Result<i32, String> {
    let supervisor = tools::supervisor(o)?;
    let cyclictest = tools::cyclictest(o);
    let other_cpu = if o.cpu == 0 { 1 } else { 0 };
    let stress_ng = tools::stress_ng(o)?;

    let env = Env::probe();
    let pid = std::process::id();
    let tmp = std::env::temp_dir().join(format!("motion-bench-jitter-{pid}"));
    std::fs::create_dir_all(&tmp).map_err(|e| format!("cannot create {}: {e}", tmp.display()))?;
    let _tmp_guard = RemoveDir(tmp.clone());
    std::fs::create_dir_all(&o.out)
        .map_err(|e| format!("cannot create {}: {e}", o.out.display()))?;

    let slices = slices::count(o);
    eprintln!(
        "jitter: {} s per tool at {} µs, {} slice(s) of ≤ {} s, SCHED_FIFO {} on CPU {}{}",
        o.duration,
        o.period_us,
        slices,
        o.slice,
        o.priority,
        o.cpu,
        if o.stress {
            format!(", stress-ng on CPU {other_cpu}")
        } else {
            String::new()
        }
    );
    eprintln!("jitter: supervisor {}", supervisor.display());
    if let Some(c) = &cyclictest {
        eprintln!("jitter: cyclictest {}", c.display());
    }
    if !env.is_rt {
        eprintln!(
            "jitter: kernel is not PREEMPT_RT ({}): the numbers are upper bounds",
            env.preemption
        );
    }
    let mut other_rt = OtherRt::new("jitter");
    other_rt.note("before the bench");

    let rig = if o.ethercat {
        Some(ethercat_rig(o, other_cpu)?)
    } else {
        None
    };

    let t0 = Instant::now();
    let t0_wall = SystemTime::now();
    let stress = match &stress_ng {
        None => None,
        Some(bin) => Some(stress::start(bin, other_cpu, o.duration, slices)?),
    };
    let motionctl = tools::motionctl(o, &supervisor)?;

    let mut c = slices::run(
        &slices::Plan {
            o,
            slices,
            pid,
            tmp: &tmp,
            t0,
            supervisor: &supervisor,
            motionctl: &motionctl,
            rig: rig.as_ref(),
            cyclictest: cyclictest.as_deref(),
        },
        &mut other_rt,
    )?;
    let mut failures = std::mem::take(&mut c.failures);
    stress::stop(stress, c.interrupted, &mut failures);
    let wall = t0.elapsed();

    if c.ours.is_empty() {
        for f in &failures {
            eprintln!("jitter: FAILED: {f}");
        }
        if c.interrupted {
            eprintln!("jitter: interrupted (signal {})", proc::stop_signal());
            return Ok(130);
        }
        return Err(failures.join("; "));
    }

    let m = summary::Summary::of(&c, o.period_us);
    m.judge(
        o.axes64,
        o.ethercat,
        cyclictest.is_some(),
        c.interrupted,
        &mut failures,
    );
    print!("{}", table::text(o, &env, other_cpu, &m, &c, &other_rt));

    let base = o.out.join(format!("jitter-{}us", o.period_us));
    let hlog_path = base.with_extension("hlog");
    let svg_path = base.with_extension("svg");
    let json_path = base.with_extension("json");
    if let Err(e) = hlog::write(&hlog_path, o, &env, t0_wall, &c) {
        failures.push(e);
    }
    if let Err(e) = plot::write(&svg_path, o, &env, &m) {
        failures.push(e);
    }
    if let Err(e) = json::write(
        &json_path,
        o,
        &env,
        wall,
        &m,
        &c,
        &other_rt,
        (&hlog_path, &svg_path),
        &failures,
    ) {
        failures.push(e);
    }
    println!(
        "files: {}, {}, {}",
        hlog_path.display(),
        svg_path.display(),
        json_path.display()
    );

    if c.interrupted {
        eprintln!(
            "jitter: interrupted (signal {}): results above are partial",
            proc::stop_signal()
        );
        return Ok(130);
    }
    if failures.is_empty() {
        println!("jitter: OK");
        Ok(0)
    } else {
        for f in &failures {
            println!("jitter: FAILED: {f}");
        }
        Ok(1)
    }
}

/// `--ethercat`: the veth pair and the emulated drives, for the whole bench.
fn ethercat_rig(o: &Opts, other_cpu: usize) -> Result<EcatRig, String> {
    let demo = motion_config::parse(motion_config::DEMO_TOML)
        .map_err(|p| format!("deploy/demo.toml: {p:?}"))?;
    // below motion-io (priority − 10), whose answer to the supervisor
    // is what the cycle measures; the emulator plays hardware that
    // would take no CPU at all
    let emu_priority = (o.priority - 15).clamp(1, 99);
    let rig =
        EcatRig::start(&demo, other_cpu, emu_priority).map_err(|e| format!("--ethercat: {e}"))?;
    eprintln!(
        "jitter: EtherCAT: motion-io --backend ethercat on {} ↔ veth ↔ ecat-emu ({} drives, \
         SCHED_FIFO {emu_priority} on CPU {other_cpu})",
        rig.interface(),
        rig.drives
    );
    Ok(rig)
}

/// Removes a directory on drop: the bench's temporary configs, logs and
/// histograms go whichever way `run` returns.
struct RemoveDir(PathBuf);

impl Drop for RemoveDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
