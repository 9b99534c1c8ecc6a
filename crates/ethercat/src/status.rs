//! What the bus thread and `motion-io`'s thread share: the two process-image
//! buffers ([`SeqBuffer`]) and counters (relaxed atomics, written by one
//! thread, read by anyone), plus their public snapshots.

use std::fmt;
use std::sync::atomic::{AtomicBool, AtomicU16, AtomicU64, AtomicU8, Ordering};

use crate::capacity::MAX_SUBDEVICES;
use crate::shared::SeqBuffer;
use crate::words;

/// How a SubDevice that drives an axis is doing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Health {
    /// In OP, answering.
    #[default]
    Ok,
    /// It does not answer (cable, power, the SubDevice before it).
    NotAnswering,
    /// It answers but is out of OP (SM watchdog, AL error, a state change
    /// of its own); being brought back.
    NotOp,
    /// It was power-cycled (station address lost): being re-configured.
    PowerCycled,
    /// Re-configuring it failed: only a restart of motion-io brings it back.
    Failed,
}

impl Health {
    fn from_u8(v: u8) -> Health {
        match v {
            1 => Health::NotAnswering,
            2 => Health::NotOp,
            3 => Health::PowerCycled,
            4 => Health::Failed,
            _ => Health::Ok,
        }
    }

    fn to_u8(self) -> u8 {
        match self {
            Health::Ok => 0,
            Health::NotAnswering => 1,
            Health::NotOp => 2,
            Health::PowerCycled => 3,
            Health::Failed => 4,
        }
    }
}

/// One SubDevice's health, written by the bus thread.
pub(crate) struct SdAtomics {
    health: AtomicU8,
    /// AL status (low byte) as last seen; AL status code (0x0134).
    pub al_status: AtomicU8,
    pub al_code: AtomicU16,
    /// Times it was lost, came back to OP, was re-configured.
    pub losses: AtomicU64,
    pub returns: AtomicU64,
    pub reconfigured: AtomicU64,
}

impl SdAtomics {
    pub fn health(&self) -> Health {
        Health::from_u8(self.health.load(Ordering::Acquire))
    }

    pub fn set_health(&self, h: Health) {
        self.health.store(h.to_u8(), Ordering::Release);
    }
}

/// Round-trip histogram: 1 µs buckets up to this.
const HIST_US: usize = 10_000;

pub(crate) struct AxisAtomics {
    pub lost: AtomicU64,
    pub wkc: AtomicU64,
    pub not_op: AtomicU64,
    pub stale: AtomicU64,
    pub rejected: AtomicU64,
    pub window_writes: AtomicU64,
    pub gap_stops: AtomicU64,
    pub blind_stop_cycles: AtomicU64,
}

pub(crate) struct Shared {
    pub commands: SeqBuffer,
    pub feedback: SeqBuffer,
    pub stop: AtomicBool,
    pub running: AtomicBool,
    pub axis: Vec<AxisAtomics>,
    pub cycles: AtomicU64,
    pub lost_frames: AtomicU64,
    pub wkc_errors: AtomicU64,
    pub overruns: AtomicU64,
    pub late_frames: AtomicU64,
    pub recoveries: AtomicU64,
    pub recovery_failures: AtomicU64,
    pub command_read_failures: AtomicU64,
    pub frames_sent: AtomicU64,
    pub frames_received: AtomicU64,
    pub window_write_failures: AtomicU64,
    pub needs_restart: AtomicU64,
    /// Times the bus thread's own watchdog stopped the drives.
    pub bus_watchdog_trips: AtomicU64,
    /// Frames whose command had to be other than the next in the
    /// supervisor's sequence ([`crate::handoff`]).
    pub handoff_corrections: AtomicU64,
    /// Per bus position: the health of the SubDevices that drive axes.
    pub sd: Vec<SdAtomics>,
    /// Bumped on every change of a SubDevice's health (the log's cue).
    pub health_events: AtomicU64,
    /// Why re-configuring a SubDevice failed (per bus position), written
    /// by the bus thread before it sets `Health::Failed` (off the cycle:
    /// from the background job, which may allocate).
    pub failures: std::sync::Mutex<Vec<(usize, String)>>,
    /// System-allocator calls of the bus thread in the cycle loop after
    /// warm-up (only counted when motion_rt::RtAllocator is the global
    /// allocator).
    pub bus_allocations: AtomicU64,
    hist: Vec<AtomicU64>,
    hist_over: AtomicU64,
    rt_min: AtomicU64,
    rt_max: AtomicU64,
}

impl Shared {
    pub fn new(axes: usize) -> Shared {
        let words = words::len(axes);
        Shared {
            commands: SeqBuffer::new(words),
            feedback: SeqBuffer::new(words),
            stop: AtomicBool::new(false),
            running: AtomicBool::new(false),
            axis: (0..axes)
                .map(|_| AxisAtomics {
                    lost: AtomicU64::new(0),
                    wkc: AtomicU64::new(0),
                    not_op: AtomicU64::new(0),
                    stale: AtomicU64::new(0),
                    rejected: AtomicU64::new(0),
                    window_writes: AtomicU64::new(0),
                    gap_stops: AtomicU64::new(0),
                    blind_stop_cycles: AtomicU64::new(0),
                })
                .collect(),
            cycles: AtomicU64::new(0),
            lost_frames: AtomicU64::new(0),
            wkc_errors: AtomicU64::new(0),
            overruns: AtomicU64::new(0),
            late_frames: AtomicU64::new(0),
            recoveries: AtomicU64::new(0),
            recovery_failures: AtomicU64::new(0),
            command_read_failures: AtomicU64::new(0),
            frames_sent: AtomicU64::new(0),
            frames_received: AtomicU64::new(0),
            window_write_failures: AtomicU64::new(0),
            needs_restart: AtomicU64::new(0),
            bus_watchdog_trips: AtomicU64::new(0),
            handoff_corrections: AtomicU64::new(0),
            sd: (0..MAX_SUBDEVICES)
                .map(|_| SdAtomics {
                    health: AtomicU8::new(0),
                    al_status: AtomicU8::new(0),
                    al_code: AtomicU16::new(0),
                    losses: AtomicU64::new(0),
                    returns: AtomicU64::new(0),
                    reconfigured: AtomicU64::new(0),
                })
                .collect(),
            health_events: AtomicU64::new(0),
            failures: std::sync::Mutex::new(Vec::new()),
            bus_allocations: AtomicU64::new(0),
            hist: (0..HIST_US).map(|_| AtomicU64::new(0)).collect(),
            hist_over: AtomicU64::new(0),
            rt_min: AtomicU64::new(u64::MAX),
            rt_max: AtomicU64::new(0),
        }
    }

    /// Records one cycle's round trip (exchange start → data back).
    pub fn record_roundtrip(&self, ns: u64) {
        let us = (ns / 1000) as usize;
        match self.hist.get(us) {
            Some(b) => b.fetch_add(1, Ordering::Relaxed),
            None => self.hist_over.fetch_add(1, Ordering::Relaxed),
        };
        self.rt_min.fetch_min(ns, Ordering::Relaxed);
        self.rt_max.fetch_max(ns, Ordering::Relaxed);
    }

    fn percentile(&self, total: u64, q: f64) -> f64 {
        let want = ((total as f64) * q).ceil().max(1.0) as u64;
        let mut acc = 0;
        for (us, b) in self.hist.iter().enumerate() {
            acc += b.load(Ordering::Relaxed);
            if acc >= want {
                return us as f64 + 0.5;
            }
        }
        HIST_US as f64
    }

    pub fn snapshot(&self) -> BusStatus {
        let l = |a: &AtomicU64| a.load(Ordering::Relaxed);
        let total: u64 = self.hist.iter().map(l).sum::<u64>() + l(&self.hist_over);
        let roundtrip = if total == 0 {
            RoundTrip::default()
        } else {
            RoundTrip {
                samples: total,
                min_us: l(&self.rt_min) as f64 / 1000.0,
                p50_us: self.percentile(total, 0.5),
                p99_us: self.percentile(total, 0.99),
                p999_us: self.percentile(total, 0.999),
                max_us: l(&self.rt_max) as f64 / 1000.0,
            }
        };
        BusStatus {
            running: self.running.load(Ordering::Acquire),
            cycles: l(&self.cycles),
            lost_frames: l(&self.lost_frames),
            wkc_errors: l(&self.wkc_errors),
            overruns: l(&self.overruns),
            late_frames: l(&self.late_frames),
            recoveries: l(&self.recoveries),
            recovery_failures: l(&self.recovery_failures),
            needs_restart: l(&self.needs_restart),
            bus_watchdog_trips: l(&self.bus_watchdog_trips),
            handoff_corrections: l(&self.handoff_corrections),
            losses: self.sd.iter().map(|s| l(&s.losses)).sum(),
            returns: self.sd.iter().map(|s| l(&s.returns)).sum(),
            reconfigured: self.sd.iter().map(|s| l(&s.reconfigured)).sum(),
            bus_thread_allocations: l(&self.bus_allocations),
            command_read_failures: l(&self.command_read_failures),
            feedback_read_failures: self.feedback.read_failures(),
            frames_sent: l(&self.frames_sent),
            frames_received: l(&self.frames_received),
            window_write_failures: l(&self.window_write_failures),
            roundtrip,
            axes: self
                .axis
                .iter()
                .map(|a| AxisStatus {
                    no_data_lost_frame: l(&a.lost),
                    no_data_wkc: l(&a.wkc),
                    no_data_not_op: l(&a.not_op),
                    no_data_stale: l(&a.stale),
                    rejected_setpoints: l(&a.rejected),
                    following_window_writes: l(&a.window_writes),
                    gap_stops: l(&a.gap_stops),
                    blind_stop_cycles: l(&a.blind_stop_cycles),
                })
                .collect(),
        }
    }
}

/// One SubDevice that drives an axis, as its health stands (for the log).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SubDeviceHealth {
    pub position: usize,
    pub name: String,
    /// The axes it drives.
    pub axes: Vec<String>,
    pub health: Health,
    /// AL status (state nibble, 0 = did not answer) last seen, and the AL
    /// status code of its last acknowledged error.
    pub al_status: u8,
    pub al_code: u16,
    pub losses: u64,
    pub returns: u64,
    pub reconfigured: u64,
    /// Why re-configuring it failed.
    pub failure: Option<String>,
}

impl Shared {
    /// The health of the SubDevices at `positions` (named `names`, driving
    /// `axes`). Off the bus thread (allocates; reads the failure list with
    /// a lock the bus thread only ever tries).
    pub(crate) fn health(&self, who: &[(usize, String, Vec<String>)]) -> Vec<SubDeviceHealth> {
        let failures = self.failures.lock().map(|f| f.clone()).unwrap_or_default();
        who.iter()
            .map(|(p, name, axes)| {
                let sd = &self.sd[*p];
                SubDeviceHealth {
                    position: *p,
                    name: name.clone(),
                    axes: axes.clone(),
                    health: sd.health(),
                    al_status: sd.al_status.load(Ordering::Relaxed),
                    al_code: sd.al_code.load(Ordering::Relaxed),
                    losses: sd.losses.load(Ordering::Relaxed),
                    returns: sd.returns.load(Ordering::Relaxed),
                    reconfigured: sd.reconfigured.load(Ordering::Relaxed),
                    failure: failures
                        .iter()
                        .find(|(k, _)| k == p)
                        .map(|(_, w)| w.clone()),
                }
            })
            .collect()
    }
}

/// Per-axis counters: cycles reported with `SW_NO_DATA`, by cause (one
/// cause per cycle, in this priority: lost frame, SubDevice not in OP,
/// working counter), and refused set-points.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AxisStatus {
    /// The cycle's frame did not come back in time.
    pub no_data_lost_frame: u64,
    /// The working counter did not match (not attributable to a SubDevice
    /// that is known to be gone).
    pub no_data_wkc: u64,
    /// The SubDevice was not in OP (unplugged, SM watchdog, AL error).
    pub no_data_not_op: u64,
    /// `exchange` found no bus cycle newer than 3 cycles (bus thread late).
    pub no_data_stale: u64,
    pub rejected_setpoints: u64,
    /// SDO writes of 0x6065 (following error window) done.
    pub following_window_writes: u64,
    /// Its data came back after a loss over which the command ran away:
    /// the drive was stopped where it stood (the backend's fault), never
    /// jumped.
    pub gap_stops: u64,
    /// Cycles a stop was sent to its drive without its data.
    pub blind_stop_cycles: u64,
}

/// Round-trip statistics of the cyclic exchange (frame out → data back), µs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RoundTrip {
    pub samples: u64,
    pub min_us: f64,
    pub p50_us: f64,
    pub p99_us: f64,
    pub p999_us: f64,
    pub max_us: f64,
}

impl fmt::Display for RoundTrip {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} cycles: min {:.1} / p50 {:.1} / p99 {:.1} / p99.9 {:.1} / max {:.1} us",
            self.samples, self.min_us, self.p50_us, self.p99_us, self.p999_us, self.max_us
        )
    }
}

/// A snapshot of the bus.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BusStatus {
    /// The bus thread cycles process data.
    pub running: bool,
    pub cycles: u64,
    pub lost_frames: u64,
    pub wkc_errors: u64,
    /// Cycles whose exchange overran the cycle (deadlines skipped).
    pub overruns: u64,
    /// Answers that came after their cycle gave up on them.
    pub late_frames: u64,
    /// SubDevices brought back to OP.
    pub recoveries: u64,
    pub recovery_failures: u64,
    /// SubDevices given up on (re-configuring them failed): only a restart
    /// of the backend brings them back.
    pub needs_restart: u64,
    /// Times the bus thread's own watchdog stopped the drives (no command
    /// from motion-io within its bound).
    pub bus_watchdog_trips: u64,
    /// Frames that could not carry the command following the previous
    /// frame's in the supervisor's sequence (the clocks a cycle apart, or
    /// a stall): their target stepped by 0 or two cycles' travel.
    pub handoff_corrections: u64,
    /// Losses of SubDevices that drive axes (not answering, out of OP),
    /// returns to OP, and re-configurations after a power cycle.
    pub losses: u64,
    pub returns: u64,
    pub reconfigured: u64,
    /// System-allocator calls the bus thread made while cycling, after
    /// [`crate::bus::WARM_UP_CYCLES`] (counted only in a binary whose global
    /// allocator is `motion_rt::RtAllocator`; 0 otherwise).
    pub bus_thread_allocations: u64,
    pub command_read_failures: u64,
    pub feedback_read_failures: u64,
    pub frames_sent: u64,
    pub frames_received: u64,
    pub window_write_failures: u64,
    pub roundtrip: RoundTrip,
    pub axes: Vec<AxisStatus>,
}
