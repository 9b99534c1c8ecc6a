//! `motion-ethercat`: the EtherCAT drive backend of `motion-io`.
//!
//! ethercrab's `MainDevice` runs on its own real-time thread ([`bus`]) that
//! cycles the process data at the supervisor's cycle; [`EthercatBackend`]
//! implements the drive [`Backend`](motion_frames::backend::Backend) on top
//! of it. Its configuration is `motion_config`'s [`EthercatBus`], checked
//! when the config file was parsed.
//!
//! * [`cia402`] — the master-side CiA 402 state machine (pure, sans-I/O).
//! * [`pdo`] — the RxPDO / TxPDO layout and the process-image packing.
//! * [`probe`] — touch probes behind the frames' latch ids.
//! * [`axis`] — one axis per cycle: command + inputs → outputs + feedback;
//!   [`stop`] — the bounded stop; [`drive_homing`] — CiA 402 homing mode.
//! * [`startup`] — INIT → OP: discovery, the axes' SubDevices, process-data
//!   sizes, SM watchdog, DC; [`drive_setup`] — one drive over CoE
//!   ([`dictionary`] read, [`wants`] checked, [`mapping`] settled, CSP,
//!   homing parameters, sync); [`objects`] — the objects, named once;
//!   [`report`] — what start-up found or why it failed.
//! * [`bus`] — the bus thread; [`cycle`] — one bus cycle; [`handoff`] —
//!   which of the supervisor's commands each frame carries; [`health`] — who
//!   answers, who is lost; [`jobs`] — recovery, [`reconfigure`] (a
//!   power-cycled drive) and SDO writes between cycles; [`group`] — the
//!   SubDevice group in OP.
//! * [`shared`] — the lock-free double buffer between `motion-io` and the
//!   bus thread, [`words`] — its layout; [`status`] — counters.
//! * [`io`] — the bus thread's executor over [`socket`], the raw socket.
//! * [`capacity`] — the fixed capacities (SubDevices, process image, frames).
//! * [`scan`] — the bus as it is (`motion-io scan`) and a config skeleton.

pub mod axis;
pub mod backend;
pub mod bus;
pub mod capacity;
pub mod cia402;
pub mod cycle;
pub mod dictionary;
pub mod drive_homing;
pub mod drive_setup;
pub mod group;
pub mod handoff;
pub mod health;
pub mod io;
pub mod jobs;
pub mod mapping;
pub mod objects;
pub mod pdo;
pub mod probe;
pub mod reconfigure;
pub mod report;
pub mod scan;
pub mod shared;
pub mod socket;
pub mod startup;
pub mod status;
pub mod stop;
pub mod wants;
pub mod words;

pub use backend::{EthercatBackend, HealthWatch, STALE_CYCLES};
pub use motion_config::EthercatBus;
pub use report::{StartupError, StartupReport, SubDeviceReport, SyncMode};
pub use status::{AxisStatus, BusStatus, Health, RoundTrip, SubDeviceHealth};
