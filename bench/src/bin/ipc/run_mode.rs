//! One mode from start to end: the peer started (motion-io, or this binary
//! as the bare echo) under a service prefix of its own, the measurement in
//! a pinned SCHED_FIFO thread that plays the supervisor, the peer stopped
//! and the prefix cleaned up. A peer that ended early fails the mode.

use crate::cli::Opts;
use crate::echo;
use crate::exchange::FrameSide;
use crate::measure::{measure, Measured};
use crate::mode::Mode;
use motion_bench::bare::{BareSide, PING, PONG};
use motion_bench::host;
use motion_bench::machine;
use motion_bench::proc::Running;
use motion_ipc::{cleanup_domain, Domain, SupervisorPorts};
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// The peer of `mode`: this binary as the bare echo, or motion-io on the
/// demo machine (its config written to `tmp`), event-waiting at priority
/// P-10 or spinning.
fn peer(
    o: &Opts,
    mode: Mode,
    prefix: &str,
    io_bin: Option<&Path>,
    tmp: &Path,
) -> Result<(Command, u32), String> {
    let (toml, machine) = machine::demo_with(&o.cycle.supervisor(prefix))?;
    let priority = (!mode.spin()).then_some(o.cycle.priority - 10);
    if mode.bare() {
        let mut cmd =
            Command::new(std::env::current_exe().map_err(|e| format!("own executable: {e}"))?);
        cmd.args(echo::args(prefix, o.peer_cpu(), priority));
        return Ok((cmd, 0));
    }
    let cfg = motion_bench::drive::write_config(tmp, prefix, &toml)?;
    let mut cmd = Command::new(io_bin.ok_or("no motion-io binary")?);
    cmd.args(["--backend", "sim", "--config"]).arg(&cfg);
    cmd.args([
        "--service-prefix",
        prefix,
        "--cpu",
        &o.peer_cpu().to_string(),
        "--quiet",
    ]);
    cmd.arg("--exit-with-supervisor");
    match priority {
        None => cmd.arg("--spin"),
        Some(p) => cmd.args(["--priority", &p.to_string()]),
    };
    Ok((cmd, machine.axes.len() as u32))
}

/// Starts the peer, measures in a pinned SCHED_FIFO thread, stops the peer.
pub fn run_mode(
    o: &Opts,
    mode: Mode,
    prefix: &str,
    io_bin: Option<&Path>,
    tmp: &Path,
) -> Result<Measured, String> {
    let (mut cmd, axes) = peer(o, mode, prefix, io_bin, tmp)?;
    // This process plays the supervisor: it claims the prefix first, the
    // peer joins through the session file.
    let domain = Domain::establish(prefix, None).map_err(|e| e.to_string())?;
    let mut peer = Running::spawn(&mut cmd, mode.key(), true, false)?;
    let cy = o.cycle.clone();
    let (count, period_ns, warmup) = (o.count, u64::from(cy.period_us) * 1000, o.warmup);
    let (prefix_owned, d) = (prefix.to_string(), domain.clone());
    let worker = std::thread::Builder::new()
        .name("ipc-measure".into())
        .spawn(move || -> Result<Measured, String> {
            let refused = host::enter_rt(Some(cy.cpu), Some(cy.priority));
            if !refused.is_empty() {
                return Err(refused.join("; "));
            }
            let node = d.create_node("motion-bench").map_err(|e| e.to_string())?;
            if mode.bare() {
                let mut x = BareSide::<PING, PONG>::create(&node, &prefix_owned, "ping", "pong")?;
                measure(&mut x, count, period_ns, warmup)
            } else {
                let ports = SupervisorPorts::create(&node, &d, "io").map_err(|e| e.to_string())?;
                measure(&mut FrameSide::new(ports, axes), count, period_ns, warmup)
            }
        })
        .map_err(|e| format!("cannot start the measuring thread: {e}"))?;
    let result = (worker.join()).unwrap_or_else(|_| Err("the measuring thread panicked".into()));
    let _ = cleanup_domain(&domain);
    domain.withdraw();
    let still_running = peer.running();
    let ended = peer.wait(Duration::ZERO, Duration::from_secs(3));
    if !still_running {
        let (how, err) = (ended.describe(), ended.stderr.trim().to_string());
        return Err(format!("the peer ended early: {how}; {err}"));
    }
    result
}
