//! `status --json`: the live state of every axis and I/O process, as the
//! status service publishes it. An axis row ([`AxisStatus`]) is generated
//! from the status table (`motion_status::axis`): a field per row, named as
//! the row, under the row's JSON key; an I/O process row ([`IoStatus`]) and
//! the stream's intake ([`StreamIntake`]) are `motion-status`'s one
//! declaration of those counters.

use serde::{Deserialize, Serialize};

pub use motion_status::{AxisStatus, IoStatus, StreamCounts as StreamIntake};

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StatusReport {
    /// Cycle counter and cycle period of the supervisor.
    pub cycle: u64,
    pub cycle_us: u32,
    /// Milliseconds since the supervisor started.
    pub uptime_ms: u64,
    pub axes: Vec<AxisStatus>,
    pub io: Vec<IoStatus>,
    /// The setpoint stream's intake: frames, setpoints, refusals by kind.
    #[serde(default)]
    pub stream: StreamIntake,
}
