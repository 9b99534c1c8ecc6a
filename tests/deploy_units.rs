//! The systemd units in deploy/ are valid: `systemd-analyze verify` accepts
//! them (with the binary paths pointed at this build).

use motion_harness::bins::test_bin as bin;
use motion_harness::TempDir;
use std::process::Command;

#[test]
fn systemd_units_verify() {
    if Command::new("systemd-analyze")
        .arg("--version")
        .output()
        .is_err()
    {
        eprintln!("SKIPPED: systemd-analyze is not installed here");
        return;
    }
    let deploy = concat!(env!("CARGO_MANIFEST_DIR"), "/../deploy");
    let dir = TempDir::new("units");
    let mut files = Vec::new();
    for (unit, as_name) in [
        ("motion-supervisor.service", "motion-supervisor.service"),
        ("motion-io@.service", "motion-io@bus0.service"),
    ] {
        let text = std::fs::read_to_string(format!("{deploy}/{unit}")).unwrap();
        let sup = bin("motion-supervisor");
        let io = bin("motion-io");
        let text = text
            .replace("/usr/local/bin/motion-supervisor", sup.to_str().unwrap())
            .replace("/usr/local/bin/motion-io", io.to_str().unwrap());
        let path = dir.path().join(as_name);
        std::fs::write(&path, text).unwrap();
        files.push(path);
    }
    let out = Command::new("systemd-analyze")
        .arg("verify")
        .args(&files)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    // Any message is a problem (an unknown key is only a warning with exit
    // 0); only the missing `motion` user of a test machine is not about the
    // units themselves.
    let problems: Vec<&str> = err
        .lines()
        .filter(|l| !l.trim().is_empty())
        .filter(|l| !(l.contains("resolve user") || l.contains("resolve group")))
        .collect();
    assert!(out.status.success() && problems.is_empty(), "{err}");
}
