//! Messages through the `log` facade (journald-friendly, see
//! `motion_rt::logging`). `--quiet` drops the informational ones; errors and
//! watchdog messages always show.

use std::fmt;

/// Whether informational messages are shown.
#[derive(Clone, Copy, Debug)]
pub struct Say {
    pub quiet: bool,
}

impl Say {
    /// Informational: suppressed by `--quiet`.
    pub fn info(&self, args: fmt::Arguments<'_>) {
        if !self.quiet {
            log::info!("{args}");
        }
    }

    /// A one-time report of the hardware in use (the EtherCAT start-up
    /// report, the bus summary at exit): at info level, shown also with
    /// `--quiet`.
    pub fn notice(&self, args: fmt::Arguments<'_>) {
        if self.quiet {
            log::set_max_level(log::LevelFilter::Info);
            log::info!("{args}");
            log::set_max_level(log::LevelFilter::Warn);
        } else {
            log::info!("{args}");
        }
    }

    /// Errors, warnings and watchdog messages: always shown (a message that
    /// starts with `error: ` at error level, the rest as warnings).
    pub fn always(&self, args: fmt::Arguments<'_>) {
        let text = args.to_string();
        match text.strip_prefix("error: ") {
            Some(rest) => log::error!("{rest}"),
            None => log::warn!("{text}"),
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
