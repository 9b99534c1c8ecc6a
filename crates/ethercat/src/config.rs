//! The backend's configuration (what motion-io fills from `--interface` and
//! the `[[io]]` section; see the crate README for the proposed keys).

use std::fmt;
use std::time::Duration;

/// How an axis finds its SubDevice.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SubDeviceSelector {
    /// Position in the bus (0 = the first SubDevice after the master).
    Position(u16),
    /// The SubDevice's name (SII order/name string); must be unique.
    Name(String),
}

impl fmt::Display for SubDeviceSelector {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SubDeviceSelector::Position(p) => write!(f, "position {p}"),
            SubDeviceSelector::Name(n) => write!(f, "name {n:?}"),
        }
    }
}

/// One axis of the supervisor's config, in frame order.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisMapping {
    /// Axis name (messages).
    pub name: String,
    pub subdevice: SubDeviceSelector,
    /// The axis' counts per position unit. The frames already carry counts
    /// and the drive's counts are taken to be the same counts (positions
    /// 0x607A/0x6064/0x60BA.. and velocity 0x606C in counts, counts/s), so
    /// the backend passes them through unchanged; this value is only used
    /// for messages in position units.
    pub counts_per_unit: f64,
    /// Manufacturer-specific bit of 0x60FD (16..=31) that reports "an
    /// index pulse passed during the last cycle", for axes configured with
    /// `marker_latch = false`; `None` (default): not reported.
    pub index_pulse_bit: Option<u8>,
}

impl AxisMapping {
    /// An axis on `subdevice` without an index-pulse input.
    pub fn new(name: &str, subdevice: SubDeviceSelector, counts_per_unit: f64) -> AxisMapping {
        AxisMapping {
            name: name.to_string(),
            subdevice,
            counts_per_unit,
            index_pulse_bit: None,
        }
    }
}

/// Distributed clocks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DcMode {
    /// SYNC0 on every mapped SubDevice that supports it, free run on the
    /// others.
    #[default]
    Auto,
    /// SYNC0 on every mapped SubDevice; one without DC is a start-up error.
    On,
    /// Free run everywhere.
    Off,
}

impl DcMode {
    /// `"auto"`, `"on"`, `"off"` (config spelling).
    pub fn parse(s: &str) -> Option<DcMode> {
        match s {
            "auto" => Some(DcMode::Auto),
            "on" => Some(DcMode::On),
            "off" => Some(DcMode::Off),
            _ => None,
        }
    }
}

/// Everything the backend needs.
#[derive(Clone, Debug, PartialEq)]
pub struct EthercatConfig {
    /// Network interface of the EtherCAT segment (`eth1`).
    pub interface: String,
    /// Bus cycle = the supervisor's cycle.
    pub cycle: Duration,
    /// Axes in frame order.
    pub axes: Vec<AxisMapping>,
    pub dc: DcMode,
    /// SyncManager watchdog of the drives (0x0400 / 0x0420): outputs are
    /// dropped and the drives stop this long after the last process data.
    pub sm_watchdog: Duration,
    /// SCHED_FIFO priority of the bus thread.
    pub priority: i32,
    /// CPU to pin the bus thread to.
    pub cpu: Option<usize>,
    /// Lock memory (`mlockall`) from the bus thread.
    pub lock_memory: bool,
    /// Map 0x6060 into the RxPDO as well (some drives want the mode cyclic).
    pub mode_in_pdo: bool,
    /// Longest wait for a cycle's frame; later answers count as lost.
    /// Default: 90 % of the cycle.
    pub reply_timeout: Option<Duration>,
    /// Start-up (INIT → OP) time limit.
    pub startup_timeout: Duration,
    /// FRMW rounds of DC static drift compensation at start-up.
    pub dc_static_sync_iterations: u32,
}

impl EthercatConfig {
    /// Defaults for everything but interface, cycle and axes: DC auto,
    /// 50 ms SM watchdog, FIFO 70, memory locked, 30 s start-up.
    pub fn new(interface: &str, cycle: Duration, axes: Vec<AxisMapping>) -> EthercatConfig {
        EthercatConfig {
            interface: interface.to_string(),
            cycle,
            axes,
            dc: DcMode::Auto,
            sm_watchdog: Duration::from_millis(50),
            priority: 70,
            cpu: None,
            lock_memory: true,
            mode_in_pdo: false,
            reply_timeout: None,
            startup_timeout: Duration::from_secs(30),
            dc_static_sync_iterations: 1000,
        }
    }

    /// The reply deadline in force.
    pub fn reply_timeout(&self) -> Duration {
        self.reply_timeout.unwrap_or(self.cycle * 9 / 10)
    }

    /// Problems with the values, one line each (empty: fine).
    pub fn problems(&self) -> Vec<String> {
        let mut p = Vec::new();
        if self.interface.is_empty() {
            p.push("interface: empty".to_string());
        }
        if self.cycle < Duration::from_micros(100) || self.cycle > Duration::from_millis(100) {
            p.push(format!(
                "cycle: {} us outside 100..=100000 us",
                self.cycle.as_micros()
            ));
        }
        if self.axes.is_empty() {
            p.push("axes: none".to_string());
        }
        if self.axes.len() > crate::bus::MAX_SUBDEVICES {
            p.push(format!(
                "axes: {} > {} supported",
                self.axes.len(),
                crate::bus::MAX_SUBDEVICES
            ));
        }
        for (i, a) in self.axes.iter().enumerate() {
            for b in &self.axes[..i] {
                if a.subdevice == b.subdevice {
                    p.push(format!(
                        "axis {}: {} already used by axis {}",
                        a.name, a.subdevice, b.name
                    ));
                }
            }
            if !(a.counts_per_unit.is_finite() && a.counts_per_unit > 0.0) {
                p.push(format!("axis {}: counts_per_unit must be > 0", a.name));
            }
            if a.index_pulse_bit.is_some_and(|b| !(16..=31).contains(&b)) {
                p.push(format!(
                    "axis {}: index_pulse_bit must be a manufacturer-specific bit 16..=31",
                    a.name
                ));
            }
        }
        let wd_units = self.sm_watchdog.as_micros() / 100;
        if wd_units == 0 || wd_units > u128::from(u16::MAX) {
            p.push(format!(
                "sm_watchdog: {} ms outside 0.1..=6553 ms",
                self.sm_watchdog.as_millis()
            ));
        } else if self.sm_watchdog < self.cycle * 3 {
            p.push(format!(
                "sm_watchdog: {} us shorter than 3 cycles",
                self.sm_watchdog.as_micros()
            ));
        }
        if !(1..=99).contains(&self.priority) {
            p.push(format!("priority: {} outside 1..=99", self.priority));
        }
        p
    }
}
