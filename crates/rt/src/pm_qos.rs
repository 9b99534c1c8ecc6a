//! CPU idle-state latency: `/dev/cpu_dma_latency`.
//!
//! Waking a CPU from a deep idle state costs tens of microseconds (on this
//! project's VM it is the difference between a 14 µs and a 45 µs median
//! wake-up). Linux honours a PM QoS request written to
//! `/dev/cpu_dma_latency` for as long as the file stays open: 0 keeps every
//! CPU in its shallowest idle state. cyclictest does exactly this by default,
//! so a fair comparison — and a real controller — does it too.

use std::fs::{File, OpenOptions};
use std::io::Write;

/// Keeps the PM QoS request alive; dropping it releases it.
#[derive(Debug)]
pub struct DmaLatencyGuard {
    _file: File,
    /// The requested maximum wake-up latency, µs.
    pub us: i32,
}

/// Requests that no CPU enters an idle state with an exit latency above
/// `us` microseconds, for as long as the guard lives. An error is a warning
/// for the operator (naming the file, the errno and the fix), never fatal.
pub fn hold_cpu_dma_latency(us: i32) -> Result<DmaLatencyGuard, String> {
    let path = "/dev/cpu_dma_latency";
    let mut f = OpenOptions::new().write(true).open(path).map_err(|e| {
        format!(
            "cpu idle latency: cannot open {path}: {e}; deep C-states stay allowed and add \
             their exit latency to every wake-up; fix: run as root or grant write access to \
             {path} (udev rule), or boot with processor.max_cstate=1"
        )
    })?;
    // The kernel takes a binary s32.
    f.write_all(&us.to_ne_bytes())
        .map_err(|e| format!("cpu idle latency: writing {us} to {path}: {e}"))?;
    Ok(DmaLatencyGuard { _file: f, us })
}
