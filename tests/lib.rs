//! Helpers for the end-to-end tests: locate the binaries, write configs with
//! unique service prefixes, run processes, find leftovers in /dev/shm.
//!
//! Every test uses its own iceoryx2 service prefix, so tests run in parallel
//! and each can check that it left nothing behind.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// Runs the process-spawning tests of one test binary one at a time.
///
/// Each test starts a SCHED_FIFO supervisor and an I/O process; several at
/// once on a 2-core CI machine (with a kernel that is not PREEMPT_RT, where
/// process start-up work in the kernel is not preemptible) can starve an I/O
/// process past `stale_cycles`, and the engines then — correctly — abort
/// homing with ERR 12/40. These tests are about behaviour, so they take turns.
pub fn serial() -> std::sync::MutexGuard<'static, ()> {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    LOCK.lock().unwrap_or_else(|e| e.into_inner())
}

/// `target/<profile>/<name>`, found from the test executable's location
/// (`target/<profile>/deps/<test>`).
pub fn bin(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    let dir = exe.parent().and_then(Path::parent).expect("target dir");
    let p = dir.join(name);
    assert!(
        p.exists(),
        "{} not built: run the tests with `cargo test --workspace`",
        p.display()
    );
    p
}

/// A service prefix no other test (or run) uses.
pub fn unique_prefix(tag: &str) -> String {
    static N: AtomicU32 = AtomicU32::new(0);
    format!(
        "e2e_{tag}_{}_{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    )
}

/// A config file (and its state directory) removed on drop.
pub struct TempConfig {
    pub path: PathBuf,
    pub prefix: String,
    /// The config's `state_dir` (homing record, stored references): one
    /// per test unless the test sets its own.
    pub state_dir: PathBuf,
}

impl Drop for TempConfig {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
        let _ = std::fs::remove_dir_all(&self.state_dir);
    }
}

/// Writes `[supervisor]` (1 kHz, the unique prefix, sim I/O) and `axes`.
/// `stale_cycles` is generous: several tests run in parallel on a small CI
/// machine, and these tests are about sequences, not about a starved peer.
pub fn config(tag: &str, supervisor_extra: &str, axes: &str) -> TempConfig {
    let prefix = unique_prefix(tag);
    let path = std::env::temp_dir().join(format!("{prefix}.toml"));
    // Defaults for the keys the test does not set itself.
    let given = |k: &str| {
        supervisor_extra.lines().any(|l| {
            l.trim_start().starts_with(&format!("{k} "))
                || l.trim_start().starts_with(&format!("{k}="))
        })
    };
    let mut sup = String::new();
    for (k, v) in [
        ("cycle_us", "1000"),
        ("cpu", "1"),
        ("priority", "80"),
        ("io", "\"sim\""),
        ("feedback_timeout_ms", "20"),
    ] {
        let implied = k == "feedback_timeout_ms" && given("stale_cycles");
        if !given(k) && !implied {
            sup += &format!("{k} = {v}\n");
        }
    }
    let state_dir = std::env::temp_dir().join(format!("{prefix}.state"));
    if !given("state_dir") {
        sup += &format!("state_dir = \"{}\"\n", state_dir.display());
    }
    let text =
        format!("[supervisor]\n{sup}service_prefix = \"{prefix}\"\n{supervisor_extra}\n{axes}");
    std::fs::write(&path, text).expect("write config");
    TempConfig {
        path,
        prefix,
        state_dir,
    }
}

/// Files of every iceoryx2 domain of this prefix in /dev/shm.
pub fn shm_leftovers(prefix: &str) -> Vec<String> {
    motion_ipc::Domain::shm_files_of_prefix(prefix)
}

/// Asserts that the domain left nothing behind (waits briefly: a process
/// may still be cleaning up when its parent has already returned).
pub fn assert_clean(prefix: &str) {
    let until = Instant::now() + Duration::from_secs(3);
    loop {
        let left = shm_leftovers(prefix);
        if left.is_empty() {
            return;
        }
        assert!(Instant::now() < until, "left in /dev/shm: {left:?}");
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Result of a finished process.
pub struct Run {
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
}

impl Run {
    pub fn json(&self) -> serde_json::Value {
        serde_json::from_str(self.stdout.trim()).unwrap_or_else(|e| {
            panic!(
                "stdout is not JSON ({e}):\n{}\nstderr:\n{}",
                self.stdout, self.stderr
            )
        })
    }
}

impl From<Output> for Run {
    fn from(o: Output) -> Self {
        Run {
            code: o.status.code(),
            stdout: String::from_utf8_lossy(&o.stdout).into_owned(),
            stderr: String::from_utf8_lossy(&o.stderr).into_owned(),
        }
    }
}

/// Runs `motion-supervisor <args>` to completion.
pub fn supervisor(args: &[&str]) -> Run {
    Command::new(bin("motion-supervisor"))
        .args(args)
        .env("MOTION_IO_BIN", bin("motion-io"))
        .output()
        .expect("run motion-supervisor")
        .into()
}

/// Starts `motion-supervisor <args>` with piped stdout/stderr.
pub fn spawn_supervisor(args: &[&str]) -> Child {
    Command::new(bin("motion-supervisor"))
        .args(args)
        .env("MOTION_IO_BIN", bin("motion-io"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn motion-supervisor")
}

/// A running process whose stderr is read line by line in the background,
/// so a test can wait for a message and still get everything at the end.
pub struct Watched {
    pub child: Child,
    pub lines: std::sync::Arc<std::sync::Mutex<Vec<String>>>,
    reader: Option<std::thread::JoinHandle<()>>,
}

impl Watched {
    pub fn new(mut child: Child) -> Self {
        let lines = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let err = child.stderr.take().expect("piped stderr");
        let sink = lines.clone();
        let reader = std::thread::spawn(move || {
            use std::io::BufRead;
            for l in std::io::BufReader::new(err).lines().map_while(Result::ok) {
                sink.lock().unwrap().push(l);
            }
        });
        Self {
            child,
            lines,
            reader: Some(reader),
        }
    }

    /// Waits until a stderr line contains `needle`.
    pub fn wait_line(&self, needle: &str, timeout: Duration) -> bool {
        wait_for(timeout, || {
            self.lines
                .lock()
                .unwrap()
                .iter()
                .any(|l| l.contains(needle))
        })
    }

    /// Waits for the process (and everyone holding its stderr) to finish.
    pub fn finish(mut self) -> Run {
        let mut stdout = String::new();
        if let Some(mut o) = self.child.stdout.take() {
            let _ = o.read_to_string(&mut stdout);
        }
        let status = self.child.wait().expect("wait");
        if let Some(r) = self.reader.take() {
            let _ = r.join();
        }
        let stderr = self.lines.lock().unwrap().join("\n");
        Run {
            code: status.code(),
            stdout,
            stderr,
        }
    }
}

impl Drop for Watched {
    /// A test that failed half-way must not leave its processes running.
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// Collects a child's output (waits for it to exit).
pub fn finish(mut child: Child) -> Run {
    let mut stdout = String::new();
    let mut stderr = String::new();
    if let Some(mut o) = child.stdout.take() {
        let _ = o.read_to_string(&mut stdout);
    }
    if let Some(mut e) = child.stderr.take() {
        let _ = e.read_to_string(&mut stderr);
    }
    let status = child.wait().expect("wait");
    Run {
        code: status.code(),
        stdout,
        stderr,
    }
}

/// Pid of a running process whose command line contains `needle` and whose
/// executable is `name`.
pub fn find_process(name: &str, needle: &str) -> Option<i32> {
    for e in std::fs::read_dir("/proc").ok()?.flatten() {
        let Ok(pid) = e.file_name().to_string_lossy().parse::<i32>() else {
            continue;
        };
        let Ok(cmd) = std::fs::read(format!("/proc/{pid}/cmdline")) else {
            continue;
        };
        let args: Vec<String> = cmd
            .split(|b| *b == 0)
            .map(|a| String::from_utf8_lossy(a).into_owned())
            .collect();
        let is_name = args.first().is_some_and(|a| a.ends_with(name));
        if is_name && args.iter().any(|a| a == needle) {
            return Some(pid);
        }
    }
    None
}

/// Waits until `f` is true or `timeout` passes.
pub fn wait_for(timeout: Duration, mut f: impl FnMut() -> bool) -> bool {
    let until = Instant::now() + timeout;
    while Instant::now() < until {
        if f() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    f()
}

/// Sends `sig` to `pid`.
pub fn signal(pid: i32, sig: nix::sys::signal::Signal) {
    let _ = nix::sys::signal::kill(nix::unistd::Pid::from_raw(pid), sig);
}

/// The row of axis `name` in `home --json` output.
pub fn axis<'a>(v: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    v["axes"]
        .as_array()
        .and_then(|a| a.iter().find(|r| r["name"] == name))
        .unwrap_or_else(|| panic!("no axis {name} in {v}"))
}

/// `x` as f64 (panics with context).
pub fn num(v: &serde_json::Value, key: &str) -> f64 {
    v[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} is not a number in {v}"))
}

/// One count at 1000 counts per unit, plus rounding.
pub const COUNT: f64 = 0.001 + 1e-9;

pub fn close(v: &serde_json::Value, key: &str, want: f64, tol: f64) {
    let got = num(v, key);
    assert!(
        (got - want).abs() <= tol,
        "{} {key} = {got}, want {want} ± {tol}\n{v}",
        v["name"]
    );
}

/// Runs `motionctl <args>` to completion.
pub fn motionctl(args: &[&str]) -> Run {
    Command::new(bin("motionctl"))
        .args(args)
        .output()
        .expect("run motionctl")
        .into()
}

/// `motionctl --service-prefix P <args>`.
pub fn ctl(prefix: &str, args: &[&str]) -> Run {
    let mut all = vec!["--service-prefix", prefix];
    all.extend_from_slice(args);
    motionctl(&all)
}

/// A running `motion-supervisor run` (the daemon), stopped with SIGTERM on
/// drop (and checked to leave nothing behind).
pub struct Daemon {
    pub watched: Option<Watched>,
    pub prefix: String,
}

impl Daemon {
    /// Starts `run --config cfg` and waits until `motionctl status` answers
    /// and every I/O process in `attached` shows attached.
    pub fn start(cfg: &TempConfig, attached: &[&str]) -> Self {
        let w = Watched::new(spawn_supervisor(&[
            "run",
            "--config",
            cfg.path.to_str().unwrap(),
        ]));
        let d = Daemon {
            watched: Some(w),
            prefix: cfg.prefix.clone(),
        };
        let ok = wait_for(Duration::from_secs(20), || {
            let r = ctl(&d.prefix, &["status", "--json"]);
            r.code == Some(0)
                && attached.iter().all(|io| {
                    let v = r.json();
                    v["io"].as_array().is_some_and(|a| {
                        a.iter().any(|x| x["name"] == *io && x["attached"] == true)
                    })
                })
        });
        assert!(ok, "daemon not ready: {}", d.stderr());
        d
    }

    pub fn stderr(&self) -> String {
        self.watched
            .as_ref()
            .map(|w| w.lines.lock().unwrap().join("\n"))
            .unwrap_or_default()
    }

    pub fn wait_line(&self, needle: &str, timeout: Duration) -> bool {
        self.watched
            .as_ref()
            .is_some_and(|w| w.wait_line(needle, timeout))
    }

    /// SIGTERM and the daemon's exit (external I/O processes may still hold
    /// the domain: check it with `assert_clean` once they are gone too).
    pub fn stop(mut self) -> Run {
        let w = self.watched.take().expect("running");
        signal(w.child.id() as i32, nix::sys::signal::Signal::SIGTERM);
        w.finish()
    }

    /// The status JSON.
    pub fn status(&self) -> serde_json::Value {
        let r = ctl(&self.prefix, &["status", "--json"]);
        assert_eq!(r.code, Some(0), "{}", r.stderr);
        r.json()
    }
}

impl Drop for Daemon {
    fn drop(&mut self) {
        if let Some(w) = self.watched.take() {
            signal(w.child.id() as i32, nix::sys::signal::Signal::SIGTERM);
            let _ = w.finish();
        }
    }
}

/// `motion-io <args>` as a child of the test, stderr collected.
pub fn spawn_io(args: &[&str]) -> Watched {
    Watched::new(
        Command::new(bin("motion-io"))
            .args(args)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn motion-io"),
    )
}
