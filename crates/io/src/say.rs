//! Messages on stderr, every one prefixed `motion-io:`. `--quiet` drops the
//! informational ones; errors and watchdog messages always show.

use std::fmt;
use std::io::Write;

/// Writes one `motion-io: ...` line to stderr. Never panics: `eprintln!`
/// would, if stderr is a pipe whose reader is gone (e.g. a killed
/// supervisor's), and a failed message must not keep the axes from stopping.
pub fn line(args: fmt::Arguments<'_>) {
    let _ = writeln!(std::io::stderr().lock(), "motion-io: {args}");
}

/// Where messages go (stderr) and whether informational ones are shown.
#[derive(Clone, Copy, Debug)]
pub struct Say {
    pub quiet: bool,
}

impl Say {
    /// Informational: suppressed by `--quiet`.
    pub fn info(&self, args: fmt::Arguments<'_>) {
        if !self.quiet {
            line(args);
        }
    }

    /// Errors, warnings and watchdog messages: always shown.
    pub fn always(&self, args: fmt::Arguments<'_>) {
        line(args);
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
