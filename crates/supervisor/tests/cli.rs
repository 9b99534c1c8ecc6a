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
    assert!(String::from_utf8_lossy(&o.stdout).contains("motion-supervisor home"));
    let o = sup(&["fly"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("unknown command 'fly'"));
    let o = sup(&[]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn check_reads_a_missing_file_as_a_config_error() {
    let o = sup(&["check", "--config", "/nonexistent/machine.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read /nonexistent/machine.toml"));
}
