//! One mode from start to end: the peer started (motion-io, or this binary
//! as the bare echo) under a service prefix of its own, the measurement in
//! a pinned SCHED_FIFO thread that plays the supervisor, the peer stopped
//! and the prefix cleaned up. A peer that ended early fails the mode.

use crate::bare::{BareSide, PING, PONG};
use crate::cli::Opts;
use crate::echo;
use crate::exchange::FrameSide;
use crate::measure::{measure, Measured};
use crate::mode::Mode;
use motion_bench::machine::{self, Supervisor};
use motion_bench::proc::Running;
use motion_bench::sys;
use motion_ipc::{cleanup_domain, Domain, SupervisorPorts};
use std::process::Command;
use std::time::Duration;

/// Starts the peer, measures in a pinned SCHED_FIFO thread, stops the peer.
pub fn run_mode(
    o: &Opts,
    mode: Mode,
    prefix: &str,
    io_bin: Option<&std::path::Path>,
    tmp: &std::path::Path,
) -> Result<Measured, String> {
    let (toml, machine) = machine::demo_with(&Supervisor {
        cycle_us: o.period_us,
        cpu: o.cpu,
        priority: o.priority,
        service_prefix: prefix.to_string(),
    })?;
    let axes = machine.axes.len() as u32;
    let peer_prio = (o.priority - 10).to_string();
    let peer_cpu = o.peer_cpu().to_string();
    let mut cmd;
    if mode.bare() {
        let exe = std::env::current_exe().map_err(|e| format!("own executable: {e}"))?;
        cmd = Command::new(exe);
        let priority = (!mode.spin()).then_some(o.priority - 10);
        cmd.args(echo::args(prefix, o.peer_cpu(), priority));
    } else {
        let cfg = tmp.join(format!("{prefix}.toml"));
        std::fs::write(&cfg, toml).map_err(|e| format!("{}: {e}", cfg.display()))?;
        cmd = Command::new(io_bin.ok_or("no motion-io binary")?);
        cmd.arg("--backend")
            .arg("sim")
            .arg("--config")
            .arg(&cfg)
            .args(["--service-prefix", prefix, "--cpu", &peer_cpu, "--quiet"])
            .arg("--exit-with-supervisor");
        if mode.spin() {
            cmd.arg("--spin");
        } else {
            cmd.args(["--priority", &peer_prio]);
        }
    }
    // This process plays the supervisor: it claims the prefix first, the
    // peer joins through the session file.
    let domain = Domain::establish(prefix, None).map_err(|e| e.to_string())?;
    let mut peer = Running::spawn(&mut cmd, mode.key(), true, false)?;

    let (count, period_ns, warmup, cpu, prio) = (
        o.count,
        u64::from(o.period_us) * 1000,
        o.warmup,
        o.cpu,
        o.priority,
    );
    let prefix_owned = prefix.to_string();
    let bare = mode.bare();
    let d = domain.clone();
    let worker = std::thread::Builder::new()
        .name("ipc-measure".into())
        .spawn(move || -> Result<Measured, String> {
            let refused = sys::enter_rt(Some(cpu), Some(prio));
            if !refused.is_empty() {
                return Err(refused.join("; "));
            }
            let node = d.create_node("motion-bench").map_err(|e| e.to_string())?;
            if bare {
                let mut x = BareSide::<PING, PONG>::create(&node, &prefix_owned, "ping", "pong")?;
                measure(&mut x, count, period_ns, warmup)
            } else {
                let ports = SupervisorPorts::create(&node, &d, "io").map_err(|e| e.to_string())?;
                let mut x = FrameSide::new(ports, axes);
                measure(&mut x, count, period_ns, warmup)
            }
        })
        .map_err(|e| format!("cannot start the measuring thread: {e}"))?;
    let result = worker
        .join()
        .unwrap_or_else(|_| Err("the measuring thread panicked".into()));
    let _ = cleanup_domain(&domain);
    domain.withdraw();
    let still_running = peer.running();
    let ended = peer.wait(Duration::ZERO, Duration::from_secs(3));
    if !still_running {
        return Err(format!(
            "the peer ended early: {}; {}",
            ended.describe(),
            ended.stderr.trim()
        ));
    }
    result
}
