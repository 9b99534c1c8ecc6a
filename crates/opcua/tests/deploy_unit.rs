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
    let Ok(_) = Command::new("systemd-analyze").arg("--version").output() else {
        eprintln!("SKIPPED: no systemd-analyze on this machine");
        return;
    };
    let dir = std::env::temp_dir().join(format!("opcua-units-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let files: Vec<std::path::PathBuf> = [
        ("motion-supervisor.service", "motion-supervisor"),
        ("motion-opcua.service", "motion-opcua"),
    ]
    .into_iter()
    .map(|(unit, binary)| {
        // The unit must name an executable that exists: this build's (the
        // daemon's only when built, else any executable stands in).
        let exe = Some(bin(binary))
            .filter(|p| p.exists())
            .unwrap_or_else(|| "/bin/true".into());
        let text = std::fs::read_to_string(format!("{DEPLOY}/{unit}"))
            .unwrap()
            .replace(&format!("/usr/local/bin/{binary}"), &exe.to_string_lossy());
        let at = dir.join(unit);
        std::fs::write(&at, text).unwrap();
        at
    })
    .collect();
    let out = Command::new("systemd-analyze")
        .args(
            ["verify".as_ref()]
                .into_iter()
                .chain(files.iter().map(|f| f.as_os_str())),
        )
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    // Every line is a problem (an unknown key is only a warning, exit 0),
    // except a test machine without the `motion` user.
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let about_the_unit = |l: &&str| {
        let l = l.trim();
        !l.is_empty() && !l.contains("resolve user") && !l.contains("resolve group")
    };
    let found: Vec<&str> = stderr.lines().filter(about_the_unit).collect();
    assert!(found.is_empty(), "{found:#?}");
    assert!(out.status.success(), "{stderr}");
}
