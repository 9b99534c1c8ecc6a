//! `--stress`: stress-ng loading the other CPU for the whole bench. It is
//! bounded by its own timeout (so it cannot outlive a bench that dies) and
//! killed as a group at the end; if it ended before the bench did, the
//! bench did not run under the load it claims, which is a failure.

use motion_bench::proc::Running;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// Starts `stress-ng --cpu 1` on `other_cpu`, with a timeout well beyond
/// the bench's expected length (`duration` s per tool in `slices` slices).
pub fn start(
    bin: &Path,
    other_cpu: usize,
    duration: f64,
    slices: usize,
) -> Result<Running, String> {
    let bound = (3.0 * duration + 20.0 * slices as f64 + 60.0).ceil() as u64;
    let mut c = Command::new(bin);
    c.args([
        "--cpu",
        "1",
        "--taskset",
        &other_cpu.to_string(),
        "--timeout",
        &format!("{bound}s"),
        "--quiet",
    ]);
    let r = Running::spawn(&mut c, "stress-ng", true, true)?;
    eprintln!(
        "jitter: stress-ng --cpu 1 --taskset {other_cpu} --timeout {bound}s (pid {})",
        r.pid()
    );
    std::thread::sleep(Duration::from_millis(300));
    Ok(r)
}

/// Ends stress-ng, whatever happened; a failure if it had ended by itself
/// (unless the bench was interrupted).
pub fn stop(stress: Option<Running>, interrupted: bool, failures: &mut Vec<String>) {
    if let Some(mut s) = stress {
        let still = s.running();
        s.terminate(Duration::from_secs(3));
        if !still && !interrupted {
            failures.push("stress-ng ended before the bench did (see its output)".into());
        }
    }
}
