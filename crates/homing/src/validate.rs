//! Configuration validation: every problem at once, each naming the attribute
//! (by its TOML key) and carrying the CIP code the instruction would report.
//!
//! Runs once, outside the real-time cycle; it may allocate.

use crate::codes::*;
use crate::config::*;
use crate::plan::creeps;
use std::fmt;

/// One configuration problem.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ConfigError {
    /// The attribute at fault, spelled as the TOML key.
    pub attribute: &'static str,
    pub err: u16,
    pub exerr: u16,
    pub message: String,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: {} (ERR {} EXERR {})",
            self.attribute, self.message, self.err, self.exerr
        )
    }
}

struct Problems(Vec<ConfigError>);

impl Problems {
    fn add(&mut self, attribute: &'static str, exerr: u16, message: String) {
        self.0.push(ConfigError {
            attribute,
            err: ERR_ILLEGAL_HOMING_CONFIG,
            exerr,
            message,
        });
    }

    /// Finite check; and `>= 0` when `non_negative`. Returns whether the value
    /// is usable for further checks.
    fn number(&mut self, attribute: &'static str, v: f64, non_negative: bool) -> bool {
        if !v.is_finite() {
            self.add(
                attribute,
                EX_BAD_NUMBER,
                format!("{v} is not a finite number"),
            );
            false
        } else if non_negative && v < 0.0 {
            self.add(attribute, EX_BAD_NUMBER, format!("{v} is negative"));
            false
        } else {
            true
        }
    }
}

/// True for the sequences that command motion (active, not Immediate).
pub fn moves(cfg: &AxisConfig) -> bool {
    cfg.home_mode == HomeMode::Active && cfg.home_sequence != HomeSequence::Immediate
}

/// Checks `cfg` and returns every problem found (empty = valid), in a
/// fixed order: numbers, scaling and travel, mode and sequence, then the
/// rules of a sequence that commands motion.
pub fn validate(cfg: &AxisConfig) -> Vec<ConfigError> {
    let mut p = Problems(Vec::new());
    // Numbers first: later rules only look at usable values.
    let usable = numbers(&mut p, cfg);
    conversion(&mut p, cfg);
    cyclic(&mut p, cfg);
    travel_limits(&mut p, cfg);
    mode_and_sequence(&mut p, cfg);
    limit_switch_homing(&mut p, cfg, &usable);
    if moves(cfg) {
        motion(&mut p, cfg, &usable);
        above_max_speed(&mut p, cfg, &usable);
        torque_levels(&mut p, cfg, &usable);
    }
    p.0
}

/// Which of the numbers later rules look at are usable (finite, and not
/// negative where that matters).
struct Usable {
    speed: bool,
    return_speed: bool,
    acceleration: bool,
    deceleration: bool,
    torque_level: bool,
    torque_threshold: bool,
    max_speed: bool,
}

/// Every number finite, and not negative where a negative value means
/// nothing; `max_position` also above zero.
fn numbers(p: &mut Problems, cfg: &AxisConfig) -> Usable {
    p.number("home_position", cfg.home_position, false);
    p.number("home_offset", cfg.home_offset, false);
    let speed = p.number("home_speed", cfg.home_speed, true);
    let return_speed = p.number("home_return_speed", cfg.home_return_speed, true);
    let acceleration = p.number("home_acceleration", cfg.home_acceleration, true);
    let deceleration = p.number("home_deceleration", cfg.home_deceleration, true);
    let torque_level = p.number("home_torque_level", cfg.home_torque_level, true);
    let torque_threshold = p.number("home_torque_threshold", cfg.home_torque_threshold, true);
    for (key, v) in [
        ("home_torque_time", cfg.home_torque_time),
        ("home_timeout", cfg.home_timeout),
        ("search_limit", cfg.search_limit),
        ("home_creep_speed", cfg.home_creep_speed),
        ("torque_limit", cfg.torque_limit),
        ("position_error_tolerance", cfg.position_error_tolerance),
        ("velocity_error_tolerance", cfg.velocity_error_tolerance),
        ("enable_timeout", cfg.enable_timeout),
        ("feedback_loss_drain", cfg.feedback_loss_drain),
        ("unhomed_speed", cfg.unhomed_speed),
        ("max_deceleration", cfg.max_deceleration),
        ("stream_acceleration", cfg.stream_acceleration),
    ] {
        p.number(key, v, true);
    }
    let max_speed = p.number("max_speed", cfg.max_speed, true);
    p.number("marker_min_distance", cfg.marker_min_distance, true);
    if p.number("max_position", cfg.max_position, true) && cfg.max_position == 0.0 {
        p.add("max_position", EX_BAD_NUMBER, "must be positive".into());
    }
    Usable {
        speed,
        return_speed,
        acceleration,
        deceleration,
        torque_level,
        torque_threshold,
        max_speed,
    }
}

/// The conversion constant (counts per unit) is a positive number.
fn conversion(p: &mut Problems, cfg: &AxisConfig) {
    if !cfg.counts_per_unit.is_finite() || cfg.counts_per_unit <= 0.0 {
        p.add(
            "counts_per_unit",
            EX_CONVERSION_CONSTANT,
            format!(
                "conversion constant {} must be a positive number",
                cfg.counts_per_unit
            ),
        );
    }
}

/// A cyclic axis has a positive unwind, and its Home Position lies in one
/// revolution.
fn cyclic(p: &mut Problems, cfg: &AxisConfig) {
    if cfg.travel != TravelMode::Cyclic {
        return;
    }
    if !cfg.unwind.is_finite() || cfg.unwind <= 0.0 {
        p.add(
            "unwind",
            EX_UNWIND,
            format!("cyclic axis needs a positive unwind, got {}", cfg.unwind),
        );
    } else if cfg.home_position.is_finite()
        && !(cfg.home_position >= 0.0 && cfg.home_position < cfg.unwind)
    {
        p.add(
            "home_position",
            EX_CYCLIC_HOME_POSITION,
            format!(
                "{} is outside [0, {}) of the cyclic axis",
                cfg.home_position, cfg.unwind
            ),
        );
    }
}

/// The travel limits are an interval, and a linear axis's Home Position
/// lies in it.
fn travel_limits(p: &mut Problems, cfg: &AxisConfig) {
    let Some((lo, hi)) = cfg.travel_limits else {
        return;
    };
    if !lo.is_finite() || !hi.is_finite() || lo >= hi {
        p.add(
            "travel_limits",
            EX_TRAVEL_LIMITS,
            format!("[{lo}, {hi}] is not an interval"),
        );
    } else if cfg.travel == TravelMode::Linear
        && cfg.home_position.is_finite()
        && !(lo..=hi).contains(&cfg.home_position)
    {
        p.add(
            "home_position",
            EX_HOME_POSITION_LIMITS,
            format!(
                "{} is outside the travel limits [{lo}, {hi}]",
                cfg.home_position
            ),
        );
    }
}

/// The home mode and sequence suit the axis: absolute mode on an absolute
/// encoder with the immediate sequence, active homing on a servo axis,
/// nothing but immediate on a virtual axis, no torque sequence passive, a
/// marker for a marker sequence.
fn mode_and_sequence(p: &mut Problems, cfg: &AxisConfig) {
    let seq = cfg.home_sequence;
    if cfg.home_mode == HomeMode::Absolute {
        if seq != HomeSequence::Immediate {
            p.add(
                "home_sequence",
                EX_SEQUENCE_INCOMPATIBLE,
                "absolute home mode takes the immediate sequence only".into(),
            );
        }
        if !cfg.absolute {
            p.add(
                "home_mode",
                EX_ABSOLUTE_NOT_ABSOLUTE,
                "absolute home mode on a non-absolute feedback device (absolute = false)".into(),
            );
        }
    }
    if cfg.home_mode == HomeMode::Active && cfg.configuration == AxisConfiguration::FeedbackOnly {
        p.add(
            "home_mode",
            EX_ACTIVE_ON_FEEDBACK_ONLY,
            "active homing needs a servo axis; a feedback-only axis can only home passive".into(),
        );
    }
    if cfg.configuration == AxisConfiguration::Virtual && seq != HomeSequence::Immediate {
        p.add(
            "home_sequence",
            EX_SEQUENCE_INCOMPATIBLE,
            "a virtual axis has no switch, marker or drive: only immediate homing applies".into(),
        );
    }
    if cfg.home_mode == HomeMode::Passive && seq.uses_torque() {
        p.add(
            "home_sequence",
            EX_SEQUENCE_INCOMPATIBLE,
            "torque sequences need commanded motion into a hard stop: not valid for passive homing"
                .into(),
        );
    }
    if seq.uses_marker() && !cfg.marker {
        p.add(
            "home_sequence",
            EX_NO_MARKER,
            "marker sequence but the feedback device has no marker (marker = false)".into(),
        );
    }
}

/// The limit-switch sequences and `home_reverse_at_limit` (see
/// `axis::at_limit`): active, bidirectional, on an axis with limit switches
/// (a cyclic axis has no ends); a limit-switch home ends off the switch;
/// only a bidirectional switch or switch-then-marker search reverses.
fn limit_switch_homing(p: &mut Problems, cfg: &AxisConfig, ok: &Usable) {
    let seq = cfg.home_sequence;
    let reverse = cfg.home_reverse_at_limit;
    if !(seq.uses_limit_switch() || reverse) {
        return;
    }
    let (key, what) = if seq.uses_limit_switch() {
        ("home_sequence", "homing on a limit switch")
    } else {
        ("home_reverse_at_limit", "reversing at a limit switch")
    };
    if !cfg.limit_switches {
        p.add(
            "limit_switches",
            EX_NO_LIMIT_SWITCHES,
            format!("{what} needs limit switches (limit_switches = false)"),
        );
    }
    if cfg.travel == TravelMode::Cyclic {
        p.add(
            key,
            EX_NO_LIMIT_SWITCHES,
            format!("{what}: a cyclic axis has no ends of travel, so no limit switches"),
        );
    }
    if reverse && !reverses(cfg) {
        p.add(
            "home_reverse_at_limit",
            EX_REVERSE_NOT_APPLICABLE,
            format!(
                "only an active bidirectional switch or switch_then_marker search can \
                 reverse at a limit, not {} {} {} (a unidirectional search cannot reverse: \
                 it stops with ERR 12 / EXERR 43 at a limit)",
                cfg.home_mode, cfg.home_sequence, cfg.home_direction
            ),
        );
    }
    if !seq.uses_limit_switch() {
        return;
    }
    if cfg.home_mode == HomeMode::Passive {
        p.add(
            "home_sequence",
            EX_SEQUENCE_INCOMPATIBLE,
            "limit switch sequences command the motion onto the limit and off it: not valid \
             for passive homing"
                .into(),
        );
    }
    if !moves(cfg) {
        return;
    }
    if cfg.home_direction.is_unidirectional() {
        p.add(
            "home_direction",
            EX_LIMIT_UNIDIRECTIONAL,
            "a limit switch sequence comes back off the limit it seeks: only bidirectional \
             directions are valid"
                .into(),
        );
    } else if cfg.home_offset.is_finite() && ok.return_speed {
        limit_offset(p, cfg);
    }
}

/// `home_reverse_at_limit` applies: an active bidirectional switch or
/// switch-then-marker sequence (the plans [`plan::after_reversal`](crate::plan::after_reversal) knows).
fn reverses(cfg: &AxisConfig) -> bool {
    moves(cfg)
        && matches!(
            cfg.home_sequence,
            HomeSequence::Switch | HomeSequence::SwitchThenMarker
        )
        && !cfg.home_direction.is_unidirectional()
}

/// A limit-switch home must not park the axis on the switch: Home Position
/// is the event plus the offset.
///
/// * `limit_switch`: the event is the clear point, the switch's very edge,
///   so the offset must point away from the limit, into the travel, by
///   more than one cycle of travel at Home Return Speed — twice the worst
///   error of a sampled clear point, so Home Position is off the switch
///   however the edge was sampled.
/// * `limit_switch_then_marker` (CiA 402 methods 1 and 2, commonly used
///   with no offset): the event is the first marker found once the switch
///   has cleared, beyond its clear point, so a zero offset rests on the
///   marker, off the switch, and an offset into the travel only adds
///   distance. An offset towards the limit is refused: how far the marker
///   lies from the switch is the machine's, not the configuration's. (A
///   marker within the clear point's own sampling error of it is an
///   ambiguous marker: `marker_min_distance` flags or refuses it.)
///
/// The switch's repeatability and hysteresis are the machine's: the README
/// asks for an offset that covers them too.
fn limit_offset(p: &mut Problems, cfg: &AxisConfig) {
    let dir = cfg.home_direction.sign();
    let on_marker = cfg.home_sequence == HomeSequence::LimitSwitchThenMarker;
    let margin = if on_marker {
        0.0
    } else {
        cfg.home_return_speed * cfg.cycle_ns as f64 * 1e-9
    };
    let off = if on_marker {
        cfg.home_offset * dir <= 0.0
    } else {
        cfg.home_offset * dir < -margin
    };
    if off {
        return;
    }
    let (limit, sign) = if dir > 0.0 {
        ("positive", "negative")
    } else {
        ("negative", "positive")
    };
    let must = if on_marker {
        format!(
            "limit_switch_then_marker rests on its marker, beyond the switch's clear point: the \
             offset must be 0 or {sign} (away from the limit, into the travel)"
        )
    } else {
        format!(
            "the offset must be {sign} (away from the limit, into the travel) by more than \
             {margin} units, one cycle of travel at home_return_speed; choose a distance that \
             also covers the switch's repeatability"
        )
    };
    p.add(
        "home_offset",
        EX_LIMIT_OFFSET,
        format!(
            "{} would leave the axis at (or on) the {limit} limit switch it homes on: {must}",
            cfg.home_offset
        ),
    );
}

/// A sequence that commands motion: a control mode that follows a
/// position, a direction that can come back from a hard stop, and speeds,
/// acceleration and deceleration that are not zero where a leg uses them.
fn motion(p: &mut Problems, cfg: &AxisConfig, ok: &Usable) {
    let seq = cfg.home_sequence;
    if cfg.control_mode == ControlMode::Torque {
        p.add(
            "control_mode",
            EX_TORQUE_CONTROL_MODE,
            "active homing needs position or velocity control mode".into(),
        );
    }
    if seq.uses_torque() && cfg.home_direction.is_unidirectional() {
        p.add(
            "home_direction",
            EX_UNIDIRECTIONAL_TORQUE,
            "torque sequences push into a hard stop and come back: only bidirectional directions are valid".into(),
        );
    }
    if ok.speed && cfg.home_speed == 0.0 {
        p.add(
            "home_speed",
            EX_HOME_SPEED_ZERO,
            "home speed is zero".into(),
        );
    }
    let uses_return = !cfg.home_direction.is_unidirectional() || seq.uses_torque();
    if ok.return_speed && uses_return && cfg.home_return_speed == 0.0 {
        p.add(
            "home_return_speed",
            EX_RETURN_SPEED_ZERO,
            "home return speed is zero".into(),
        );
    }
    if ok.acceleration && cfg.home_acceleration == 0.0 {
        p.add(
            "home_acceleration",
            EX_ACCELERATION_ZERO,
            "home acceleration is zero: the axis could never start".into(),
        );
    }
    if ok.deceleration && cfg.home_deceleration == 0.0 {
        p.add(
            "home_deceleration",
            EX_DECELERATION_ZERO,
            "home deceleration is zero: the axis could never stop".into(),
        );
    }
}

/// No commanded speed above `max_speed`: the axis's own feedback would be
/// refused as implausible.
fn above_max_speed(p: &mut Problems, cfg: &AxisConfig, ok: &Usable) {
    if !(ok.max_speed && cfg.max_speed > 0.0) {
        return;
    }
    for (key, v) in commanded_speeds(cfg) {
        if v > cfg.max_speed {
            p.add(
                key,
                EX_ABOVE_MAX_SPEED,
                format!(
                    "{v} units/s is above max_speed {} units/s, the fastest the axis \
                     can move: its own feedback would be refused as implausible",
                    cfg.max_speed
                ),
            );
        }
    }
}

/// A torque sequence: a level in (0, 100] % and a threshold above zero and
/// at most the level, or the hard stop could never be detected.
fn torque_levels(p: &mut Problems, cfg: &AxisConfig, ok: &Usable) {
    if !(cfg.home_sequence.uses_torque() && ok.torque_level && ok.torque_threshold) {
        return;
    }
    let (lvl, thr) = (cfg.home_torque_level, cfg.home_torque_threshold);
    if lvl == 0.0 || lvl > 100.0 {
        p.add(
            "home_torque_level",
            EX_TORQUE_LEVEL,
            format!("{lvl} % is not in (0, 100] %"),
        );
    } else if thr == 0.0 || thr > lvl {
        p.add(
            "home_torque_threshold",
            EX_TORQUE_LEVEL,
            format!(
                "{thr} % must be above 0 and at most the torque level {lvl} %, \
                 or the hard stop can never be detected"
            ),
        );
    }
}

/// The homing speeds the configured sequence commands, by TOML key: Home
/// Speed; Home Return Speed where a leg after the first or the move home
/// uses it; the creep speed where a creep leg runs. None for a sequence that
/// commands no motion.
fn commanded_speeds(cfg: &AxisConfig) -> impl Iterator<Item = (&'static str, f64)> {
    let m = moves(cfg);
    let uses_return = !cfg.home_direction.is_unidirectional() || cfg.home_sequence.uses_torque();
    [
        ("home_speed", cfg.home_speed, m),
        ("home_return_speed", cfg.home_return_speed, m && uses_return),
        ("home_creep_speed", cfg.home_creep_speed, m && creeps(cfg)),
    ]
    .into_iter()
    .filter(|&(_, v, used)| used && v.is_finite() && v > 0.0)
    .map(|(k, v, _)| (k, v))
}

/// The fastest plausible speed, units/s, for the feedback plausibility check:
/// `max_speed` when set, else twice the fastest speed the sequence commands
/// (the axis never moves faster than its command, and twice leaves room for
/// a lagging frame). `None` = no check: a passive or immediate axis commands
/// nothing, and its homing speeds (which CIP defines for active homing only)
/// say nothing about how fast something else may move it.
pub fn effective_max_speed(cfg: &AxisConfig) -> Option<f64> {
    if cfg.max_speed.is_finite() && cfg.max_speed > 0.0 {
        return Some(cfg.max_speed);
    }
    let fastest = commanded_speeds(cfg).map(|(_, v)| v).fold(0.0, f64::max);
    (fastest > 0.0).then_some(2.0 * fastest)
}

/// Search limit in force: explicit, else derived from the travel limits
/// (110 % of the span: a search may start at one end and find its switch at
/// the other), else two revolutions on a cyclic axis, else unbounded.
pub fn effective_search_limit(cfg: &AxisConfig) -> f64 {
    if cfg.search_limit > 0.0 {
        cfg.search_limit
    } else if let Some((lo, hi)) = cfg.travel_limits {
        1.1 * (hi - lo)
    } else if cfg.travel == TravelMode::Cyclic && cfg.unwind > 0.0 {
        2.0 * cfg.unwind
    } else {
        f64::INFINITY
    }
}

/// What `check` says about a limit-switch sequence or a search that
/// reverses at a limit: which limit, what is suspended, its CiA 402 and
/// PLCopen names, how the search limit counts.
fn limit_notes(cfg: &AxisConfig, out: &mut Vec<String>) {
    let Some(e) = crate::equivalent::equivalent(cfg) else {
        return;
    };
    let limit = if cfg.home_direction.sign() > 0.0 {
        "positive"
    } else {
        "negative"
    };
    let names = format!(
        "CiA 402 homing method {}, PLCopen {}",
        e.cia402_method, e.plcopen
    );
    if cfg.home_sequence.uses_limit_switch() {
        out.push(format!(
            "home_sequence {}: homes on its {limit} limit switch ({names}); the overtravel stop \
             is suspended while seeking that limit and stopping on it; an EtherCAT drive in CSP \
             may stop at its own 0x60FD limit bits (see the README)",
            cfg.home_sequence
        ));
    } else {
        out.push(format!(
            "home_reverse_at_limit: a search that meets the {limit} limit switch before the home \
             switch reverses, passes the switch and searches again ({names}); search_limit \
             bounds each leg of it (seek, run back, new seek) and home_timeout the whole"
        ));
    }
}

/// Things that are legal but that a controls engineer would want pointed out.
/// `cycle_s` is the controller period.
pub fn advisories(cfg: &AxisConfig, cycle_s: f64) -> Vec<String> {
    let mut out = Vec::new();
    if moves(cfg) && effective_search_limit(cfg).is_infinite() {
        out.push(
            "search_limit: no search limit and no travel limits: a search that never finds its \
             event runs until the timeout or a hardware limit"
                .into(),
        );
    }
    let seq = cfg.home_sequence;
    limit_notes(cfg, &mut out);
    if seq.uses_switch() && !cfg.registration {
        let v = if moves(cfg) && !cfg.home_direction.is_unidirectional() {
            cfg.home_return_speed
        } else {
            cfg.home_speed
        };
        let switch = if seq.uses_limit_switch() {
            "limit switch"
        } else {
            "home switch"
        };
        if v > 0.0 && !seq.uses_marker() {
            out.push(format!(
                "{switch} sampled once per cycle: event uncertainty up to {:.6} units \
                 (half of {v} units/s x {cycle_s} s); registration = true or a marker sequence \
                 removes it",
                0.5 * v * cycle_s
            ));
        }
    }
    if seq.uses_marker() && cfg.marker && !cfg.marker_latch {
        let creeps =
            moves(cfg) && !cfg.home_direction.is_unidirectional() && cfg.home_creep_speed > 0.0;
        if !creeps {
            out.push(format!(
                "marker without a position latch and no creep leg: the marker is known only to \
                 half a cycle of travel ({cycle_s} s x speed / 2); set home_creep_speed \
                 (bidirectional) or use a drive that latches"
            ));
        }
    }
    if moves(cfg)
        && !cfg.home_direction.is_unidirectional()
        && cfg.home_return_speed > cfg.home_speed
    {
        out.push("home_return_speed is above home_speed: the precise leg is the fast one".into());
    }
    if cfg.home_timeout == 0.0 && moves(cfg) {
        out.push("home_timeout = 0: homing has no time limit".into());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn active_switch() -> AxisConfig {
        AxisConfig {
            home_sequence: HomeSequence::Switch,
            home_speed: 10.0,
            home_return_speed: 1.0,
            home_acceleration: 100.0,
            home_deceleration: 100.0,
            ..AxisConfig::default()
        }
    }

    fn codes(cfg: &AxisConfig) -> Vec<(&'static str, u16)> {
        validate(cfg)
            .iter()
            .map(|e| (e.attribute, e.exerr))
            .collect()
    }

    #[test]
    fn valid_config_has_no_problems() {
        assert!(validate(&active_switch()).is_empty());
        assert!(
            validate(&AxisConfig::default()).is_empty(),
            "immediate needs nothing"
        );
    }

    #[test]
    fn cip_codes_for_zero_speeds() {
        let cfg = AxisConfig {
            home_speed: 0.0,
            home_return_speed: 0.0,
            ..active_switch()
        };
        assert_eq!(
            codes(&cfg),
            vec![("home_speed", 6), ("home_return_speed", 7)]
        );
    }

    #[test]
    fn unidirectional_does_not_need_return_speed() {
        let cfg = AxisConfig {
            home_direction: HomeDirection::UnidirectionalReverse,
            home_return_speed: 0.0,
            ..active_switch()
        };
        assert!(validate(&cfg).is_empty());
    }

    #[test]
    fn every_problem_reported_at_once() {
        let cfg = AxisConfig {
            configuration: AxisConfiguration::FeedbackOnly,
            control_mode: ControlMode::Torque,
            travel: TravelMode::Cyclic,
            unwind: 360.0,
            home_position: 360.0,
            home_direction: HomeDirection::UnidirectionalForward,
            home_sequence: HomeSequence::TorqueThenMarker,
            home_speed: f64::NAN,
            home_return_speed: -1.0,
            home_acceleration: 0.0,
            home_deceleration: 0.0,
            home_torque_level: 30.0,
            home_torque_threshold: 40.0,
            ..AxisConfig::default()
        };
        let got = codes(&cfg);
        for want in [
            ("home_speed", EX_BAD_NUMBER),
            ("home_return_speed", EX_BAD_NUMBER),
            ("home_position", EX_CYCLIC_HOME_POSITION),
            ("home_mode", EX_ACTIVE_ON_FEEDBACK_ONLY),
            ("home_sequence", EX_NO_MARKER),
            ("control_mode", EX_TORQUE_CONTROL_MODE),
            ("home_direction", EX_UNIDIRECTIONAL_TORQUE),
            ("home_acceleration", EX_ACCELERATION_ZERO),
            ("home_deceleration", EX_DECELERATION_ZERO),
            ("home_torque_threshold", EX_TORQUE_LEVEL),
        ] {
            assert!(got.contains(&want), "missing {want:?} in {got:?}");
        }
        assert!(validate(&cfg).iter().all(|e| e.err == 41));
    }

    #[test]
    fn passive_torque_and_virtual_switch_are_incompatible() {
        let cfg = AxisConfig {
            home_mode: HomeMode::Passive,
            home_sequence: HomeSequence::Torque,
            ..AxisConfig::default()
        };
        assert_eq!(codes(&cfg), vec![("home_sequence", 4)]);
        let cfg = AxisConfig {
            configuration: AxisConfiguration::Virtual,
            ..active_switch()
        };
        assert_eq!(codes(&cfg), vec![("home_sequence", 4)]);
    }

    #[test]
    fn limits_and_conversion() {
        let cfg = AxisConfig {
            counts_per_unit: 0.0,
            travel_limits: Some((-10.0, 10.0)),
            home_position: 11.0,
            ..active_switch()
        };
        assert_eq!(
            codes(&cfg),
            vec![("counts_per_unit", 30), ("home_position", 31)]
        );
        let cfg = AxisConfig {
            travel_limits: Some((10.0, -10.0)),
            ..active_switch()
        };
        assert_eq!(codes(&cfg), vec![("travel_limits", 32)]);
    }

    #[test]
    fn search_limit_derivation() {
        let mut cfg = active_switch();
        assert!(effective_search_limit(&cfg).is_infinite());
        cfg.travel_limits = Some((-100.0, 100.0));
        assert!((effective_search_limit(&cfg) - 220.0).abs() < 1e-9);
        cfg.search_limit = 50.0;
        assert_eq!(effective_search_limit(&cfg), 50.0);
        assert!(!advisories(&cfg, 0.001).is_empty());
    }
}
