//! What every bench shares from its start to its exit status, written once:
//! the stop handler, the host it runs on, other real-time threads, a
//! temporary directory (removed whichever way the run ends), the output
//! directory; then the JSON file, the closing lines and the exit status
//! (0; 1 if something failed; 130 if interrupted, the partial results
//! printed and written all the same).

use crate::flags::Cycle;
use crate::host::{loadavg, Host, OtherRt};
use crate::proc;
use crate::table::Text;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// One bench run.
pub struct Bench {
    /// The binary's name, in front of its stderr lines.
    pub name: &'static str,
    pub host: Host,
    pub other_rt: OtherRt,
    /// Configs, logs and histograms of the runs (removed on drop).
    pub tmp: PathBuf,
    pub t0: Instant,
}

impl Bench {
    /// Installs the stop handler, reads the host, makes the temporary
    /// directory and `out` (if the bench writes files), notes other
    /// real-time threads.
    pub fn start(name: &'static str, out: Option<&Path>) -> Result<Self, String> {
        proc::install_stop_handler();
        let tmp = tmp_dir(name);
        for d in std::iter::once(tmp.as_path()).chain(out) {
            std::fs::create_dir_all(d)
                .map_err(|e| format!("cannot create {}: {e}", d.display()))?;
        }
        let (host, mut other_rt) = (Host::read(), OtherRt::new(name));
        other_rt.note("before the bench");
        Ok(Bench {
            name,
            host,
            other_rt,
            tmp,
            t0: Instant::now(),
        })
    }

    /// Says so on stderr when the kernel is not PREEMPT_RT.
    pub fn warn_not_rt(&self) {
        if !self.host.is_rt {
            let (name, p) = (self.name, &self.host.preemption);
            eprintln!("{name}: kernel is not PREEMPT_RT ({p}): the numbers are upper bounds");
        }
    }

    /// The `environment` object of a report's JSON.
    pub fn environment(&self) -> Value {
        let e = &self.host;
        json!({
            "kernel": e.kernel,
            "preemption": e.preemption,
            "preempt_rt": e.is_rt,
            "cpus": e.cpus,
            "rt_throttling": e.throttling,
            "other_rt_threads": self.other_rt.list(),
        })
    }

    /// `kernel … | preemption: … | N CPUs | load before B, after A | wall
    /// W s`: the second line of the soak's and deadpeer's reports.
    pub fn load_line(&self, wall: f64) -> String {
        let (head, before, after) = (self.host.head(), &self.host.load, loadavg());
        format!("{head} | load before {before}, after {after} | wall {wall:.0} s")
    }

    /// What the soak's and deadpeer's JSON start with: the cycle, the
    /// kernel, the load before and after, the wall time.
    pub fn json_head(&self, cy: &Cycle, wall: f64) -> Value {
        json!({
            "period_us": cy.period_us,
            "cpu": cy.cpu,
            "priority": cy.priority,
            "kernel": self.host.kernel,
            "preemption": self.host.preemption,
            "load_before": self.host.load,
            "load_after": loadavg(),
            "wall_s": wall,
        })
    }

    /// `WARNING: other real-time threads WHEN: …` in `t`, if there were any.
    pub fn other_rt_warning(&self, t: &mut Text, when: &str) {
        if !self.other_rt.is_empty() {
            let list = self.other_rt.list().join("; ");
            t.line(format!("WARNING: other real-time threads {when}: {list}"));
        }
    }

    /// Nothing was measured: the failures on stderr, then 130 if
    /// interrupted, else the failures as the error.
    pub fn nothing_measured(&self, interrupted: bool, failures: &[String]) -> Result<i32, String> {
        for f in failures {
            eprintln!("{}: FAILED: {f}", self.name);
        }
        if interrupted {
            eprintln!(
                "{}: interrupted (signal {})",
                self.name,
                proc::stop_signal()
            );
            return Ok(130);
        }
        Err(failures.join("; "))
    }

    /// The exit status once the report is printed and `files` written:
    /// 130 if interrupted, 1 with the failures listed, else 0 (`NAME: OK`
    /// said if `judged`).
    pub fn end(
        &self,
        files: &[&Path],
        interrupted: bool,
        failures: &[String],
        judged: bool,
    ) -> i32 {
        let name = self.name;
        if !files.is_empty() {
            let files: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
            println!("files: {}", files.join(", "));
        }
        if interrupted {
            eprintln!(
                "{name}: interrupted (signal {}): results above are partial",
                proc::stop_signal()
            );
            return 130;
        }
        if failures.is_empty() {
            if judged {
                println!("{name}: OK");
            }
            return 0;
        }
        for f in failures {
            println!("{name}: FAILED: {f}");
        }
        1
    }
}

impl Drop for Bench {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.tmp);
    }
}

/// The temporary directory of bench `name` in this process.
pub fn tmp_dir(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("motion-bench-{name}-{}", std::process::id()))
}

/// Cleans what the run of `prefix` left in /dev/shm; if it left anything:
/// the files and `(then cleaned by the bench[, NOT all]): FILES`.
pub fn cleaned(prefix: &str) -> Option<(Vec<String>, String)> {
    let (found, remaining) = crate::drive::clean_leftovers(prefix);
    let all = if remaining.is_empty() {
        ""
    } else {
        ", NOT all"
    };
    let note = format!("(then cleaned by the bench{all}): {}", found.join(", "));
    (!found.is_empty()).then_some((found, note))
}

/// The `status` object of a report's JSON: ok, interrupted, the failures.
pub fn status(interrupted: bool, failures: &[String]) -> Value {
    json!({
        "ok": failures.is_empty() && !interrupted,
        "interrupted": interrupted,
        "failures": failures,
    })
}

/// The object `v` with the members of `more` added.
pub fn with(mut v: Value, more: Value) -> Value {
    if let (Some(v), Value::Object(more)) = (v.as_object_mut(), more) {
        v.extend(more);
    }
    v
}

/// Writes `v` to `path` as pretty JSON.
pub fn write_json(path: &Path, v: &Value) -> Result<(), String> {
    let text = serde_json::to_string_pretty(v).unwrap_or_default() + "\n";
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// A bench's `main`: runs it and exits with its status; an error is
/// `NAME: FAILED: …` on stderr, status 1.
pub fn main(name: &str, run: impl FnOnce() -> Result<i32, String>) -> ! {
    std::process::exit(run().unwrap_or_else(|e| {
        eprintln!("{name}: FAILED: {e}");
        1
    }))
}
