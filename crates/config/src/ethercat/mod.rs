//! The EtherCAT configuration, defined once: the `[[io]]` keys of an I/O
//! process with `backend = "ethercat"` ([`EthercatIo`]), the keys of its
//! axes ([`AxisEthercat`]), and what the bus of one such process runs with
//! ([`EthercatBus`]: those keys, the cycle, the axes on the bus, the bus
//! thread's placement).
//!
//! `motion-ethercat` takes an [`EthercatBus`] as it is: every check (key
//! ranges, a watchdog of at least three cycles, a reply deadline inside the
//! cycle, a bus cycle the backend runs, one drive per axis, at most
//! [`ETHERCAT_MAX_AXES`](crate::limits::ETHERCAT_MAX_AXES) axes) is made
//! here, while the file is parsed, and reported by I/O process or axis and
//! key like every other configuration problem.
//!
//! * `parse` — reading and checking the keys;
//! * `bus` — [`EthercatBus`] for one I/O process (`motion-io --backend
//!   ethercat`), with `--interface` and the bus thread's CPU and priority;
//! * `needs` — what each axis's configuration needs of its drive
//!   ([`AxisNeeds`]), which the backend checks at start-up;
//! * `homing` — the CiA 402 homing method of a sequence the drive homes.

mod bus;
pub mod homing;
mod needs;
pub(crate) mod parse;

pub use bus::{BusAxis, EthercatBus, DEFAULT_BUS_PRIORITY};
pub use needs::{AxisNeeds, DriveHomingPlan};

/// Distributed clocks of an EtherCAT I/O process (`[[io]] dc`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EthercatDc {
    /// SYNC0 where the drive supports it, free run elsewhere.
    #[default]
    Auto,
    /// SYNC0 on every drive; one without DC is a start-up error.
    On,
    /// Free run everywhere.
    Off,
}

motion_homing::spellings!(EthercatDc {
    Auto => "auto",
    On => "on",
    Off => "off",
});

/// `[[io]] dc`.
pub const DC_MODES: &[(&str, EthercatDc)] = EthercatDc::NAMES;

/// The `[[io]]` keys of an I/O process with `backend = "ethercat"`
/// (declared, with their ranges and defaults, in [`crate::keytable::ethercat`]).
#[derive(Clone, Debug, PartialEq)]
pub struct EthercatIo {
    /// Network interface of the EtherCAT segment (`motion-io --interface`
    /// overrides it).
    pub interface: String,
    pub dc: EthercatDc,
    /// SyncManager watchdog of the drives: they stop this long after the
    /// last process data (a dead `motion-io`).
    pub sm_watchdog_ms: u32,
    /// A bus frame answered later than this counts as lost; `None`: 90 % of
    /// the cycle.
    pub reply_timeout_us: Option<u32>,
    /// INIT → OP limit.
    pub startup_timeout_s: u32,
    /// Also map 0x6060 (modes of operation) into the RxPDO.
    pub mode_in_pdo: bool,
    /// Rounds of the distributed clocks' static drift compensation.
    pub dc_static_sync_iterations: u32,
    /// The watchdog's and the shutdown's stop: a drive gets quick stop for
    /// at most this long (less once it is at rest, none if it ignores quick
    /// stop), then disable voltage (Switch on disabled, power stage off).
    pub quick_stop_timeout_ms: u32,
}

/// How an axis of an EtherCAT I/O process finds its drive.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum EthercatDrive {
    /// `ethercat_position`: position on the bus (0 = first after the master).
    Position(u16),
    /// `ethercat_name`: the SubDevice's name (SII name; unique on the bus).
    Name(String),
}

/// The EtherCAT keys of an `[[axis]]`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AxisEthercat {
    pub drive: EthercatDrive,
    /// `ethercat_index_pulse_bit`: manufacturer bit (16..=31) of 0x60FD
    /// that reports an index pulse per cycle (`marker_latch = false` axes).
    pub index_pulse_bit: Option<u8>,
    /// `ethercat_home_switch_bit`: manufacturer bit (16..=31) of 0x60FD
    /// wired to the home switch, instead of bit 2.
    pub home_switch_bit: Option<u8>,
    /// `ethercat_brake_delay_ms`: the axis has a holding brake the drive
    /// controls (a vertical axis); every stop ends with disable operation,
    /// this long with the power stage on while the brake closes, then
    /// disable voltage. 0: no brake.
    pub brake_delay_ms: u32,
    /// `drive_homing` / `drive_homing_method`: the drive homes the axis
    /// itself (CiA 402 mode 6) with this method — the given one, else the
    /// standard method of the sequence ([`homing::standard_method`]).
    pub drive_homing_method: Option<i8>,
}

#[cfg(test)]
mod tests;
