//! `deploy/motion-opcua.service` is valid: `systemd-analyze verify` accepts
//! it together with the daemon's unit it is bound to (binary paths pointed
//! at this build), and it keeps the hardening a network-facing process
//! needs.

use std::path::Path;
use std::process::Command;

fn bin(name: &str) -> std::path::PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.parent().and_then(Path::parent).unwrap().join(name)
}

const DEPLOY: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../deploy");

#[test]
fn the_unit_is_bound_to_the_daemon_and_hardened() {
    let text = std::fs::read_to_string(format!("{DEPLOY}/motion-opcua.service")).unwrap();
    for line in [
        "BindsTo=motion-supervisor.service",
        "After=motion-supervisor.service",
        "User=motion",
        "NoNewPrivileges=yes",
        "CapabilityBoundingSet=",
        "ProtectSystem=strict",
        "RemoveIPC=no",
        "--runtime-dir /run/motion",
    ] {
        assert!(text.contains(line), "missing {line:?}");
    }
}

#[test]
fn systemd_analyze_verifies_the_unit() {
    if Command::new("systemd-analyze")
        .arg("--version")
        .output()
        .is_err()
    {
        eprintln!("SKIPPED: systemd-analyze is not installed here");
        return;
    }
    let dir = std::env::temp_dir().join(format!("opcua-units-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut files = Vec::new();
    for (unit, binary) in [
        ("motion-supervisor.service", "motion-supervisor"),
        ("motion-opcua.service", "motion-opcua"),
    ] {
        let text = std::fs::read_to_string(format!("{DEPLOY}/{unit}")).unwrap();
        // The unit must name an executable that exists: this build's (the
        // daemon's only when built, else any executable stands in).
        let mut exe = bin(binary);
        if !exe.exists() {
            exe = "/bin/true".into();
        }
        let text = text.replace(&format!("/usr/local/bin/{binary}"), exe.to_str().unwrap());
        let path = dir.join(unit);
        std::fs::write(&path, text).unwrap();
        files.push(path);
    }
    let out = Command::new("systemd-analyze")
        .arg("verify")
        .args(&files)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    // A missing `motion` user on a test machine is not about the unit.
    let problems: Vec<&str> = err
        .lines()
        .filter(|l| !l.trim().is_empty())
        .filter(|l| !(l.contains("resolve user") || l.contains("resolve group")))
        .collect();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(out.status.success() && problems.is_empty(), "{err}");
}
