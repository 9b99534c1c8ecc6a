//! The keys of the operations around homing (declared in
//! [`crate::keytable::operations`]):
//! `unhomed_speed`, `limit_switches`, `max_deceleration`,
//! `stream_acceleration`, `stream_timeout_ms`, `stream_unhomed`, `jerk`
//! (`travel_limits` and `max_speed` are read with the homing keys).
//!
//! A number left out takes its default from the homing attributes, and the
//! engine resolves it (`motion_homing::op_limits`), so `check`, the engine
//! and the control plane agree; a number given must be above zero (zero
//! would mean "none", which for a speed cap or a deceleration is not a
//! setting but a machine that cannot move or stop).

use crate::keys::{num, Reader};
use crate::keytable::operations::*;
use motion_homing::AxisConfig;

/// Reads the keys into `engine` (which holds the homing keys already).
pub(crate) fn keys(r: &mut Reader<'_>, engine: &mut AxisConfig) {
    let home_speed = engine.home_speed;
    let home_deceleration = engine.home_deceleration;
    let home_acceleration = engine.home_acceleration;
    engine.unhomed_speed =
        r.f64_positive(&UNHOMED_SPEED, &format!("home_speed ({})", num(home_speed)));
    engine.limit_switches = r.bool(&LIMIT_SWITCHES);
    engine.max_deceleration = r.f64_positive(
        &MAX_DECELERATION,
        &format!("home_deceleration ({})", num(home_deceleration)),
    );
    engine.stream_acceleration = r.f64_positive(
        &STREAM_ACCELERATION,
        &format!("10 × home_acceleration ({})", num(10.0 * home_acceleration)),
    );
    let ms = r.f64_in(&STREAM_TIMEOUT_MS);
    engine.stream_timeout_ns = (ms * 1e6).round() as u64;
    engine.stream_unhomed = r.bool(&STREAM_UNHOMED);
    engine.jerk = r.f64_in(&JERK_KEY);
}
