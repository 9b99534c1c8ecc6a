//! Start-up and shut-down around the real-time thread, shared by `run` and
//! `home`: spawn the cycle, spawn (or wait for) the I/O process, follow the
//! snapshots and statistics, and leave cleanly — axes stopped, drives
//! disabled, ports and node dropped, the I/O process ended, no shared memory
//! left behind.

use crate::io_child::IoChild;
use crate::rt_thread::{self, RtOutcome, RtSettings};
use crate::shared::{Control, Phase, Shared, Snapshot};
use crate::stats::HistSet;
use motion_config::{IoMode, MachineConfig};
use motion_rt::termination as signals;
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

pub struct SessionOptions {
    pub config_path: Option<PathBuf>,
    pub service_prefix: String,
    /// Extra arguments for a spawned motion-io (e.g. `--spin --cpu 0`).
    pub io_args: Vec<String>,
}

pub struct Session {
    pub machine: MachineConfig,
    pub shared: Arc<Shared>,
    rt: Option<JoinHandle<RtOutcome>>,
    pub io: Option<IoChild>,
    pub snapshot: Option<Box<Snapshot>>,
    pub totals: HistSet,
    started: Instant,
    prefix: String,
    /// PM QoS request held for the session (dropped at the end).
    _idle_latency: Option<motion_rt::DmaLatencyGuard>,
    /// Warnings about the environment, printed once.
    pub warnings: Vec<String>,
}

/// What is left after [`Session::finish`].
pub struct Finished {
    pub warnings: Vec<String>,
    pub machine: MachineConfig,
    pub outcome: Option<RtOutcome>,
    pub totals: HistSet,
    pub snapshot: Option<Box<Snapshot>>,
    pub supervisor_cpu: Option<f64>,
    pub io_cpu: Option<f64>,
    pub system_calls_in_cycle: u64,
    pub pool_allocs_in_cycle: u64,
    pub io_exit: Option<String>,
    pub wall_s: f64,
}

/// Where a spawned `motion-io` runs: pinned to another CPU than the cycle
/// (it must not wake up on the real-time core) and SCHED_FIFO below the
/// cycle, as a fieldbus master would be. A starved I/O process shows up as
/// stale feedback, and the engines abort homing on that.
fn io_placement(m: &MachineConfig) -> Vec<String> {
    let sup = &m.supervisor;
    let mut args = Vec::new();
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let cpu = sup
        .io_cpu
        .or_else(|| (cpus > 1).then_some(if sup.cpu == 0 { 1 } else { 0 }));
    if let Some(c) = cpu {
        args.push("--cpu".to_string());
        args.push(c.to_string());
    }
    if sup.io_priority > 0 {
        args.push("--priority".to_string());
        args.push(sup.io_priority.to_string());
    }
    args
}

impl Session {
    pub fn start(machine: MachineConfig, opts: &SessionOptions) -> Result<Session, String> {
        signals::install()?;
        let mut warnings = Vec::new();
        let idle_latency = match machine.supervisor.cpu_dma_latency_us {
            us if us >= 0 => match motion_rt::hold_cpu_dma_latency(us) {
                Ok(g) => Some(g),
                Err(w) => {
                    warnings.push(w);
                    None
                }
            },
            _ => None,
        };
        let shared = Arc::new(Shared::new(4, 8));
        let settings = RtSettings::new(machine.clone(), opts.service_prefix.clone());
        let rt = rt_thread::spawn(settings, shared.clone())
            .map_err(|e| format!("cannot start the real-time thread: {e}"))?;
        let mut s = Session {
            machine,
            shared,
            rt: Some(rt),
            io: None,
            snapshot: None,
            totals: HistSet::new(),
            started: Instant::now(),
            prefix: opts.service_prefix.clone(),
            _idle_latency: idle_latency,
            warnings,
        };
        // The thread creates the ports before it says Running.
        let until = Instant::now() + Duration::from_secs(10);
        loop {
            match s.shared.phase() {
                Phase::Running => break,
                Phase::Failed | Phase::Exited => return Err(s.rt_error()),
                Phase::Starting if Instant::now() > until => {
                    return Err("the real-time thread did not start within 10 s".into())
                }
                Phase::Starting => std::thread::sleep(Duration::from_millis(5)),
            }
        }
        if s.machine.supervisor.io == IoMode::Sim {
            // Options given by the caller come last and win.
            let mut args = io_placement(&s.machine);
            args.extend(opts.io_args.iter().cloned());
            let io = IoChild::spawn(opts.config_path.as_deref(), &opts.service_prefix, &args);
            match io {
                Ok(io) => s.io = Some(io),
                Err(e) => {
                    s.shutdown_rt();
                    return Err(e);
                }
            }
        }
        Ok(s)
    }

    /// Collects what the real-time thread handed over.
    pub fn poll(&mut self) {
        self.shared.latest_snapshot(&mut self.snapshot);
        self.shared.collect_stats(&mut self.totals);
    }

    /// Waits until the I/O process answers every cycle and warm-up is over.
    pub fn wait_io(&mut self, timeout: Duration) -> Result<(), String> {
        let until = Instant::now() + timeout;
        loop {
            self.poll();
            if self.shared.measuring.load(Ordering::Acquire)
                && self.snapshot.as_ref().is_some_and(|s| s.io_fresh)
            {
                return Ok(());
            }
            if let Some(e) = self.check_alive() {
                return Err(e);
            }
            if let Some(sig) = signals::received() {
                return Err(format!("signal {sig} while waiting for the I/O process"));
            }
            if Instant::now() > until {
                let how = match self.machine.supervisor.io {
                    IoMode::Sim => "the motion-io process it started",
                    IoMode::External => "an external I/O process (io = \"external\")",
                };
                return Err(format!(
                    "no answer on iceoryx2 service '{}/feedback' within {} s from {how}",
                    self.prefix,
                    timeout.as_secs()
                ));
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// `Some(reason)` if the real-time thread or the I/O process died.
    pub fn check_alive(&mut self) -> Option<String> {
        match self.shared.phase() {
            Phase::Failed => return Some(self.rt_error()),
            Phase::Exited => return Some("the real-time thread ended".into()),
            _ => {}
        }
        if let Some(io) = &mut self.io {
            if let Some(status) = io.exited() {
                return Some(format!("motion-io (pid {}) ended: {status}", io.pid()));
            }
        }
        None
    }

    /// Queues a request for the cycle; false if the cycle has not taken
    /// requests for a second (it drains the 256-entry queue every period).
    pub fn send(&self, c: Control) -> bool {
        let until = Instant::now() + Duration::from_secs(1);
        while !self.shared.send(c) {
            if Instant::now() > until {
                return false;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        true
    }

    pub fn elapsed(&self) -> Duration {
        self.started.elapsed()
    }

    fn rt_error(&mut self) -> String {
        match self.rt.take().map(|h| h.join()) {
            Some(Ok(out)) => out
                .error
                .unwrap_or_else(|| "the real-time thread ended".into()),
            Some(Err(_)) => "the real-time thread panicked".into(),
            None => "the real-time thread is gone".into(),
        }
    }

    fn shutdown_rt(&mut self) -> Option<RtOutcome> {
        let h = self.rt.take()?;
        if !matches!(self.shared.phase(), Phase::Exited | Phase::Failed) {
            let _ = self.send(Control::Exit);
        }
        // Stopping axes at home deceleration takes well under this.
        let until = Instant::now() + Duration::from_secs(30);
        while !h.is_finished() && Instant::now() < until {
            std::thread::sleep(Duration::from_millis(5));
        }
        if h.is_finished() {
            h.join().ok()
        } else {
            None
        }
    }

    /// Stops every axis and disables the drives (Control::Exit), ends the
    /// real-time thread, then the I/O process; cleans up shared memory.
    pub fn finish(self) -> Finished {
        self.finish_with(|_| {})
    }

    /// [`Self::finish`], showing each histogram interval handed over during
    /// shut-down to `each` (the interval log must not lose the last one).
    pub fn finish_with(mut self, each: impl FnMut(&HistSet)) -> Finished {
        let io_cpu = self.io.as_mut().and_then(|io| io.cpu_share());
        let supervisor_cpu = crate::cpu::process_cpu_seconds(std::process::id())
            .map(|s| s / self.started.elapsed().as_secs_f64());
        let outcome = self.shutdown_rt();
        self.shared.collect_intervals(&mut self.totals, each);
        self.shared.latest_snapshot(&mut self.snapshot);
        let io_exit = self
            .io
            .as_mut()
            .map(|io| match io.terminate(Duration::from_secs(3)) {
                Some(s) => s.to_string(),
                None => "still running".into(),
            });
        let _ =
            motion_frames::ipc::cleanup_domain(&motion_frames::IpcConfig::new(self.prefix.clone()));
        Finished {
            warnings: std::mem::take(&mut self.warnings),
            machine: self.machine.clone(),
            outcome,
            totals: std::mem::take(&mut self.totals),
            snapshot: self.snapshot.take(),
            supervisor_cpu,
            io_cpu,
            system_calls_in_cycle: self.shared.system_calls_in_cycle.load(Ordering::Acquire),
            pool_allocs_in_cycle: self.shared.pool_allocs_in_cycle.load(Ordering::Acquire),
            io_exit,
            wall_s: self.started.elapsed().as_secs_f64(),
        }
    }
}
