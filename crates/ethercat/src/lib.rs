//! `motion-ethercat`: the EtherCAT drive backend of `motion-io`.
//!
//! ethercrab's `MainDevice` runs on its own real-time thread ([`bus`]) that
//! cycles the process data at the supervisor's cycle; [`EthercatBackend`]
//! offers exactly the methods of motion-io's `Backend` trait on top of it.
//!
//! * [`cia402`] — the master-side CiA 402 state machine (pure, sans-I/O).
//! * [`pdo`] — the RxPDO / TxPDO layout and the process-image packing.
//! * [`probe`] — touch probes behind the frames' latch ids.
//! * [`axis`] — one axis per cycle: command + inputs → outputs + feedback.
//! * [`startup`] — INIT → OP: PDO mapping over CoE, CSP, DC, SM watchdog.
//! * [`shared`] — the lock-free double buffer between `motion-io` and the
//!   bus thread; [`status`] — counters.
//! * [`io`] — raw socket and the bus thread's executor.

pub mod axis;
pub mod backend;
pub mod bus;
pub mod cia402;
pub mod config;
pub mod io;
pub mod pdo;
pub mod probe;
pub mod shared;
pub mod startup;
pub mod status;

pub use backend::{EthercatBackend, ExchangeError, STALE_CYCLES};
pub use config::{AxisMapping, DcMode, EthercatConfig, SubDeviceSelector};
pub use startup::{StartupError, StartupReport, SubDeviceReport, SyncMode};
pub use status::{AxisStatus, BusStatus, RoundTrip};
