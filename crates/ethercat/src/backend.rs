//! [`EthercatBackend`]: the drive backend ([`motion_frames::backend::Backend`])
//! over the bus thread.
//!
//! `exchange` never waits for the bus: it publishes the commands into one
//! seqlock double buffer and copies the newest feedback out of the other
//! (bounded retries, no lock, no allocation). Feedback older than
//! [`STALE_CYCLES`] bus cycles (the bus thread is late or gone) is reported
//! with `SW_NO_DATA` on every axis.

use std::cell::RefCell;
use std::sync::atomic::Ordering;
use std::sync::mpsc;
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use motion_config::EthercatBus;
use motion_frames::backend::{Backend, ExchangeError, MAX_STOP_CYCLES};
use motion_frames::{CommandFrame, FeedbackFrame, SW_NO_DATA};
use motion_rt::now_ns;

use crate::bus;
use crate::report::{StartupError, StartupReport};
use crate::status::{BusStatus, Shared, SubDeviceHealth};
use crate::words::{self, FLAG_RUNNING, MODE_EMERGENCY, MODE_NORMAL, MODE_WATCHDOG_STOP};

/// Feedback older than this many bus cycles counts as missing.
pub const STALE_CYCLES: u64 = 3;
/// What a paced [`EthercatBackend::shutdown`] adds to the stop's own bound
/// (`quick_stop_timeout_ms` + the longest brake delay) before it falls back
/// to the emergency stop: the drives' answers to disable voltage.
pub const SHUTDOWN_MARGIN: Duration = Duration::from_millis(200);

/// The EtherCAT drive backend.
pub struct EthercatBackend {
    names: Vec<String>,
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
    report: StartupReport,
    cycle_ns: u64,
    generation: u64,
    mode: u64,
    cmd_words: Vec<u64>,
    fb_words: RefCell<Vec<u64>>,
    /// Bus cycle at which the current watchdog stop was asked for.
    stop_from_cycle: Option<u64>,
    /// The bounded stop, whole: quick stop bound + longest brake delay +
    /// [`SHUTDOWN_MARGIN`].
    stop_bound: Duration,
    /// The SubDevices that drive axes: position, name, axes.
    devices: Vec<(usize, String, Vec<String>)>,
}

impl EthercatBackend {
    /// Starts the bus thread and brings every SubDevice to OP (blocking, up
    /// to the start-up timeout). Errors name the SubDevice and the object or
    /// state that failed. `cfg` was checked when the config was parsed.
    pub fn new(cfg: EthercatBus) -> Result<EthercatBackend, StartupError> {
        let n = cfg.axes.len();
        let names = cfg.axes.iter().map(|a| a.name.clone()).collect();
        let shared = Arc::new(Shared::new(n));
        let cycle_ns = cfg.cycle().as_nanos() as u64;
        let brake = cfg.axes.iter().map(|a| a.ethercat.brake_delay_ms).max();
        let stop_bound = Duration::from_millis(u64::from(
            cfg.keys.quick_stop_timeout_ms + brake.unwrap_or(0),
        )) + SHUTDOWN_MARGIN;
        let (tx, rx) = mpsc::channel();
        let thread = {
            let shared = shared.clone();
            std::thread::Builder::new()
                .name("ecat-bus".into())
                .stack_size(4 << 20)
                .spawn(move || bus::thread_main(cfg, shared, tx))
                .map_err(|e| StartupError(format!("cannot start the bus thread: {e}")))?
        };
        match rx.recv() {
            Ok(Ok(report)) => Ok(EthercatBackend {
                devices: devices_of(&report),
                stop_bound,
                names,
                shared,
                thread: Some(thread),
                report,
                cycle_ns,
                generation: 0,
                mode: MODE_NORMAL,
                cmd_words: vec![0; words::len(n)],
                fb_words: RefCell::new(vec![0; words::len(n)]),
                stop_from_cycle: None,
            }),
            Ok(Err(e)) => {
                let _ = thread.join();
                Err(e)
            }
            Err(_) => {
                let _ = thread.join();
                Err(StartupError("the bus thread ended during start-up".into()))
            }
        }
    }

    /// What start-up found and did (SubDevices, DC or free run, warnings).
    pub fn report(&self) -> &StartupReport {
        &self.report
    }

    /// Counters and round-trip statistics.
    pub fn bus_status(&self) -> BusStatus {
        self.shared.snapshot()
    }

    /// How the SubDevices that drive axes are doing (off the bus thread;
    /// allocates). Poll [`health_events`](Self::health_events) to know when
    /// it changed.
    pub fn health(&self) -> Vec<SubDeviceHealth> {
        self.shared.health(&self.devices)
    }

    /// Bumped on every change of a SubDevice's health.
    pub fn health_events(&self) -> u64 {
        self.shared.health_events.load(Ordering::Acquire)
    }

    /// A handle that reads the SubDevices' health from another thread
    /// (motion-io's log).
    pub fn health_watch(&self) -> HealthWatch {
        HealthWatch {
            shared: self.shared.clone(),
            devices: self.devices.clone(),
        }
    }

    /// The bounded stop, whole (the shutdown's bound before its fallback).
    pub fn stop_bound(&self) -> Duration {
        self.stop_bound
    }

    fn publish(&mut self) {
        self.generation += 1;
        self.cmd_words[0] = self.generation;
        self.cmd_words[1] = self.mode;
        self.shared.commands.write(&self.cmd_words);
    }

    /// Reads the feedback; returns (bus cycle, at-rest mask, fresh).
    fn read_feedback(&self, fb: &mut FeedbackFrame) -> (u64, u64, bool) {
        let n = self.names.len();
        let mut words = self.fb_words.borrow_mut();
        let ok = self.shared.feedback.read(&mut words);
        let age = now_ns().saturating_sub(words[1]);
        let fresh = ok && words[2] & FLAG_RUNNING != 0 && age <= STALE_CYCLES * self.cycle_ns;
        for i in 0..n {
            let mut a = words::feedback(&words, i);
            if !fresh {
                a.status_word |= SW_NO_DATA;
                self.shared.axis[i].stale.fetch_add(1, Ordering::Relaxed);
            }
            fb.axes[i] = a;
        }
        fb.header.axis_count = n as u32;
        (words[0], words[3], fresh)
    }

    /// Stops the bus thread: SAFE-OP (the drives stop on their own ramps),
    /// PRE-OP, INIT. Also done on drop.
    pub fn close(mut self) {
        self.stop_thread();
    }

    fn stop_thread(&mut self) {
        self.shared.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Backend for EthercatBackend {
    fn name(&self) -> &str {
        "ethercat"
    }

    fn axis_count(&self) -> usize {
        self.names.len()
    }

    fn axis_names(&self) -> Vec<String> {
        self.names.clone()
    }

    /// Hands `cmd` to the bus thread and fills `fb` with the newest
    /// feedback. Never waits for the bus.
    fn apply(&mut self, cmd: &CommandFrame, fb: &mut FeedbackFrame) -> Result<(), ExchangeError> {
        for (i, c) in cmd.axes[..self.names.len()].iter().enumerate() {
            words::put_command(&mut self.cmd_words, i, c);
        }
        self.cmd_words[2] = cmd.header.sequence;
        self.mode = MODE_NORMAL;
        self.stop_from_cycle = None;
        self.publish();
        self.status(fb);
        Ok(())
    }

    /// Fills `fb` with the current state without changing anything.
    fn status(&self, fb: &mut FeedbackFrame) {
        self.read_feedback(fb);
    }

    /// Commands have stopped: every enabled axis quick-stops on its drive's
    /// ramp, is then disabled and reports a fault. `true` once every axis is
    /// at rest and disabled (as seen by a bus cycle after the request).
    fn watchdog_stop(&mut self, _dt_s: f64, fb: &mut FeedbackFrame) -> bool {
        if self.mode != MODE_WATCHDOG_STOP {
            self.mode = MODE_WATCHDOG_STOP;
            self.publish();
        }
        let (cycle, rest, fresh) = self.read_feedback(fb);
        let from = *self.stop_from_cycle.get_or_insert(cycle);
        let all = if self.names.len() >= 64 {
            u64::MAX
        } else {
            (1u64 << self.names.len()) - 1
        };
        fresh && cycle > from + 1 && rest & all == all
    }

    /// Immediate stop: "disable voltage" on every axis (no ramp), a fault
    /// reported. Waits up to three bus cycles for the bus to apply it.
    fn emergency_stop(&mut self, fb: &mut FeedbackFrame) {
        self.mode = MODE_EMERGENCY;
        self.publish();
        let (first, _, _) = self.read_feedback(fb);
        let until = now_ns() + 3 * self.cycle_ns;
        while now_ns() < until {
            std::thread::sleep(Duration::from_nanos(self.cycle_ns / 4));
            let (c, _, _) = self.read_feedback(fb);
            if c > first + 1 {
                break;
            }
        }
    }

    /// Controlled stop of every axis, paced by the bus cycle, at most the
    /// bounded stop's own bound ([`stop_bound`](Self::stop_bound); or
    /// [`MAX_STOP_CYCLES`] of `dt_s`, the smaller); falls back to
    /// [`emergency_stop`](Self::emergency_stop). Axes of lost SubDevices do
    /// not hold it up. `true` if the controlled stop completed. The bus
    /// keeps running (drives disabled) until the backend is dropped, which
    /// leaves OP within `bus::EXIT_TIMEOUT_NS`.
    fn shutdown(&mut self, dt_s: f64, fb: &mut FeedbackFrame) -> bool {
        let pace = Duration::from_nanos(self.cycle_ns);
        let by_dt = if dt_s.is_finite() && dt_s > 0.0 {
            Duration::from_secs_f64(
                (dt_s * f64::from(MAX_STOP_CYCLES)).min(self.stop_bound.as_secs_f64()),
            )
        } else {
            self.stop_bound
        };
        let until = now_ns() + by_dt.min(self.stop_bound).as_nanos() as u64;
        while now_ns() < until {
            if self.watchdog_stop(dt_s, fb) {
                return true;
            }
            std::thread::sleep(pace);
        }
        self.emergency_stop(fb);
        false
    }
}

impl Drop for EthercatBackend {
    fn drop(&mut self) {
        self.stop_thread();
    }
}

/// The SubDevices that drive axes: position, name, the axes.
fn devices_of(r: &StartupReport) -> Vec<(usize, String, Vec<String>)> {
    r.subdevices
        .iter()
        .filter_map(|s| {
            s.axis
                .as_ref()
                .map(|a| (s.position, s.name.clone(), vec![a.clone()]))
        })
        .collect()
}

/// Reads the SubDevices' health from any thread (see
/// [`EthercatBackend::health_watch`]).
#[derive(Clone)]
pub struct HealthWatch {
    shared: Arc<Shared>,
    devices: Vec<(usize, String, Vec<String>)>,
}

impl HealthWatch {
    /// Bumped on every change of a SubDevice's health.
    pub fn events(&self) -> u64 {
        self.shared.health_events.load(Ordering::Acquire)
    }

    /// How the SubDevices that drive axes are doing.
    pub fn health(&self) -> Vec<SubDeviceHealth> {
        self.shared.health(&self.devices)
    }

    /// The bus thread still runs.
    pub fn running(&self) -> bool {
        self.shared.running.load(Ordering::Acquire)
    }
}
