//! The latency plot (`.svg`): the wake-up histograms of every variant and of
//! cyclictest on one chart, like the OSADL / LinuxCNC plots, with the period
//! marked, so that the distributions are compared on the same axes.

use crate::cli::Opts;
use crate::summary::Summary;
use motion_bench::host::Env;
use motion_bench::svg::{self, Series};
use std::path::Path;

/// Writes the plot of `m` to `path`.
pub fn write(path: &Path, o: &Opts, env: &Env, m: &Summary) -> Result<(), String> {
    let title = format!(
        "Wake-up latency, period {} µs: motion-supervisor vs cyclictest, {:.0} s each",
        o.period_us, m.ours.secs
    );
    let sub1 = format!(
        "Linux {} · {} · {} CPUs",
        env.kernel, env.preemption, env.cpus
    );
    let sub2 = format!(
        "both SCHED_FIFO {} on CPU {} · {} · {}",
        o.priority,
        o.cpu,
        if o.stress {
            "stress-ng on the other CPU"
        } else {
            "no load"
        },
        if m.ct.ran() {
            "cyclictest in 1 µs bins"
        } else {
            "cyclictest not run"
        }
    );
    let mut series = vec![Series {
        name: "ours, demo machine (idle)",
        colour: "#1f6fd1",
        hist: &m.ours.wake,
    }];
    if m.axes64.ran() {
        series.push(Series {
            name: "ours, 64 axes homing",
            colour: "#9467bd",
            hist: &m.axes64.wake,
        });
    }
    if m.ecat.ran() {
        series.push(Series {
            name: "ours, EtherCAT backend",
            colour: "#2ca02c",
            hist: &m.ecat.wake,
        });
    }
    if m.ct.ran() {
        series.push(Series {
            name: "cyclictest",
            colour: "#d62728",
            hist: &m.ct.hdr,
        });
    }
    let plot = svg::latency_plot(
        &title,
        &[&sub1, &sub2],
        &series,
        Some(f64::from(o.period_us)),
    );
    std::fs::write(path, plot).map_err(|e| format!("cannot write {}: {e}", path.display()))
}
