//! `deploy/motion-opcua.service` keeps the hardening a network-facing
//! process needs; `systemd-analyze verify` checks it with the daemon's units
//! in tests/deploy_units.rs (and the packaged copy in .ci/deb).

const DEPLOY: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../deploy");

#[test]
fn the_unit_follows_the_daemon_and_is_hardened() {
    let text = std::fs::read_to_string(format!("{DEPLOY}/motion-opcua.service")).unwrap();
    for line in [
        "Wants=motion-supervisor.service",
        "After=motion-supervisor.service",
        "User=motion",
        "NoNewPrivileges=yes",
        "CapabilityBoundingSet=",
        "ProtectSystem=strict",
        "RemoveIPC=no",
        "SystemCallFilter=@system-service",
        "MemoryMax=",
        "--runtime-dir /run/motion",
    ] {
        assert!(text.contains(line), "missing {line:?}");
    }
}
