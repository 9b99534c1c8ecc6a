//! cyclictest, the reference the jitter bench measures the cycle against:
//! its command line for one thread, and its histogram file (`-h MAXUS
//! --histfile=FILE`): one line per 1 µs bin `NNNNNN CCCCCC`, then `# Total:`,
//! `# Min Latencies:`, `# Avg Latencies:`, `# Max Latencies:`, `# Histogram
//! Overflows:` (samples at or above MAXUS, not in any bin).

use crate::proc::{tail, Ended};
use hdrhistogram::Histogram;
use std::path::Path;
use std::process::Command;

/// One thread, `loops` periods of `period_us` (`-l`, since `-D` takes whole
/// seconds only), SCHED_FIFO `priority` on `cpu`, memory locked, quiet, a
/// histogram of `hist_max_us` 1 µs bins: the arguments as the report shows
/// them (the histogram file's name left out, see [`command`]).
pub fn args(priority: i32, cpu: usize, period_us: u32, loops: u64, hist_max_us: u64) -> String {
    format!("-m -p {priority} -t 1 -a {cpu} -i {period_us} -l {loops} -q -h {hist_max_us}")
}

/// `BIN ARGS --histfile=HIST`.
pub fn command(bin: &Path, args: &str, hist: &Path) -> Command {
    let mut cmd = Command::new(bin);
    cmd.args(args.split(' '))
        .arg(format!("--histfile={}", hist.display()));
    cmd
}

/// A histogram file, read.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CtHistogram {
    /// (latency µs, samples) of every non-empty bin.
    pub bins: Vec<(u64, u64)>,
    pub total: u64,
    pub min_us: u64,
    pub avg_us: u64,
    pub max_us: u64,
    pub overflows: u64,
}

fn summary_value(line: &str, key: &str) -> Option<u64> {
    let rest = line.strip_prefix(key)?;
    rest.split_whitespace().next()?.parse().ok()
}

/// Parses the histogram file of a one-thread run.
pub fn parse(text: &str) -> Result<CtHistogram, String> {
    let mut h = CtHistogram::default();
    let mut saw_total = false;
    for line in text.lines() {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        if let Some(rest) = line.strip_prefix('#') {
            let rest = rest.trim();
            if let Some(v) = summary_value(rest, "Total:") {
                h.total = v;
                saw_total = true;
            } else if let Some(v) = summary_value(rest, "Min Latencies:") {
                h.min_us = v;
            } else if let Some(v) = summary_value(rest, "Avg Latencies:") {
                h.avg_us = v;
            } else if let Some(v) = summary_value(rest, "Max Latencies:") {
                h.max_us = v;
            } else if let Some(v) = summary_value(rest, "Histogram Overflows:") {
                h.overflows = v;
            }
            continue;
        }
        let mut it = line.split_whitespace();
        let (Some(bin), Some(count)) = (it.next(), it.next()) else {
            return Err(format!("unexpected line {line:?}"));
        };
        let bin: u64 = bin.parse().map_err(|_| format!("bad bin in {line:?}"))?;
        let count: u64 = count
            .parse()
            .map_err(|_| format!("bad count in {line:?}"))?;
        if count > 0 {
            h.bins.push((bin, count));
        }
    }
    if !saw_total {
        return Err("no '# Total:' line (cyclictest did not finish its histogram)".into());
    }
    Ok(h)
}

/// Reads one finished run: its exit and its histogram file; errors carry
/// the end of its output.
pub fn read_run(ended: &Ended, hist_path: &Path) -> Result<CtHistogram, String> {
    let out = format!("{}\n{}", ended.stdout.trim(), ended.stderr.trim());
    let out = match out.trim() {
        "" => String::new(),
        e => format!("; its output: {}", tail(e, 8)),
    };
    if !ended.success() {
        return Err(format!("{}{out}", ended.describe()));
    }
    let text = std::fs::read_to_string(hist_path)
        .map_err(|e| format!("no histogram file {} ({e}){out}", hist_path.display()))?;
    let hist = parse(&text)?;
    match hist.samples() {
        0 => Err(format!("an empty histogram{out}")),
        _ => Ok(hist),
    }
}

impl CtHistogram {
    /// Samples in bins plus overflows.
    pub fn samples(&self) -> u64 {
        self.bins.iter().map(|b| b.1).sum::<u64>() + self.overflows
    }

    /// Samples of `period_us` or more (overflows count if the max does).
    pub fn at_or_above(&self, period_us: u64) -> u64 {
        let binned: u64 = self
            .bins
            .iter()
            .filter(|b| b.0 >= period_us)
            .map(|b| b.1)
            .sum();
        binned
            + if self.max_us >= period_us {
                self.overflows
            } else {
                0
            }
    }

    /// Records its samples into `h` (ns). A bin `v` holds latencies in
    /// [v, v+1) µs (cyclictest truncates); it is recorded at v µs, as
    /// cyclictest reports it. Overflows are recorded at the run's max (an
    /// upper bound).
    pub fn record_into(&self, h: &mut Histogram<u64>) {
        for &(us, n) in &self.bins {
            h.saturating_record_n(us * 1000, n);
        }
        if self.overflows > 0 {
            h.saturating_record_n(self.max_us * 1000, self.overflows);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SAMPLE: &str = "# Histogram\n000000 000000\n000012 000002\n000013 000003\n\
        000999 000001\n# Total: 000000007\n# Min Latencies: 00012\n# Avg Latencies: 00025\n\
        # Max Latencies: 01500\n# Histogram Overflows: 00001\n\
        # Histogram Overflow at cycle number:\n# Thread 0: 00042\n";

    #[test]
    fn parses_bins_and_summary() {
        let h = parse(SAMPLE).unwrap();
        assert_eq!(h.bins, vec![(12, 2), (13, 3), (999, 1)]);
        assert_eq!((h.total, h.min_us, h.max_us, h.overflows), (7, 12, 1500, 1));
        assert_eq!(h.samples(), 7);
        assert_eq!(h.at_or_above(1000), 1);
        assert_eq!(h.at_or_above(999), 2);
        let mut hdr = Histogram::new_with_bounds(1, 10_000_000_000, 3).unwrap();
        h.record_into(&mut hdr);
        assert_eq!(hdr.len(), 7);
        assert_eq!(hdr.min(), 12_000);
        assert!(hdr.max() >= 1_500_000);
        assert!(parse("000001 000002\n").is_err());
        let a = args(80, 1, 1000, 2500, 20000);
        assert_eq!(a, "-m -p 80 -t 1 -a 1 -i 1000 -l 2500 -q -h 20000");
        let c = command(Path::new("/c"), &a, Path::new("/t/h"));
        let argv: Vec<_> = c.get_args().map(|a| a.to_str().unwrap()).collect();
        assert_eq!((argv.len(), argv[14]), (15, "--histfile=/t/h"));
    }
}
