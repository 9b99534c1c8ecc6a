//! Logs of the daemons, through the `log` facade (env_logger behind it):
//! levels from `RUST_LOG` (default `info`), always to stderr, never from the
//! real-time thread (it does not format anything).
//!
//! journald-friendly: under systemd (`JOURNAL_STREAM` set) every line starts
//! with its syslog priority (`<3>` error, `<4>` warning, `<6>` info, `<7>`
//! debug, see sd-daemon(3)) and carries no time stamp — the journal adds
//! both. On a terminal a line reads `motion-supervisor: warning: …`.

use std::io::Write;

/// Installs the logger for `program` (idempotent: a second call is ignored).
pub fn init(program: &'static str) {
    let journal = std::env::var_os("JOURNAL_STREAM").is_some();
    let mut b = env_logger::Builder::new();
    b.filter_level(log::LevelFilter::Info);
    // ethercrab (motion-io's EtherCAT backend) logs every late bus frame at
    // error level from the real-time bus thread; the backend counts them
    // instead (bus summary). `RUST_LOG=ethercrab=debug` shows them again.
    b.filter_module("ethercrab", log::LevelFilter::Off);
    if let Ok(spec) = std::env::var("RUST_LOG") {
        b.parse_filters(&spec);
    }
    b.target(env_logger::Target::Stderr);
    b.format(move |buf, r| {
        let (prio, word) = match r.level() {
            log::Level::Error => (3, "error: "),
            log::Level::Warn => (4, "warning: "),
            log::Level::Info => (6, ""),
            log::Level::Debug => (7, "debug: "),
            log::Level::Trace => (7, "trace: "),
        };
        if journal {
            writeln!(buf, "<{prio}>{word}{}", r.args())
        } else {
            writeln!(buf, "{program}: {word}{}", r.args())
        }
    });
    let _ = b.try_init();
}
