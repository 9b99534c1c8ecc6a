//! motionctl without a supervisor: clear errors, the right exit codes, fast.

use std::process::Command;
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_motionctl");

fn run(args: &[&str]) -> (Option<i32>, String, String, Duration) {
    let t = Instant::now();
    let o = Command::new(BIN)
        .args(args)
        .output()
        .expect("run motionctl");
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        t.elapsed(),
    )
}

#[test]
fn no_supervisor_is_said_and_exits_3_within_2_s() {
    let prefix = format!("ctl_none_{}", std::process::id());
    for cmd in ["status", "home", "stop", "unhome", "stats"] {
        let (code, _, err, took) = run(&["--service-prefix", &prefix, cmd]);
        assert_eq!(code, Some(3), "{cmd}: {err}");
        assert!(
            err.contains(&prefix),
            "{cmd}: the message names the prefix: {err}"
        );
        assert!(took < Duration::from_secs(2), "{cmd}: {took:?}");
        // The same with --json: exactly one JSON object on stdout.
        let (code, out, _, _) = run(&["--service-prefix", &prefix, cmd, "--json"]);
        assert_eq!(code, Some(3));
        let v: serde_json::Value = serde_json::from_str(out.trim()).expect("one JSON object");
        assert!(v["errors"][0]["message"]
            .as_str()
            .unwrap()
            .contains(&prefix));
        assert!(v["errors"][0]["axis"].is_null());
    }
}

#[test]
fn argument_mistakes_exit_2_also_as_json() {
    let (code, _, err, _) = run(&["home", "--timeout", "1e308"]);
    assert_eq!(code, Some(2), "{err}");
    let (code, out, _, _) = run(&["home", "--timeout", "nan", "--json"]);
    assert_eq!(code, Some(2));
    let v: serde_json::Value = serde_json::from_str(out.trim()).expect("one JSON object");
    assert!(v["errors"][0]["message"]
        .as_str()
        .unwrap()
        .contains("timeout"));
    let (code, _, _, _) = run(&["--service-prefix", "a/b", "status"]);
    assert_eq!(code, Some(2));
    let (code, _, _, _) = run(&["trace", "X"]);
    assert_eq!(code, Some(2), "--out is required");
    let (code, out, _, _) = run(&["--help"]);
    assert_eq!(code, Some(0));
    assert!(out.contains("Exit codes"));
}
