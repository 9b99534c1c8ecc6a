//! The physical magnitudes the configuration's numbers are bounded by,
//! shared by many keys (positions, speeds, accelerations, torques, times);
//! each key's own range is its row in the key table ([`crate::keytable`]).
//! A value outside is a configuration problem naming the axis and the key;
//! nothing is silently clamped.
//!
//! Why bounds at all: a speed of 1e308 or a conversion constant of 1e-300
//! passes "finite and positive" and then overflows a count, a profile or a
//! timer; a watchdog of 2³² cycles is a watchdog switched off.

/// Positions (home position, offsets, travel limits, sim positions), units.
pub const POSITION: f64 = 1e9;
/// Speeds, units/s.
pub const SPEED: f64 = 1e6;
/// Accelerations and decelerations, units/s².
pub const ACCELERATION: f64 = 1e9;
/// Jerks, units/s³: the most an operation may ask for.
pub const JERK: f64 = motion_homing::MAX_JERK;
/// Largest |position| in counts: positions travel as i64 counts and are
/// converted through f64, exact up to 2^53.
pub const MAX_COUNTS: f64 = 9.0e15;
/// Torques, % rated.
pub const TORQUE: f64 = 1000.0;
/// Home timeout, s (a day).
pub const TIMEOUT_S: f64 = 86_400.0;
/// Short times (torque time, enable timeout), s.
pub const SHORT_TIME_S: f64 = 60.0;
/// The I/O process's command watchdog, ms of cycles: at most a second.
pub const WATCHDOG_MS: f64 = 1000.0;

/// EtherCAT: shortest bus cycle the backend runs, µs.
pub const ETHERCAT_MIN_CYCLE_US: u32 = 100;
/// EtherCAT: most axes (SubDevices) one EtherCAT I/O process drives.
pub const ETHERCAT_MAX_AXES: usize = 32;
