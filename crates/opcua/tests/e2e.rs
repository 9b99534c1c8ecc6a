//! The real daemon (`motion-supervisor run`, sim I/O), the real
//! `motion-opcua`, and a client nobody here wrote: PyPI `asyncua`
//! (`tests/asyncua_client.py`, one scenario per run). Skipped without a
//! Python that has asyncua, unless `MOTION_PYTHON_REQUIRED` is set (CI).

use serde_json::Value;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const SCRIPT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/asyncua_client.py");

/// `target/<profile>/<name>` (built by `cargo test --workspace`).
fn bin(name: &str) -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let p = exe.parent().and_then(Path::parent).unwrap().join(name);
    assert!(
        p.exists(),
        "{} not built: run `cargo test --workspace`",
        p.display()
    );
    p
}

fn python() -> Option<String> {
    let candidates = [
        std::env::var("MOTION_PYTHON").ok(),
        Some(concat!(env!("CARGO_MANIFEST_DIR"), "/../../.ci/venv/bin/python").to_string()),
    ];
    let found = candidates.into_iter().flatten().find(|p| {
        Command::new(p)
            .args(["-c", "import asyncua"])
            .output()
            .is_ok_and(|o| o.status.success())
    });
    assert!(
        found.is_some() || std::env::var_os("MOTION_PYTHON_REQUIRED").is_none(),
        "MOTION_PYTHON_REQUIRED is set but no Python with asyncua was found"
    );
    found
}

fn run_dir() -> PathBuf {
    PathBuf::from(format!("/tmp/uo{}", std::process::id()))
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

/// The test's files: config, state (pki), runtime dir, client certificates.
struct Rig {
    dir: PathBuf,
    config: PathBuf,
    prefix: String,
    url: String,
    python: String,
    daemon: Option<Child>,
    opcua: Option<Child>,
}

const AXES: &str = r#"
[[axis]]
name = "X"
configuration = "servo"
control_mode = "position"
travel = "linear"
counts_per_unit = 1000.0
marker = true
home_mode = "active"
home_direction = "bidirectional_forward"
home_sequence = "switch_then_marker"
home_speed = 20.0
home_return_speed = 4.0
home_acceleration = 500.0
home_deceleration = 500.0
home_timeout = 20.0
[axis.sim]
start = -20.0
switch = [0.0, 5.0]
marker_every = 10.0
marker_at = 2.5

# Fails homing fast (ERR 1015: the switch is far beyond its timeout).
[[axis]]
name = "F"
configuration = "servo"
control_mode = "position"
travel = "linear"
counts_per_unit = 1000.0
marker = false
home_mode = "active"
home_direction = "bidirectional_forward"
home_sequence = "switch"
home_speed = 1.0
home_return_speed = 1.0
home_acceleration = 100.0
home_deceleration = 100.0
home_timeout = 0.5
[axis.sim]
start = 0.0
switch = [50.0, 55.0]
"#;

impl Rig {
    fn new(python: String) -> Rig {
        let prefix = format!("e2e_opcua_{}", std::process::id());
        let dir = std::env::temp_dir().join(&prefix);
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        // Short: the runtime directory's path is bounded (socket names).
        let run = run_dir();
        let _ = std::fs::remove_dir_all(&run);
        std::fs::create_dir_all(&run).unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&run, std::fs::Permissions::from_mode(0o700)).unwrap();
        let port = free_port();
        let url = format!("opc.tcp://127.0.0.1:{port}/");
        let config = dir.join("machine.toml");
        let rig = Rig {
            dir,
            config,
            prefix,
            url,
            python,
            daemon: None,
            opcua: None,
        };
        // feedback_timeout_ms 100: on a loaded CI machine a 20 ms stall of
        // motion-io counts as lost feedback, re-attaches the I/O process and
        // aborts the Move under test (seen once); nothing here tests that.
        let hash = rig.hash("op-secret");
        let viewer = rig.hash("view-secret");
        let text = format!(
            "[supervisor]\ncycle_us = 1000\ncpu = 1\npriority = 80\nio = \"sim\"\n\
             feedback_timeout_ms = 100\nservice_prefix = \"{}\"\nstate_dir = \"{}\"\n\
             runtime_dir = \"{}\"\n{AXES}\n[opcua]\nendpoint = \"{}\"\nunits = {{ X = \"mm\" }}\n\
             [[opcua.user]]\nname = \"op1\"\npassword_hash = \"{hash}\"\nrole = \"operator\"\n\
             [[opcua.user]]\nname = \"view1\"\npassword_hash = \"{viewer}\"\nrole = \"viewer\"\n",
            rig.prefix,
            rig.dir.join("state").display(),
            run_dir().display(),
            rig.url
        );
        std::fs::write(&rig.config, text).unwrap();
        rig
    }

    /// `motion-opcua hash-password`: the hash alone on the last line.
    fn hash(&self, pw: &str) -> String {
        let mut c = Command::new(bin("motion-opcua"))
            .args(["--config", "/nonexistent.toml", "hash-password"])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        c.stdin.take().unwrap().write_all(pw.as_bytes()).unwrap();
        let out = c.wait_with_output().unwrap();
        assert!(out.status.success());
        let text = String::from_utf8(out.stdout).unwrap();
        let h = text.lines().last().unwrap().to_string();
        assert!(h.starts_with("$argon2id$"), "{text}");
        h
    }

    fn log(&self, name: &str) -> std::fs::File {
        std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(self.dir.join(name))
            .unwrap()
    }

    fn start_daemon(&mut self) {
        let c = Command::new(bin("motion-supervisor"))
            .args(["run", "--config"])
            .arg(&self.config)
            .env("MOTION_IO_BIN", bin("motion-io"))
            .stdout(self.log("daemon.out"))
            .stderr(self.log("daemon.err"))
            .spawn()
            .unwrap();
        self.daemon = Some(c);
    }

    fn start_opcua(&mut self) {
        let c = Command::new(bin("motion-opcua"))
            .arg("--config")
            .arg(&self.config)
            .stdout(self.log("opcua.out"))
            .stderr(self.log("opcua.err"))
            .spawn()
            .unwrap();
        self.opcua = Some(c);
    }

    fn text(&self, name: &str) -> String {
        std::fs::read_to_string(self.dir.join(name)).unwrap_or_default()
    }

    /// Waits until `name` has `needle` at least `n` times.
    fn wait_log(&self, name: &str, needle: &str, n: usize) {
        let until = Instant::now() + Duration::from_secs(60);
        while self.text(name).matches(needle).count() < n {
            assert!(
                Instant::now() < until,
                "no {needle:?} in {name}:\n{}",
                self.text(name)
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// Runs one scenario; its JSON.
    fn ua(&self, scenario: &str, extra: &[&str]) -> Value {
        let out = Command::new(&self.python)
            .arg(SCRIPT)
            .arg(scenario)
            .args(["--url", &self.url, "--pki"])
            .arg(self.dir.join("client"))
            .args(extra)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{scenario}: {stdout}\n{stderr}");
        serde_json::from_str(stdout.lines().last().unwrap_or_default())
            .unwrap_or_else(|e| panic!("{scenario}: not JSON ({e}): {stdout}\n{stderr}"))
    }

    fn stop(child: &mut Option<Child>) -> Option<i32> {
        let mut c = child.take()?;
        let _ = nix::sys::signal::kill(
            nix::unistd::Pid::from_raw(c.id() as i32),
            nix::sys::signal::Signal::SIGTERM,
        );
        let until = Instant::now() + Duration::from_secs(30);
        loop {
            if let Some(s) = c.try_wait().unwrap() {
                return Some(s.code().unwrap_or(128));
            }
            if Instant::now() > until {
                let _ = c.kill();
                let _ = c.wait();
                panic!("did not stop on SIGTERM");
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    fn alive(child: &mut Option<Child>) -> bool {
        child
            .as_mut()
            .is_some_and(|c| c.try_wait().unwrap().is_none())
    }
}

impl Drop for Rig {
    fn drop(&mut self) {
        for c in [self.opcua.as_mut(), self.daemon.as_mut()]
            .into_iter()
            .flatten()
        {
            let _ = c.kill();
            let _ = c.wait();
        }
        let _ = std::fs::remove_dir_all(run_dir());
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.dir);
        }
    }
}

fn shm_leftovers(prefix: &str) -> Vec<String> {
    std::fs::read_dir("/dev/shm")
        .map(|d| {
            d.flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.contains(prefix))
                .collect()
        })
        .unwrap_or_default()
}

fn err_of(v: &Value) -> String {
    v["error"].as_str().unwrap_or("none").to_string()
}

#[test]
fn asyncua_against_the_daemon_and_motion_opcua() {
    let Some(py) = python() else {
        eprintln!("SKIPPED: no Python with asyncua (set MOTION_PYTHON; .ci/run makes one)");
        return;
    };
    let mut rig = Rig::new(py);
    rig.start_daemon();
    rig.wait_log("daemon.err", "attached", 1);
    rig.start_opcua();
    rig.wait_log("opcua.err", "joined motion-supervisor", 1);
    rig.wait_log("opcua.err", "Now listening", 1);
    let key = rig.dir.join("state/opcua/private/private.pem");
    use std::os::unix::fs::PermissionsExt;
    let mode = std::fs::metadata(&key).unwrap().permissions().mode();
    assert_eq!(mode & 0o777, 0o600, "the server's key is owner-only");

    for name in ["client", "stranger"] {
        rig.ua("gen-cert", &["--name", name]);
    }
    // Secure by default: no None endpoint, Sign & Encrypt only.
    let eps = rig.ua("endpoints", &[]);
    let eps = eps["endpoints"].as_array().unwrap();
    assert_eq!(eps.len(), 3, "{eps:?}");
    for e in eps {
        assert_ne!(e[0], "None", "{e}");
        assert_eq!(e[1], "SignAndEncrypt", "{e}");
    }
    // Untrusted until `trust`, which takes effect without a restart.
    let v = rig.ua("untrusted", &["--other", "client"]);
    assert!(err_of(&v).contains("Untrusted"), "{v}");
    let t = Command::new(bin("motion-opcua"))
        .arg("--config")
        .arg(&rig.config)
        .arg("trust")
        .arg(rig.dir.join("client/client.der"))
        .output()
        .unwrap();
    assert!(t.status.success(), "{}", String::from_utf8_lossy(&t.stderr));
    let said = String::from_utf8_lossy(&t.stdout);
    assert!(
        said.contains("subject \"") && said.contains("SHA-1 ") && said.contains("SHA-256 "),
        "trust names what it trusts: {said}"
    );
    let v = rig.ua("untrusted", &["--other", "stranger"]);
    assert!(err_of(&v).contains("Untrusted"), "{v}");
    // The refusal is logged with the certificate's name and thumbprint.
    let log = rig.text("opcua.err");
    assert!(log.contains("CN=urn:motion-test:stranger ["), "{log}");

    // Browse and read every axis's variables (anonymous).
    let b = rig.ua("browse", &[]);
    for axis in ["X", "F"] {
        let a = &b["axes"][axis];
        assert_eq!(
            a["_methods"],
            serde_json::json!([
                "Arm", "Change", "Disable", "Disarm", "Enable", "Gear", "Home", "Jog", "Move",
                "Redefine", "Reset", "Stop", "Unhome"
            ]),
            "{a}"
        );
        for v in [
            "HomedStatus",
            "HomingStatus",
            "PC",
            "ER",
            "ERR",
            "EXERR",
            "ActualPosition",
            "HomePosition",
            "Phase",
        ] {
            assert_eq!(a[v]["status"], "Good", "{axis}.{v}: {a}");
        }
        assert_eq!(a["HomedStatus"]["value"], false);
    }
    assert_eq!(b["axes"]["X"]["_eu"], "mm");
    assert_eq!(b["axes"]["F"]["_eu"], "units");
    assert_eq!(b["io"]["io"], true, "{b}");

    // Refusals: anonymous and viewer callers, a wrong password.
    let v = rig.ua("anon-call", &[]);
    assert_eq!(err_of(&v), "BadUserAccessDenied");
    assert_eq!(v["jog"], "BadUserAccessDenied", "{v}");
    assert_eq!(v["enable"], "BadUserAccessDenied", "{v}");
    let v = rig.ua(
        "anon-call",
        &["--login", "view1", "--password", "view-secret"],
    );
    assert_eq!(err_of(&v), "BadUserAccessDenied");
    let v = rig.ua("wrong-password", &["--password", "op-secret"]);
    assert!(err_of(&v).starts_with("Bad"), "{v}");
    let log = rig.text("opcua.err");
    assert!(
        log.contains("refused (BadUserAccessDenied: not an operator): user anonymous"),
        "{log}"
    );
    assert!(log.contains("user view1 [viewer (read-only)]"), "{log}");
    assert!(
        log.contains("user \"op1\" on Basic256Sha256: wrong password")
            || log.contains("op1 on Basic256Sha256: wrong password"),
        "{log}"
    );

    // An operator homes X over Basic256Sha256 Sign & Encrypt, watching HomedStatus.
    let h = rig.ua("home", &["--password", "op-secret"]);
    assert_eq!(h["homed"], true, "{h}");
    assert_eq!(
        h["outputs"],
        serde_json::json!([true, "accepted", 0, 0]),
        "{h}"
    );
    assert_eq!(h["changes"], serde_json::json!([false, true]), "{h}");

    // F fails homing: the event carries ERR/EXERR and the message.
    let e = rig.ua(
        "er-event",
        &["--password", "op-secret", "--axis", "F", "--timeout", "10"],
    );
    assert_eq!(e["event"], true, "{e}");
    assert_eq!(e["fields"]["ERR"], 1015, "{e}");
    assert_eq!(e["fields"]["Axis"], "F", "{e}");
    assert!(
        e["fields"]["Message"].as_str().unwrap().contains("timeout"),
        "{e}"
    );

    // The operations: Enable then Move, X reaches the target.
    let m = rig.ua(
        "enable-move",
        &["--password", "op-secret", "--target", "10"],
    );
    assert_eq!(
        m["enable"],
        serde_json::json!([true, "accepted", 0, 0]),
        "{m}"
    );
    assert_eq!(m["servo"], true, "{m}");
    assert_eq!(
        m["outputs"],
        serde_json::json!([true, "accepted", 0, 0]),
        "{m}"
    );
    assert_eq!(m["reached"], true, "{m}");
    // Jog is hold to run: called once and then never again by a client
    // that froze with its session open, it stops within its lease ...
    let j = rig.ua("jog", &["--password", "op-secret", "--duration", "1"]);
    assert_eq!(
        j["outputs"],
        serde_json::json!([true, "accepted", 0, 0]),
        "{j}"
    );
    assert_eq!(
        (&j["jogging_seen"], &j["stopped"], &j["session_open"]),
        (&Value::Bool(true), &Value::Bool(true), &Value::Bool(true)),
        "{j}"
    );
    assert!(j["moved"].as_f64().unwrap() > 0.5, "{j}");
    rig.wait_log("opcua.err", "jog on axis X ended: its lease ran out", 1);
    // ... one whose session closes stops at once ...
    let j = rig.ua(
        "jog",
        &[
            "--password",
            "op-secret",
            "--speed",
            "-5",
            "--duration",
            "1",
            "--close",
            "--timeout",
            "5",
        ],
    );
    assert_eq!(
        (&j["jogging_seen"], &j["stopped"]),
        (&Value::Bool(true), &Value::Bool(true)),
        "{j}"
    );
    rig.wait_log("opcua.err", "the session that started it is gone", 1);
    // ... one called again and again runs as long as the calls come, each
    // accepted (a lease of a second, renewed five times a second) ...
    let j = rig.ua(
        "jog-hold",
        &["--password", "op-secret", "--duration", "1", "--hold", "3"],
    );
    assert_eq!(
        j["first"],
        serde_json::json!([true, "accepted", 0, 0]),
        "{j}"
    );
    assert_eq!(j["refused"], Value::Null, "{j}");
    assert!(j["polls"].as_u64().unwrap() >= 5, "{j}");
    assert_eq!(
        (&j["jogging_throughout"], &j["stopped"]),
        (&Value::Bool(true), &Value::Bool(true)),
        "{j}"
    );
    // ... and one whose caller loses the operator role (the users read
    // again on SIGHUP) is refused its next call and stops, every renewal
    // being checked like a first call.
    let original = std::fs::read_to_string(&rig.config).unwrap();
    let pid = rig.opcua.as_ref().unwrap().id().to_string();
    let config = rig.config.to_string_lossy().into_owned();
    let j = rig.ua(
        "jog-hold",
        &[
            "--password",
            "op-secret",
            "--duration",
            "1",
            "--hold",
            "10",
            "--config",
            &config,
            "--pid",
            &pid,
        ],
    );
    std::fs::write(&rig.config, &original).unwrap();
    rig.wait_log("opcua.err", "the users were read again", 1);
    assert_eq!(j["refused"], "BadUserAccessDenied", "{j}");
    assert!(j["calls"].as_u64().unwrap() >= 4, "{j}");
    assert_eq!(j["stopped"], true, "{j}");
    rig.wait_log("opcua.err", "its user is no longer an operator", 1);
    nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(rig.opcua.as_ref().unwrap().id() as i32),
        nix::sys::signal::Signal::SIGHUP,
    )
    .unwrap();
    rig.wait_log("opcua.err", "the users were read again", 2);

    // Hostile arguments: each refused with a Bad status, the server still serves.
    let f = rig.ua("fuzz", &["--password", "op-secret"]);
    for (case, r) in f.as_object().unwrap() {
        if case == "after" {
            assert_eq!(*r, true, "{f}");
        } else {
            assert!(
                r.as_str().is_some_and(|s| s.starts_with("Bad")),
                "{case}: {f}"
            );
        }
    }

    // motion-opcua stops and starts again while the daemon runs.
    assert_eq!(
        Rig::stop(&mut rig.opcua),
        Some(0),
        "{}",
        rig.text("opcua.err")
    );
    assert!(Rig::alive(&mut rig.daemon), "{}", rig.text("daemon.err"));
    rig.start_opcua();
    assert_eq!(rig.ua("connected", &["--want", "true"])["connected"], true);

    // The daemon stops and starts again under it: it reconnects.
    let code = Rig::stop(&mut rig.daemon);
    assert!(
        matches!(code, Some(0 | 143)),
        "{code:?}: {}",
        rig.text("daemon.err")
    );
    assert_eq!(
        rig.ua("connected", &["--want", "false"])["connected"],
        false
    );
    assert!(Rig::alive(&mut rig.opcua), "{}", rig.text("opcua.err"));
    rig.start_daemon();
    assert_eq!(rig.ua("connected", &["--want", "true"])["connected"], true);
    let b = rig.ua("browse", &[]);
    assert_eq!(b["axes"]["X"]["HomedStatus"]["status"], "Good", "{b}");
    // Revoking: the trusted certificate deleted, the client is refused
    // again at once (no restart).
    for f in std::fs::read_dir(rig.dir.join("state/opcua/trusted")).unwrap() {
        std::fs::remove_file(f.unwrap().path()).unwrap();
    }
    let v = rig.ua("untrusted", &["--other", "client"]);
    assert!(err_of(&v).contains("Untrusted"), "{v}");
    assert_eq!(
        Rig::stop(&mut rig.opcua),
        Some(0),
        "{}",
        rig.text("opcua.err")
    );

    // A None endpoint only when configured, and then anonymous and read-only.
    let text = std::fs::read_to_string(&rig.config).unwrap().replace(
        "[opcua]\n",
        "[opcua]\npolicies = [\"Basic256Sha256\", \"None\"]\n",
    );
    std::fs::write(&rig.config, text).unwrap();
    rig.start_opcua();
    rig.wait_log("opcua.err", "the None policy is offered", 1);
    rig.wait_log("opcua.err", "Now listening", 3);
    let eps = rig.ua("endpoints", &[]);
    let none: Vec<&Value> = eps["endpoints"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e[0] == "None")
        .collect();
    assert_eq!(none.len(), 1, "{eps}");
    assert_eq!(none[0][2], serde_json::json!(["Anonymous"]), "{eps}");
    let v = rig.ua("none-call", &[]);
    assert!(v["read"].is_boolean(), "{v}");
    assert_eq!(err_of(&v), "BadUserAccessDenied", "{v}");
    assert_eq!(
        Rig::stop(&mut rig.opcua),
        Some(0),
        "{}",
        rig.text("opcua.err")
    );
    let code = Rig::stop(&mut rig.daemon);
    assert!(
        matches!(code, Some(0 | 143)),
        "{code:?}: {}",
        rig.text("daemon.err")
    );
    let until = Instant::now() + Duration::from_secs(3);
    while !shm_leftovers(&rig.prefix).is_empty() && Instant::now() < until {
        std::thread::sleep(Duration::from_millis(50));
    }
    assert_eq!(shm_leftovers(&rig.prefix), Vec::<String>::new());
}
