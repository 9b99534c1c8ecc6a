//! Start-up and shut-down around the real-time thread, shared by `run` and
//! `home`: claim the domain, start the cycle and the control thread, spawn
//! (or wait for) the I/O processes, and leave cleanly — axes stopped, drives
//! disabled, ports and nodes dropped, the spawned I/O processes ended, no
//! shared memory and no session file left behind.
//!
//! A `Session` that is dropped without [`Session::finish`] (an early return,
//! a panic unwinding through a command) still does all of that: nothing is
//! left moving and nothing is left in `/dev/shm`.

use crate::control_thread::{self, ControlSettings, Ready};
use crate::hub::SharedHub;
use crate::io_child::{Backoff, IoChild, Seen, SpawnNote};
use crate::rt_thread::{self, RtOutcome, RtSettings};
use crate::shared::{Ask, Control, Phase, Shared, Snapshot};
use motion_config::{IoMode, MachineConfig};
use motion_ipc::Domain;
use motion_report::{IoReport, Latency};
use motion_rt::termination as signals;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

pub struct SessionOptions {
    pub config_path: Option<PathBuf>,
    pub service_prefix: String,
    /// Overrides `[supervisor] runtime_dir`.
    pub runtime_dir: Option<PathBuf>,
    /// Extra arguments for every spawned motion-io (e.g. `--spin`).
    pub io_args: Vec<String>,
    /// `run --hlog FILE`.
    pub hlog_file: Option<PathBuf>,
    /// `run --no-control-plane` (benchmarks only): no control or status
    /// service, to measure what they cost the cycle.
    pub no_control_plane: bool,
}

/// A spawned I/O process and when it may be restarted.
struct Spawned {
    io: usize,
    child: Option<IoChild>,
    restart_at: Option<Instant>,
    restarts: u32,
    /// The delay before the next start (1 s doubling to 30 s).
    backoff: Backoff,
    /// Its lines shown already.
    seen: Seen,
    /// The error its last failed start ended with.
    last_error: Option<String>,
}

pub struct Session {
    pub machine: MachineConfig,
    pub domain: Domain,
    pub shared: Arc<Shared>,
    pub hub: SharedHub,
    rt: Option<JoinHandle<RtOutcome>>,
    control: Option<JoinHandle<()>>,
    control_stop: Arc<AtomicBool>,
    spawned: Vec<Spawned>,
    opts_config: Option<PathBuf>,
    io_args: Vec<String>,
    started: Instant,
    /// PM QoS request held for the session (dropped at the end).
    _idle_latency: Option<motion_rt::DmaLatencyGuard>,
    /// Warnings about the environment and the config, printed once.
    pub warnings: Vec<String>,
    finished: bool,
}

/// What is left after [`Session::finish`].
pub struct Finished {
    pub warnings: Vec<String>,
    pub machine: MachineConfig,
    pub outcome: Option<RtOutcome>,
    pub latency: Latency,
    pub io: Vec<IoReport>,
    pub snapshot: Option<Box<Snapshot>>,
    pub supervisor_cpu: Option<f64>,
    pub io_cpu: Vec<(String, Option<f64>)>,
    pub system_calls_in_cycle: u64,
    pub pool_allocs_in_cycle: u64,
    pub io_exit: Vec<String>,
    pub wall_s: f64,
}

/// Where a spawned `motion-io` runs: by default on the cycle's CPU, at
/// SCHED_FIFO 10 below the cycle. The cycle publishes and goes to sleep;
/// the I/O process answers in the rest of the period on the same core. A
/// stall of that core then stalls both alike — one missed answer, not a
/// silent peer — while on another core every stall of either one shows as a
/// gap in the answers (measured on the development VM: 26 gaps of 4–10
/// cycles per minute on separate cores, 1 on the same core; the round trip
/// p50 fell from 28 to 19 µs). `cpu` in `[[io]]` (or `io_cpu`) places it
/// elsewhere.
fn io_placement(m: &MachineConfig, io: usize) -> Vec<String> {
    let sup = &m.supervisor;
    let cfg = &m.ios[io];
    let mut args = Vec::new();
    let cpu = cfg.cpu.or(Some(sup.cpu));
    if let Some(c) = cpu {
        args.push("--cpu".to_string());
        args.push(c.to_string());
    }
    if cfg.priority > 0 {
        args.push("--priority".to_string());
        args.push(cfg.priority.to_string());
    }
    args
}

impl Session {
    pub fn start(machine: MachineConfig, opts: &SessionOptions) -> Result<Session, String> {
        signals::install()?;
        let runtime_dir = opts
            .runtime_dir
            .clone()
            .or_else(|| machine.supervisor.runtime_dir.clone());
        let domain = Domain::establish(&opts.service_prefix, runtime_dir.as_deref())
            .map_err(|e| e.to_string())?;
        let mut warnings = machine.warnings.clone();
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
        let hub = SharedHub::default();
        let mut s = Session {
            machine: machine.clone(),
            domain: domain.clone(),
            shared: shared.clone(),
            hub: hub.clone(),
            rt: None,
            control: None,
            control_stop: Arc::new(AtomicBool::new(false)),
            spawned: Vec::new(),
            opts_config: opts.config_path.clone(),
            io_args: opts.io_args.clone(),
            started: Instant::now(),
            _idle_latency: idle_latency,
            warnings,
            finished: false,
        };
        let settings = RtSettings::new(machine.clone(), domain.clone());
        s.rt = Some(
            rt_thread::spawn(settings, shared.clone())
                .map_err(|e| format!("cannot start the real-time thread: {e}"))?,
        );
        // The thread creates the frame services before it says Running.
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
        // This thread and the ones it spawns from here on (control, status,
        // reporting) leave the cycle's CPU to the cycle (and the I/O process
        // placed there, which pins itself): see `motion_rt::keep_off_cpu`.
        match motion_rt::keep_off_cpu(machine.supervisor.cpu) {
            Ok(cpus) => log::info!(
                "non-real-time threads kept off cpu {} (on cpu {})",
                machine.supervisor.cpu,
                cpus.iter()
                    .map(|c| c.to_string())
                    .collect::<Vec<_>>()
                    .join(",")
            ),
            Err(w) => s.warnings.push(w),
        }
        let ready = Arc::new(Ready::default());
        s.control = Some(
            control_thread::spawn(
                ControlSettings {
                    machine: machine.clone(),
                    domain: domain.clone(),
                    hlog_file: opts.hlog_file.clone(),
                    serve: !opts.no_control_plane,
                },
                shared,
                hub,
                s.control_stop.clone(),
                ready.clone(),
            )
            .map_err(|e| format!("cannot start the control thread: {e}"))?,
        );
        let until = Instant::now() + Duration::from_secs(10);
        while !ready.ready.load(Ordering::Acquire) {
            if ready.failed.load(Ordering::Acquire) || Instant::now() > until {
                let e = s
                    .hub
                    .lock()
                    .control_error
                    .clone()
                    .unwrap_or_else(|| "the control thread did not start within 10 s".into());
                return Err(e);
            }
            std::thread::sleep(Duration::from_millis(2));
        }
        for (k, io) in machine.ios.iter().enumerate() {
            if io.spawn == IoMode::Sim {
                s.spawned.push(Spawned {
                    io: k,
                    child: None,
                    restart_at: None,
                    restarts: 0,
                    backoff: Backoff::default(),
                    seen: Seen::default(),
                    last_error: None,
                });
            }
        }
        for i in 0..s.spawned.len() {
            s.spawn_io(i)?;
        }
        Ok(s)
    }

    fn spawn_io(&mut self, i: usize) -> Result<(), String> {
        let k = self.spawned[i].io;
        let mut args = io_placement(&self.machine, k);
        // Options given by the caller come last and win.
        args.extend(self.io_args.iter().cloned());
        let child = IoChild::spawn(
            &self.machine.ios[k].name,
            self.machine.ios[k].backend.name(),
            self.opts_config.as_deref(),
            &self.domain.prefix,
            &self.domain.runtime_dir,
            &args,
            self.spawned[i].seen.clone(),
        )?;
        self.spawned[i].child = Some(child);
        self.spawned[i].restart_at = None;
        self.note_spawns();
        Ok(())
    }

    /// The spawned I/O processes' restarts and start-up errors, for the
    /// status (`io_child::note_spawns`).
    fn note_spawns(&self) {
        let mut notes = vec![SpawnNote::default(); self.machine.ios.len()];
        for sp in &self.spawned {
            notes[sp.io] = SpawnNote {
                restarts: sp.restarts,
                retry_at: sp.restart_at,
                start_error: sp.last_error.clone(),
            };
        }
        self.hub.lock().spawns = notes;
    }

    /// Collects what the control thread gathered: the newest snapshot.
    pub fn snapshot(&self) -> Option<Box<Snapshot>> {
        self.hub.lock().snapshot.clone()
    }

    /// Waits until every I/O process answers and warm-up is over.
    pub fn wait_io(&mut self, timeout: Duration) -> Result<(), String> {
        let until = Instant::now() + timeout;
        loop {
            let attached = self.snapshot().is_some_and(|s| s.all_attached());
            if self.shared.measuring.load(Ordering::Acquire) && attached {
                return Ok(());
            }
            if let Some(e) = self.check_alive() {
                return Err(e);
            }
            if let Some(e) = self.poll_children(false).into_iter().next() {
                return Err(e);
            }
            if let Some(sig) = signals::received() {
                return Err(format!("signal {sig} while waiting for the I/O processes"));
            }
            if Instant::now() > until {
                let snap = self.snapshot();
                let missing: Vec<String> = self
                    .machine
                    .ios
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| !snap.as_ref().is_some_and(|s| s.ios[*k].attached))
                    .map(|(_, io)| match io.spawn {
                        IoMode::Sim => format!("{} (spawned by the supervisor)", io.name),
                        IoMode::External => format!(
                            "{} (external: start `motion-io --io {} --service-prefix {}`)",
                            io.name, io.name, self.domain.prefix
                        ),
                    })
                    .collect();
                return Err(format!(
                    "no answer within {} s from I/O process {}",
                    timeout.as_secs(),
                    missing.join(", ")
                ));
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// `Some(reason)` if the real-time thread or the control thread died.
    pub fn check_alive(&mut self) -> Option<String> {
        match self.shared.phase() {
            Phase::Failed => return Some(self.rt_error()),
            Phase::Exited => return Some("the real-time thread ended".into()),
            _ => {}
        }
        if self.control.as_ref().is_some_and(|h| h.is_finished()) {
            return Some("the control thread ended unexpectedly".into());
        }
        None
    }

    /// Spawned I/O processes that ended since the last call, in words; with
    /// `respawn`, each is started again after its back-off (1 s, doubling to
    /// 30 s while it keeps failing at start-up: see `io_child`; the daemon
    /// keeps its simulators; the axes of a restarted one are unhomed, as on
    /// real buses). A failure like the one before is said in a line of its
    /// own, not repeated in full.
    pub fn poll_children(&mut self, respawn: bool) -> Vec<String> {
        let mut events = Vec::new();
        let mut changed = false;
        for i in 0..self.spawned.len() {
            let sp = &mut self.spawned[i];
            if let Some(c) = sp.child.as_mut() {
                if let Some(status) = c.exited() {
                    let error = c.start_error();
                    let again = error.is_some() && error == sp.last_error;
                    let delay = sp.backoff.ended(c.ran());
                    if c.ran() >= Backoff::STABLE {
                        // it did run: its lines are news again
                        if let Ok(mut s) = sp.seen.lock() {
                            s.clear();
                        }
                    }
                    let mut e = if again {
                        format!(
                            "I/O process {} (motion-io pid {}) failed at start-up again, as \
                             before ({status})",
                            c.name,
                            c.pid()
                        )
                    } else {
                        format!(
                            "I/O process {} (motion-io pid {}) ended: {status}{}",
                            c.name,
                            c.pid(),
                            error
                                .as_deref()
                                .and_then(|e| e.lines().next())
                                .map_or(String::new(), |e| format!(" ({e})"))
                        )
                    };
                    if respawn {
                        e.push_str(&format!(
                            "; starting it again in {} s (restart {})",
                            delay.as_secs(),
                            sp.restarts + 1
                        ));
                        sp.restart_at = Some(Instant::now() + delay);
                    }
                    events.push(e);
                    sp.last_error = error;
                    sp.child = None;
                    changed = true;
                }
            } else if sp.restart_at.is_some_and(|t| Instant::now() >= t) {
                sp.restarts += 1;
                let name = self.machine.ios[sp.io].name.clone();
                match self.spawn_io(i) {
                    Ok(()) => log::info!("I/O process {name} restarted"),
                    Err(e) => {
                        let sp = &mut self.spawned[i];
                        let delay = sp.backoff.ended(Duration::ZERO);
                        log::error!("{e}; trying again in {} s", delay.as_secs());
                        sp.last_error = Some(e);
                        sp.restart_at = Some(Instant::now() + delay);
                    }
                }
                changed = true;
            }
        }
        if changed {
            self.note_spawns();
        }
        events
    }

    /// Queues a request for the cycle; false if the cycle has not taken
    /// requests for a second.
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
            let _ = self.send(Control::undated(0, Ask::Exit));
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
    /// real-time and control threads, then the I/O processes; cleans up
    /// shared memory and the session file.
    pub fn finish(mut self) -> Finished {
        let mut io_cpu = Vec::new();
        for sp in &mut self.spawned {
            if let Some(c) = sp.child.as_mut() {
                io_cpu.push((c.name.clone(), c.cpu_share()));
            }
        }
        let supervisor_cpu = crate::cpu::process_cpu_seconds(std::process::id())
            .map(|s| s / self.started.elapsed().as_secs_f64());
        let outcome = self.shutdown_rt();
        let io_exit = self.stop_rest();
        let hub = self.hub.lock();
        let snapshot = hub.snapshot.clone();
        let latency = hub.since_start.summary();
        let io = snapshot
            .as_deref()
            .map(|s| control_thread::io_reports(&self.machine, s))
            .unwrap_or_default();
        drop(hub);
        Finished {
            warnings: std::mem::take(&mut self.warnings),
            machine: self.machine.clone(),
            outcome,
            latency,
            io,
            snapshot,
            supervisor_cpu,
            io_cpu,
            system_calls_in_cycle: self.shared.system_calls_in_cycle.load(Ordering::Acquire),
            pool_allocs_in_cycle: self.shared.pool_allocs_in_cycle.load(Ordering::Acquire),
            io_exit,
            wall_s: self.started.elapsed().as_secs_f64(),
        }
    }

    /// Everything after the real-time thread: the control thread, the
    /// spawned I/O processes, shared memory, the session file.
    fn stop_rest(&mut self) -> Vec<String> {
        self.finished = true;
        self.control_stop.store(true, Ordering::Release);
        if let Some(h) = self.control.take() {
            let _ = h.join();
        }
        let mut io_exit = Vec::new();
        for sp in &mut self.spawned {
            if let Some(c) = sp.child.as_mut() {
                let how = match c.terminate(Duration::from_secs(3)) {
                    Some(s) => s.to_string(),
                    None => "still running".into(),
                };
                io_exit.push(format!("{}: {how}", c.name));
            }
            sp.child = None;
        }
        let report = motion_ipc::cleanup_domain(&self.domain);
        if !report.domain_gone() {
            log::debug!("iceoryx2 domain on exit: {report}");
        }
        self.domain.withdraw();
        io_exit
    }
}

impl Drop for Session {
    /// A session left without `finish` (an error path, a panic unwinding):
    /// stop the axes, end the threads and children, clean up.
    fn drop(&mut self) {
        if self.finished {
            return;
        }
        let _ = self.shutdown_rt();
        let _ = self.stop_rest();
    }
}
