//! Logs of the daemons, through the `log` facade (env_logger behind it):
//! levels from `RUST_LOG` (default `info`), always to stderr, never from the
//! real-time thread (it does not format anything).
//!
//! journald-friendly: under systemd (`JOURNAL_STREAM` set) every line starts
//! with its syslog priority (`<3>` error, `<4>` warning, `<6>` info, `<7>`
//! debug, see sd-daemon(3)) and carries no time stamp — the journal adds
//! both. On a terminal a line reads `motion-supervisor: warning: …`.
//!
//! A `motion-io` the supervisor spawns writes its stderr into a pipe the
//! supervisor reads (each line shown once). When the supervisor dies that
//! pipe has no reader, and the lines that matter most — the watchdog
//! stopping every axis — would be lost: the supervisor hands the child its
//! own stderr as a second descriptor ([`FALLBACK_FD_ENV`]). Once its
//! start-up is over the child writes there directly ([`direct_stderr`]:
//! nothing of a running child waits in a pipe buffer its reader may never
//! empty), and before that the logger writes there once the pipe is broken.

use std::fs::File;
use std::io::{self, Write};
use std::os::fd::FromRawFd;

/// Environment variable naming an inherited descriptor the logger writes to
/// once stderr is a broken pipe (set by the supervisor for its children).
pub const FALLBACK_FD_ENV: &str = "MOTION_STDERR_FALLBACK_FD";

/// The inherited descriptor of [`FALLBACK_FD_ENV`] (-1: none).
static FALLBACK_FD: std::sync::atomic::AtomicI32 = std::sync::atomic::AtomicI32::new(-1);

/// Start-up is over: stderr becomes the parent's own stderr (the copy of
/// [`FALLBACK_FD_ENV`]), so what the process says from now on — above all
/// how it stopped its axes when the parent died — reaches the terminal or
/// the journal without passing through the parent. Without such a copy
/// nothing changes.
pub fn direct_stderr() {
    let fd = FALLBACK_FD.load(std::sync::atomic::Ordering::Relaxed);
    if fd > 2 {
        // SAFETY: dup2 of a descriptor we own onto our stderr.
        unsafe { libc::dup2(fd, 2) };
    }
}

/// stderr, then the fallback descriptor once stderr's reader is gone.
struct Stderr {
    fallback: Option<File>,
    broken: bool,
}

impl Stderr {
    fn from_env() -> Self {
        let fd = std::env::var(FALLBACK_FD_ENV)
            .ok()
            .and_then(|v| v.parse::<i32>().ok())
            .filter(|&fd| fd > 2);
        // SAFETY: F_GETFD only asks whether the descriptor is open; the
        // descriptor was inherited for this purpose alone and is owned by
        // the `File` from here on.
        let fallback = fd
            .filter(|&fd| unsafe { libc::fcntl(fd, libc::F_GETFD) } >= 0)
            .map(|fd| {
                FALLBACK_FD.store(fd, std::sync::atomic::Ordering::Relaxed);
                unsafe { File::from_raw_fd(fd) }
            });
        Stderr {
            fallback,
            broken: false,
        }
    }
}

impl Write for Stderr {
    fn write(&mut self, b: &[u8]) -> io::Result<usize> {
        if !self.broken {
            match io::stderr().write(b) {
                Err(e) if e.kind() == io::ErrorKind::BrokenPipe => self.broken = true,
                other => return other,
            }
        }
        match &mut self.fallback {
            Some(f) => f.write(b),
            None => Ok(b.len()),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match (&mut self.fallback, self.broken) {
            (Some(f), true) => f.flush(),
            _ => io::stderr().flush(),
        }
    }
}

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
    b.target(env_logger::Target::Pipe(Box::new(Stderr::from_env())));
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
