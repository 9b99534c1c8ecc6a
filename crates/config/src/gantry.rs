//! `[[gantry]]`: axes homed as one machine axis.
//!
//! The sides run the same sequence in lockstep (every leg starts on all
//! sides in the same cycle), so what decides the legs must be the same on
//! every side: mode, sequence, direction, speeds, accelerations, torque
//! settings, home order. What squares the gantry may differ: each side's own
//! switch, marker and hard stop, and its own `home_offset` / Home Position.

use crate::keys::Reader;
use crate::keytable::{gantry::*, Section};
use crate::{names, AxisEntry, Problem};

/// Most sides a gantry has.
pub const MAX_SIDES: usize = 4;

#[derive(Clone, Debug, PartialEq)]
pub struct GantryConfig {
    pub name: String,
    /// Axis indices of the sides, in the order given.
    pub axes: Vec<usize>,
    /// Units: sides whose events lie further apart fail together before
    /// anything is squared.
    pub max_skew: f64,
}

pub(crate) fn parse(
    tables: &[toml::Table],
    axes: &[AxisEntry],
    problems: &mut Vec<Problem>,
) -> Vec<GantryConfig> {
    let mut out: Vec<GantryConfig> = Vec::new();
    for (g, t) in tables.iter().enumerate() {
        let mut r = Reader::new(t, None, Section::Gantry, problems);
        let name = r.string(&NAME);
        let label = format!("gantry #{}", g + 1);
        if let Err(e) = names::check_name(&name) {
            r.problem(&NAME, format!("{label}: {e}"));
        }
        if axes.iter().any(|a| a.name == name) {
            r.problem(
                &NAME,
                format!("{label}: {} is also an axis name", names::shown(&name)),
            );
        }
        if out.iter().any(|o| o.name == name) {
            r.problem(
                &NAME,
                format!("gantry name {} used twice", names::shown(&name)),
            );
        }
        let max_skew = r.f64_in(&MAX_SKEW);
        let side_names: Vec<String> = match r.value(&AXES) {
            Some(toml::Value::Array(a)) => a
                .iter()
                .map(|v| v.as_str().map(str::to_string).unwrap_or_default())
                .collect(),
            _ => {
                r.problem(&AXES, format!("{label}: expected a list of axis names"));
                Vec::new()
            }
        };
        if !(2..=MAX_SIDES).contains(&side_names.len()) && !side_names.is_empty() {
            r.problem(
                &AXES,
                format!(
                    "{label}: {} sides; a gantry has 2..={MAX_SIDES}",
                    side_names.len()
                ),
            );
        }
        let mut sides = Vec::new();
        for n in &side_names {
            match axes.iter().position(|a| &a.name == n) {
                Some(i) if sides.contains(&i) => r.problem(
                    &AXES,
                    format!("{label}: axis {} named twice", names::shown(n)),
                ),
                Some(i) if out.iter().any(|o| o.axes.contains(&i)) => r.problem(
                    &AXES,
                    format!(
                        "{label}: axis {} is already a side of another gantry",
                        names::shown(n)
                    ),
                ),
                Some(i) => sides.push(i),
                None => r.problem(&AXES, format!("{label}: no axis {}", names::shown(n))),
            }
        }
        r.finish();
        lockstep_checks(&name, &sides, axes, problems);
        out.push(GantryConfig {
            name,
            axes: sides,
            max_skew,
        });
    }
    out
}

/// The sides must run the same legs with the same profiles.
fn lockstep_checks(gantry: &str, sides: &[usize], axes: &[AxisEntry], problems: &mut Vec<Problem>) {
    use motion_homing::{HomeMode, HomeSequence};
    let Some(&first) = sides.first() else {
        return;
    };
    let a = &axes[first];
    let e = &a.engine;
    if e.home_mode != HomeMode::Active || e.home_sequence == HomeSequence::Immediate {
        problems.push(Problem::new(
            Some(&a.name),
            "home_mode",
            format!("gantry {gantry}: sides must home actively with a sequence that moves"),
        ));
    }
    // A side that met its limit would reverse alone: its plan would leave
    // the lockstep, and the gantry would rack.
    for &i in sides
        .iter()
        .filter(|&&i| axes[i].engine.home_reverse_at_limit)
    {
        problems.push(Problem::new(
            Some(&axes[i].name),
            "home_reverse_at_limit",
            format!(
                "gantry {gantry}: a gantry's sides cannot reverse at a limit (one side would \
                 reverse alone)"
            ),
        ));
    }
    for &i in &sides[1..] {
        let b = &axes[i];
        let f = &b.engine;
        let same = [
            ("home_mode", e.home_mode == f.home_mode),
            ("home_sequence", e.home_sequence == f.home_sequence),
            ("home_direction", e.home_direction == f.home_direction),
            ("home_speed", e.home_speed == f.home_speed),
            (
                "home_return_speed",
                e.home_return_speed == f.home_return_speed,
            ),
            (
                "home_acceleration",
                e.home_acceleration == f.home_acceleration,
            ),
            (
                "home_deceleration",
                e.home_deceleration == f.home_deceleration,
            ),
            ("home_creep_speed", e.home_creep_speed == f.home_creep_speed),
            (
                "home_torque_level",
                e.home_torque_level == f.home_torque_level,
            ),
            (
                "home_torque_threshold",
                e.home_torque_threshold == f.home_torque_threshold,
            ),
            ("home_torque_time", e.home_torque_time == f.home_torque_time),
            ("travel", e.travel == f.travel),
            // A jog or move of the gantry plans every side alike.
            ("jerk", e.jerk == f.jerk),
            ("home_order", a.home_order == b.home_order),
        ];
        for (key, ok) in same {
            if !ok {
                problems.push(Problem::new(
                    Some(&b.name),
                    key,
                    format!(
                        "gantry {gantry}: differs from side {} (the sides run their legs in lockstep)",
                        a.name
                    ),
                ));
            }
        }
    }
}
