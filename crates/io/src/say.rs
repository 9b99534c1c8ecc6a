//! Messages through the `log` facade (journald-friendly, see
//! `motion_rt::logging`). `--quiet` drops the informational ones; errors and
//! watchdog messages always show.
//!
//! Never blocking: once [`start_writer`] ran, a message is formatted and
//! handed to a writer thread through a bounded queue, which writes it to
//! stderr. A stderr nobody reads (a full pipe: a supervisor stopped or
//! hung, a terminal scrolled back) blocks only that thread: the main loop
//! goes on serving the drives and stopping them, and what did not fit in
//! the queue ([`QUEUE_LINES`]) is dropped and counted — the next line that
//! gets through says how many were. [`flush`] waits, bounded, for the queue
//! at exit.

use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, SyncSender, TrySendError};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// Lines the queue holds before new ones are dropped.
pub const QUEUE_LINES: usize = 256;

/// How a line is logged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Level {
    Info,
    /// Info, shown also with `--quiet`.
    Notice,
    Warn,
    Error,
}

struct Writer {
    queue: SyncSender<(Level, String)>,
    /// Lines queued, written, dropped (queue full).
    queued: AtomicU64,
    written: AtomicU64,
    dropped: AtomicU64,
}

static WRITER: OnceLock<Writer> = OnceLock::new();

/// Starts the writer thread (once; later calls do nothing). Before it runs,
/// messages are logged directly. Start it before the process goes
/// real-time: the thread inherits the caller's scheduling.
pub fn start_writer() {
    let (tx, rx) = mpsc::sync_channel(QUEUE_LINES);
    if WRITER
        .set(Writer {
            queue: tx,
            queued: AtomicU64::new(0),
            written: AtomicU64::new(0),
            dropped: AtomicU64::new(0),
        })
        .is_ok()
    {
        let _ = std::thread::Builder::new()
            .name("io-log".into())
            .spawn(move || write_lines(rx));
    }
}

fn write_lines(rx: Receiver<(Level, String)>) {
    let Some(w) = WRITER.get() else { return };
    let mut told = 0;
    for (level, text) in rx {
        let dropped = w.dropped.load(Ordering::Relaxed);
        if dropped > told {
            log::warn!(
                "{} log line(s) dropped: stderr did not take them",
                dropped - told
            );
            told = dropped;
        }
        log_now(level, &text);
        w.written.fetch_add(1, Ordering::Release);
    }
}

fn log_now(level: Level, text: &str) {
    match level {
        Level::Info => log::info!("{text}"),
        Level::Notice => {
            if log::max_level() < log::LevelFilter::Info {
                log::set_max_level(log::LevelFilter::Info);
                log::info!("{text}");
                log::set_max_level(log::LevelFilter::Warn);
            } else {
                log::info!("{text}");
            }
        }
        Level::Warn => log::warn!("{text}"),
        Level::Error => log::error!("{text}"),
    }
}

fn emit(level: Level, text: String) {
    let Some(w) = WRITER.get() else {
        return log_now(level, &text);
    };
    match w.queue.try_send((level, text)) {
        Ok(()) => {
            w.queued.fetch_add(1, Ordering::Relaxed);
        }
        Err(TrySendError::Full(_) | TrySendError::Disconnected(_)) => {
            w.dropped.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// Waits until the writer has written every queued line, at most `limit`
/// (a blocked stderr never holds up the exit).
pub fn flush(limit: Duration) {
    let Some(w) = WRITER.get() else { return };
    let until = Instant::now() + limit;
    while w.written.load(Ordering::Acquire) < w.queued.load(Ordering::Relaxed)
        && Instant::now() < until
    {
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// Whether informational messages are shown.
#[derive(Clone, Copy, Debug)]
pub struct Say {
    pub quiet: bool,
}

impl Say {
    /// Informational: suppressed by `--quiet`.
    pub fn info(&self, args: fmt::Arguments<'_>) {
        if !self.quiet {
            emit(Level::Info, args.to_string());
        }
    }

    /// A one-time report of the hardware in use (the EtherCAT start-up
    /// report, the bus summary at exit): at info level, shown also with
    /// `--quiet`.
    pub fn notice(&self, args: fmt::Arguments<'_>) {
        emit(Level::Notice, args.to_string());
    }

    /// Errors, warnings and watchdog messages: always shown (a message that
    /// starts with `error: ` at error level, the rest as warnings).
    pub fn always(&self, args: fmt::Arguments<'_>) {
        let text = args.to_string();
        match text.strip_prefix("error: ") {
            Some(rest) => emit(Level::Error, rest.to_string()),
            None => emit(Level::Warn, text),
        }
    }
}

/// A condition reported once when it starts, and silently cleared when it
/// ends (so a persisting fault does not flood the log at the cycle rate).
#[derive(Clone, Copy, Debug, Default)]
pub struct Once {
    active: bool,
}

impl Once {
    /// Reports `args` if the condition was not already active.
    pub fn fail(&mut self, say: &Say, args: fmt::Arguments<'_>) {
        if !self.active {
            self.active = true;
            say.always(args);
        }
    }

    /// The condition is over; returns whether it had been active.
    pub fn clear(&mut self) -> bool {
        std::mem::take(&mut self.active)
    }
}
