//! The physical ranges every number of the configuration must lie in — one
//! table, also printed in the README. A value outside is a configuration
//! problem naming the axis and the key; nothing is silently clamped.
//!
//! Why bounds at all: a speed of 1e308 or a conversion constant of 1e-300
//! passes "finite and positive" and then overflows a count, a profile or a
//! timer; a watchdog of 2³² cycles is a watchdog switched off.

/// `(key, low, high, unit)`: the inclusive range of a number.
pub type Range = (&'static str, f64, f64, &'static str);

/// Cycle period.
pub const CYCLE_US: (u32, u32) = (50, 100_000);
/// Positions (home position, offsets, travel limits, sim positions), units.
pub const POSITION: f64 = 1e9;
/// Speeds, units/s.
pub const SPEED: f64 = 1e6;
/// Accelerations and decelerations, units/s².
pub const ACCELERATION: f64 = 1e9;
/// Conversion constant, counts per unit.
pub const COUNTS_PER_UNIT: (f64, f64) = (1e-6, 1e9);
/// Largest |position| in counts: positions travel as i64 counts and are
/// converted through f64, exact up to 2^53.
pub const MAX_COUNTS: f64 = 9.0e15;
/// Torques, % rated.
pub const TORQUE: f64 = 1000.0;
/// Home timeout, s (a day).
pub const TIMEOUT_S: f64 = 86_400.0;
/// Short times (torque time, enable timeout), s.
pub const SHORT_TIME_S: f64 = 60.0;
/// Feedback-loss time bound, ms: at least a millisecond, at most a second
/// (a larger value would switch the detection of a dead I/O process off).
pub const FEEDBACK_TIMEOUT_MS: (f64, f64) = (1.0, 1000.0);
/// The I/O process's command watchdog, ms of cycles: at most a second.
pub const WATCHDOG_MS: f64 = 1000.0;
/// A silent setpoint stream stops its axes after this long, ms: at least a
/// millisecond, at most a second (longer is no supervision).
pub const STREAM_TIMEOUT_MS: (f64, f64) = (1.0, 1000.0);

/// EtherCAT: SM watchdog of the drives, ms (and at least 3 cycles).
pub const SM_WATCHDOG_MS: (u32, u32) = (1, 1000);
/// EtherCAT: shortest bus cycle the backend runs, µs.
pub const ETHERCAT_MIN_CYCLE_US: u32 = 100;
/// EtherCAT: reply deadline of a bus frame, µs (and at most 95 % of the cycle).
pub const REPLY_TIMEOUT_US: (u32, u32) = (10, 95_000);
/// EtherCAT: INIT → OP limit, s.
pub const STARTUP_TIMEOUT_S: (u32, u32) = (1, 300);
/// EtherCAT: rounds of static drift compensation at start-up.
pub const DC_STATIC_SYNC_ITERATIONS: (u32, u32) = (0, 100_000);
/// EtherCAT: bus position of an axis' drive.
pub const ETHERCAT_POSITION: (u32, u32) = (0, 65_535);
/// EtherCAT: manufacturer-specific bits of 0x60FD.
pub const INDEX_PULSE_BIT: (u32, u32) = (16, 31);
/// EtherCAT: most axes (SubDevices) one EtherCAT I/O process drives.
pub const ETHERCAT_MAX_AXES: usize = 32;
/// EtherCAT: the quick stop's bound before disable voltage, ms.
pub const QUICK_STOP_TIMEOUT_MS: (u32, u32) = (10, 10_000);
/// EtherCAT: a vertical axis's brake delay (disable operation → disable
/// voltage), ms.
pub const BRAKE_DELAY_MS: (u32, u32) = (0, 2_000);
/// EtherCAT: CiA 402 homing methods (0x6098, a signed byte; 0 = none).
pub const DRIVE_HOMING_METHOD: (i32, i32) = (-128, 127);

/// The table as the README prints it.
pub const TABLE: &[Range] = &[
    ("[supervisor] cycle_us", 50.0, 100_000.0, "µs"),
    ("[supervisor] priority", 1.0, 99.0, "SCHED_FIFO"),
    (
        "[supervisor] io_priority, [[io]] priority",
        0.0,
        99.0,
        "0 = normal",
    ),
    ("[supervisor] feedback_timeout_ms", 1.0, 1000.0, "ms"),
    ("[supervisor] feedback_loss_drain", 0.0, 1.0, ""),
    ("[supervisor] io_watchdog_cycles × cycle", 1.0, 1000.0, "ms"),
    (
        "positions (home_position, home_offset, travel_limits, max_position, drift_limit, marker_min_distance, max_skew, sim.*)",
        -POSITION,
        POSITION,
        "units",
    ),
    (
        "speeds (home_speed, home_return_speed, home_creep_speed, max_speed, sim.external_speed)",
        0.0,
        SPEED,
        "units/s",
    ),
    (
        "home_acceleration, home_deceleration",
        0.0,
        ACCELERATION,
        "units/s²",
    ),
    (
        "counts_per_unit",
        1e-6,
        1e9,
        "counts/unit (and max_position × counts_per_unit ≤ 9e15)",
    ),
    (
        "torques (home_torque_level, home_torque_threshold, torque_limit)",
        0.0,
        TORQUE,
        "% rated",
    ),
    ("home_timeout", 0.0, TIMEOUT_S, "s"),
    ("home_torque_time, enable_timeout", 0.0, SHORT_TIME_S, "s"),
    (
        "[[io]] sm_watchdog_ms (EtherCAT; also ≥ 3 × cycle_us)",
        1.0,
        1000.0,
        "ms",
    ),
    (
        "[[io]] reply_timeout_us (EtherCAT; also ≤ 95 % of cycle_us)",
        10.0,
        95_000.0,
        "µs",
    ),
    ("[[io]] startup_timeout_s (EtherCAT)", 1.0, 300.0, "s"),
    (
        "[[io]] dc_static_sync_iterations (EtherCAT)",
        0.0,
        100_000.0,
        "",
    ),
    ("ethercat_position", 0.0, 65_535.0, "bus position"),
    ("ethercat_index_pulse_bit", 16.0, 31.0, "bit of 0x60FD"),
    ("unhomed_speed (above 0)", 0.0, SPEED, "units/s"),
    (
        "max_deceleration, stream_acceleration (above 0)",
        0.0,
        ACCELERATION,
        "units/s²",
    ),
    ("stream_timeout_ms", 1.0, 1000.0, "ms"),
    ("[[io]] quick_stop_timeout_ms (EtherCAT)", 10.0, 10_000.0, "ms"),
    ("ethercat_home_switch_bit", 16.0, 31.0, "bit of 0x60FD"),
    ("ethercat_brake_delay_ms", 0.0, 2_000.0, "ms"),
    ("drive_homing_method", -128.0, 127.0, "CiA 402 method, not 0"),
];
