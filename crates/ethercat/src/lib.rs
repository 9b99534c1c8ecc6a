//! `motion-ethercat`: the EtherCAT drive backend of `motion-io`.
//!
//! * [`cia402`] — the master-side CiA 402 state machine (pure, sans-I/O).
//! * [`pdo`] — the RxPDO / TxPDO layout and the process-image packing.
//! * [`probe`] — touch probes behind the frames' latch ids.
//! * [`shared`] — the lock-free double buffer between `motion-io` and the
//!   bus thread.

pub mod cia402;
pub mod pdo;
pub mod probe;
pub mod shared;
