//! The cycle monitor's trips in the log. The cycle formats nothing: it
//! hands the trip over as data in the snapshot (the invariant, the value
//! against its bound, the stop's category, where it started), and this
//! thread writes one line per trip.

use crate::shared::Snapshot;
use motion_config::MachineConfig;
use motion_monitor::{Category, Trip};

/// Trips already logged, per axis (the monitor counts them).
pub(super) struct TripWatch {
    logged: Vec<u32>,
}

impl TripWatch {
    pub fn new(axes: usize) -> Self {
        Self {
            logged: vec![0; axes],
        }
    }

    /// Logs every trip since the last snapshot.
    pub fn watch(&mut self, m: &MachineConfig, snap: &Snapshot) {
        for (i, a) in m.axes.iter().enumerate() {
            let s = &snap.axes[i];
            let seen = &mut self.logged[i];
            if s.monitor_trips == *seen {
                continue;
            }
            let missed = s.monitor_trips.wrapping_sub(*seen).saturating_sub(1);
            *seen = s.monitor_trips;
            if let Some(t) = s.monitor {
                log::error!("axis {}: {}", a.name, describe(&t, missed));
            }
        }
    }
}

/// One trip in words.
pub fn describe(t: &Trip, missed: u32) -> String {
    let (err, exerr) = t.code();
    let unit = t.invariant.unit();
    let what = match t.invariant {
        motion_monitor::Invariant::Enable => format!(
            "the power stage was asked on without a request since it was taken away ({})",
            t.withdrawn.unwrap_or_default()
        ),
        motion_monitor::Invariant::NotFinite => {
            format!("a command that is not a number ({})", t.value)
        }
        motion_monitor::Invariant::SoftLimit => format!(
            "commanded {} {unit}, beyond the travel limit {} {unit}",
            t.value, t.bound
        ),
        inv => format!(
            "{inv} {} {unit} above its bound {} {unit}",
            t.value, t.bound
        ),
    };
    let stop = match t.category {
        Category::Stop1 => "stopped (category 1) from",
        Category::Stop0 => "power stage off (category 0) at",
    };
    let earlier = if missed > 0 {
        format!(" ({missed} earlier trip(s) reset in between)")
    } else {
        String::new()
    };
    format!(
        "the cycle monitor tripped, ERR {err} / EXERR {exerr}: {what}; {stop} raw position {}; \
         reset to clear{earlier}",
        t.from
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion_monitor::Invariant;

    #[test]
    fn a_trip_reads_as_the_invariant_the_values_and_the_stop() {
        let t = Trip {
            invariant: Invariant::Velocity,
            value: 7.0,
            bound: 5.0,
            at_ns: 1,
            category: Category::Stop1,
            from: 0.25,
            withdrawn: None,
        };
        assert_eq!(
            describe(&t, 0),
            "the cycle monitor tripped, ERR 1021 / EXERR 1: velocity 7 units/s above its bound \
             5 units/s; stopped (category 1) from raw position 0.25; reset to clear"
        );
        let e = Trip {
            invariant: Invariant::Enable,
            category: Category::Stop0,
            withdrawn: Some(motion_monitor::Withdrawn::DriveFault),
            ..t
        };
        assert!(describe(&e, 2).contains("since it was taken away (drive_fault)"));
        assert!(describe(&e, 2).contains("power stage off (category 0) at raw position 0.25"));
        assert!(describe(&e, 2).ends_with("(2 earlier trip(s) reset in between)"));
    }
}
