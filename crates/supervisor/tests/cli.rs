//! Command-line smoke tests of the binary. (Their presence also makes
//! `cargo test --workspace` build the binary that `tests/` runs end to end.)

use std::process::Command;

fn sup(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_motion-supervisor"))
        .args(args)
        .output()
        .expect("run motion-supervisor")
}

#[test]
fn help_and_usage_errors() {
    let o = sup(&["--help"]);
    assert!(o.status.success());
    let help = String::from_utf8_lossy(&o.stdout);
    for cmd in ["run", "home", "check", "Exit codes"] {
        assert!(help.contains(cmd), "{help}");
    }
    let o = sup(&["fly"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("unrecognized subcommand 'fly'"));
    let o = sup(&["fly", "--json"]);
    assert_eq!(o.status.code(), Some(2));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("one JSON object");
    assert!(v["errors"][0]["message"].as_str().unwrap().contains("fly"));
    let o = sup(&[]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn check_reads_a_missing_file_as_a_config_error() {
    let o = sup(&["check", "--config", "/nonexistent/machine.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read /nonexistent/machine.toml"));
}
