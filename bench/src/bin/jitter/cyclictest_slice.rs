//! Running cyclictest for one slice, as the reference the supervisor is
//! compared with: the same period, priority and CPU, as many loops as the
//! slice has periods (`-l`, since `-D` takes whole seconds only), its
//! histogram written to a file and read back.

use crate::cli::Opts;
use hdrhistogram::Histogram;
use motion_bench::cyclictest::{self, CtHistogram};
use motion_bench::drive;
use motion_bench::proc;
use std::path::Path;
use std::time::Duration;

/// One cyclictest slice.
pub struct CtSlice {
    pub start: Duration,
    pub len: Duration,
    pub hist: CtHistogram,
    pub hdr: Histogram<u64>,
}

/// cyclictest's arguments for `loops` periods with its histogram written to
/// `hist_path`, and the command as reported (the file's name left out: it
/// is a temporary one).
pub fn command(o: &Opts, loops: u64, hist_path: &Path) -> (Vec<String>, String) {
    let args = vec![
        "-m".to_string(),
        "-p".into(),
        o.priority.to_string(),
        "-t".into(),
        "1".into(),
        "-a".into(),
        o.cpu.to_string(),
        "-i".into(),
        o.period_us.to_string(),
        "-l".into(),
        loops.to_string(),
        "-q".into(),
        "-h".into(),
        o.hist_max_us.to_string(),
        format!("--histfile={}", hist_path.display()),
    ];
    let shown = format!(
        "cyclictest {}",
        args[..args.len() - 1].join(" ") + " --histfile=FILE"
    );
    (args, shown)
}

/// Reads one cyclictest run: its exit and its histogram file.
pub fn ct_slice(
    ended: &proc::Ended,
    hist_path: &Path,
    start: Duration,
    len: f64,
) -> Result<CtSlice, String> {
    let out = || {
        let e = format!("{}\n{}", ended.stdout.trim(), ended.stderr.trim());
        let e = e.trim();
        if e.is_empty() {
            String::new()
        } else {
            format!("; its output: {}", drive::tail(e, 8))
        }
    };
    if !ended.success() {
        return Err(format!("{}{}", ended.describe(), out()));
    }
    let text = std::fs::read_to_string(hist_path)
        .map_err(|e| format!("no histogram file {} ({e}){}", hist_path.display(), out()))?;
    let hist = cyclictest::parse(&text)?;
    if hist.samples() == 0 {
        return Err(format!("an empty histogram{}", out()));
    }
    let hdr = hist.to_hdr();
    Ok(CtSlice {
        start,
        len: Duration::from_secs_f64(len),
        hist,
        hdr,
    })
}
