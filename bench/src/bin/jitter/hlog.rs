//! The interval log (`.hlog`): every slice's wake-up histogram in ns, tagged
//! by variant and timed from the bench's start, so that the raw
//! distributions can be re-plotted or merged differently later (HdrHistogram
//! tools read it) without running the bench again.

use crate::cli::Opts;
use crate::slices::Collected;
use hdrhistogram::Histogram;
use motion_bench::hist;
use motion_bench::host::Env;
use std::path::Path;
use std::time::{Duration, SystemTime};

/// Writes the slices of `c` to `path`, in the order they ran; `t0_wall` is
/// the bench's start.
pub fn write(
    path: &Path,
    o: &Opts,
    env: &Env,
    t0_wall: SystemTime,
    c: &Collected,
) -> Result<(), String> {
    let mut intervals: Vec<(&str, Duration, Duration, &Histogram<u64>)> = Vec::new();
    for s in &c.ours_ecat {
        intervals.push(("ours_ethercat", s.start, s.len, &s.wakeup));
    }
    for s in &c.ours64 {
        intervals.push(("ours_axes64", s.start, s.len, &s.wakeup));
    }
    for (i, s) in c.ours.iter().enumerate() {
        intervals.push(("ours", s.start, s.len, &s.wakeup));
        if let Some(c) = c.ct.get(i) {
            intervals.push(("cyclictest", c.start, c.len, &c.hdr));
        }
    }
    intervals.sort_by_key(|i| i.1);
    let comments = vec![
        format!(
            "motion-bench jitter: wake-up latency, ns; period {} us, SCHED_FIFO {} on CPU {}",
            o.period_us, o.priority, o.cpu
        ),
        "tags: ours = motion-supervisor run (wake-up), demo machine idle; ours_axes64 = the same with 64 axes homing in parallel again and again; ours_ethercat = the same with motion-io --backend ethercat (--ethercat), cyclictest = cyclictest (1 us bins, recorded at the bin's lower edge)".into(),
        format!("kernel {} ({})", env.kernel, env.preemption),
    ];
    hist::write_interval_log(path, &comments, t0_wall, &intervals)
}
