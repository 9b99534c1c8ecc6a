//! Command-line values, checked by the same rules as the config file (clap
//! `value_parser`s shared by every binary).

use crate::names;
use std::path::PathBuf;

/// `--service-prefix P`.
pub fn service_prefix(s: &str) -> Result<String, String> {
    names::check_service_prefix(s).map(|()| s.to_string())
}

/// An axis name.
pub fn axis(s: &str) -> Result<String, String> {
    names::check_name(s).map(|()| s.to_string())
}

/// An I/O process name.
pub fn io(s: &str) -> Result<String, String> {
    names::check_io_name(s).map(|()| s.to_string())
}

/// `--interface IF`: a network interface name.
pub fn interface(s: &str) -> Result<String, String> {
    names::check_interface_name(s).map(|()| s.to_string())
}

/// Seconds: a finite positive number of at most a day.
pub fn seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 && x <= 86_400.0 => Ok(x),
        _ => Err(format!(
            "{} is not a number of seconds in (0, 86400]",
            names::shown(s)
        )),
    }
}

/// `--runtime-dir DIR`: absolute, short, no `..` (the domain checks the
/// directory itself: owner, mode, not a symlink).
pub fn runtime_dir(s: &str) -> Result<PathBuf, String> {
    if !s.starts_with('/') || s.contains("..") || s.len() > RUNTIME_DIR_MAX {
        return Err(format!(
            "{} must be an absolute path of at most {RUNTIME_DIR_MAX} characters without \"..\"",
            names::shown(s)
        ));
    }
    Ok(PathBuf::from(s))
}

/// A CPU that exists on this machine.
pub fn cpu(s: &str) -> Result<usize, String> {
    let n: i64 = s
        .parse()
        .map_err(|_| format!("{} is not a CPU number", names::shown(s)))?;
    crate::check_cpu(n).map(|()| n as usize)
}

/// Longest runtime directory: iceoryx2 puts its event sockets directly in it,
/// named `{file prefix}{40 hex}.event`, and a unix socket path has at most 107
/// bytes. With a 32-character service prefix ([`crate::names::PREFIX_MAX`])
/// that leaves 19. Defined once, here, where the user's value is checked
/// first; `motion-ipc` checks it again when it creates the directory.
pub const RUNTIME_DIR_MAX: usize = 19;

/// A position, distance, speed or acceleration of an operation (`motionctl
/// jog`, `move`): a finite number of at most 1e9 in magnitude (the axis's
/// own bounds — `max_speed`, `travel_limits`, ... — are the supervisor's to
/// judge, with the instruction's error codes).
pub fn number(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x.is_finite() && x.abs() <= 1e9 => Ok(x),
        _ => Err(format!(
            "{} is not a finite number in [-1e9, 1e9]",
            names::shown(s)
        )),
    }
}
