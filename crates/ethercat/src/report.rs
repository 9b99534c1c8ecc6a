//! What start-up tells the operator: the report of a bus that reached OP
//! ([`StartupReport`], one [`SubDeviceReport`] per SubDevice) or why it did
//! not ([`StartupError`]).

use std::fmt;
use std::time::Duration;

/// A start-up failure, in words for the operator.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StartupError(pub String);

impl fmt::Display for StartupError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for StartupError {}

/// A SubDevice as messages name it.
pub(crate) struct Sd<'a> {
    pub position: usize,
    pub name: &'a str,
}

impl Sd<'_> {
    pub fn err(&self, what: String) -> StartupError {
        StartupError(format!(
            "SubDevice {} ({}): {what}",
            self.position, self.name
        ))
    }
}

/// How a SubDevice is synchronised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SyncMode {
    /// Distributed clocks, SYNC0 = the bus cycle.
    Dc,
    /// Free run (frame-triggered).
    FreeRun,
}

impl fmt::Display for SyncMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SyncMode::Dc => "dc",
            SyncMode::FreeRun => "free-run",
        })
    }
}

/// One SubDevice found on the bus.
#[derive(Clone, Debug, PartialEq)]
pub struct SubDeviceReport {
    /// Position in the bus (0-based).
    pub position: usize,
    pub name: String,
    /// Configured station address.
    pub address: u16,
    pub vendor_id: u32,
    pub product_id: u32,
    pub revision: u32,
    pub serial: u32,
    /// Supports distributed clocks (SYNC0).
    pub dc_capable: bool,
    /// Name of the axis driven through it.
    pub axis: Option<String>,
    /// `Some` for mapped SubDevices.
    pub sync: Option<SyncMode>,
    /// 0x1008 as read over CoE (normal / segmented upload), if present.
    pub device_name: Option<String>,
    /// Output / input bytes of its process data.
    pub output_bytes: usize,
    pub input_bytes: usize,
    /// Its set-up for the log: the mapping in force (objects, offsets,
    /// bits), sync mode and cycle, SM watchdog, stop, brake, homing, and
    /// what is unavailable.
    pub lines: Vec<String>,
}

impl fmt::Display for SubDeviceReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "SubDevice {} ({}) at {:#06x}: vendor {:#010x} product {:#010x} rev {} serial {}, \
             {} B out / {} B in",
            self.position,
            self.name,
            self.address,
            self.vendor_id,
            self.product_id,
            self.revision,
            self.serial,
            self.output_bytes,
            self.input_bytes
        )?;
        if let (Some(axis), Some(sync)) = (&self.axis, self.sync) {
            write!(f, ", axis {axis}, {sync}")?;
        }
        Ok(())
    }
}

/// What start-up found and did.
#[derive(Clone, Debug, PartialEq)]
pub struct StartupReport {
    pub subdevices: Vec<SubDeviceReport>,
    /// Per axis (frame order): the SubDevice position and its sync mode.
    pub axes: Vec<(usize, SyncMode)>,
    /// Real-time set-up of the bus thread, as applied.
    pub rt: String,
    /// Things that work but are worth saying (not-permitted RT settings, a
    /// missing optional object).
    pub warnings: Vec<String>,
    /// INIT → OP.
    pub duration: Duration,
}
