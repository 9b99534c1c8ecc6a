//! The keys of limit-switch homing: `[axis.sim] limit_switches` (and its old
//! spelling `overtravel`), `limit_switches_normally_closed`,
//! `home_reverse_at_limit`, `limit_switches`, the new sequences, and the
//! problems each may have — every one by axis and key, with the CIP code
//! where the engine's validation finds it.

use motion_config::{parse, Problem};
use motion_plant::RegistrationInput;

/// An axis homing on its negative limit, with `extra` keys appended to the
/// axis and `sim` to its `[axis.sim]`.
fn machine(extra: &str, sim: &str) -> String {
    format!(
        "[[axis]]\nname = \"X\"\nhome_sequence = \"limit_switch\"\n\
         home_direction = \"bidirectional_reverse\"\nhome_offset = 2.0\nhome_speed = 20.0\n\
         home_return_speed = 2.0\nhome_acceleration = 500.0\nhome_deceleration = 500.0\n\
         {extra}\n[axis.sim]\nstart = 0.0\nhard_stop = [-100.0, 100.0]\n{sim}\n"
    )
}

fn problems(text: &str) -> Vec<String> {
    parse(text)
        .err()
        .unwrap_or_default()
        .iter()
        .map(Problem::to_string)
        .collect()
}

#[track_caller]
fn refused_with(text: &str, want: &str) {
    let p = problems(text);
    assert!(
        p.iter().any(|l| l.starts_with(want)),
        "missing {want:?} in {p:#?}"
    );
}

#[test]
fn limit_switches_and_the_old_spelling() {
    let m = parse(&machine("", "limit_switches = [-90.0, 90.0]")).unwrap();
    let x = &m.axes[0];
    assert_eq!(x.sim.overtravel, Some((-90.0, 90.0)));
    assert!(!x.sim.limit_switches_normally_closed);
    assert!(
        x.engine.limit_switches,
        "default: the axis has limit switches"
    );
    // The probe input is wired to the limit the axis homes on.
    assert_eq!(x.sim.registration_input, RegistrationInput::NegativeLimit);

    let m = parse(&machine(
        "",
        "overtravel = [-90.0, 90.0]\nlimit_switches_normally_closed = true",
    ))
    .unwrap();
    assert_eq!(m.axes[0].sim.overtravel, Some((-90.0, 90.0)));
    assert!(m.axes[0].sim.limit_switches_normally_closed);

    refused_with(
        &machine(
            "",
            "limit_switches = [-90.0, 90.0]\novertravel = [-90.0, 90.0]",
        ),
        "axis X: sim.overtravel: given together with limit_switches",
    );
    refused_with(
        &machine("", "limit_switches = [90.0, -90.0]"),
        "axis X: sim.limit_switches: [90, -90]: low must be below high",
    );
}

#[test]
fn a_sim_axis_homing_on_a_limit_needs_one_with_room_to_stop() {
    refused_with(
        &machine("", ""),
        "axis X: sim.limit_switches: missing: the axis homes on a limit switch",
    );
    // The seek at 20 u/s stops 0.4 + 2 × 0.02 = 0.44 past the limit: the
    // negative limit at -99.7 leaves 0.3 before the hard stop at -100.
    refused_with(
        &machine("", "limit_switches = [-99.7, 90.0]"),
        "axis X: sim.limit_switches: the negative limit switch ends 0.3",
    );
    // The positive side does not matter for a reverse search.
    assert!(parse(&machine("", "limit_switches = [-99.5, 99.9]")).is_ok());
    // An axis on an EtherCAT drive: [axis.sim] is not its plant.
    let ecat = format!(
        "[[io]]\nname = \"bus0\"\nbackend = \"ethercat\"\ninterface = \"eth0\"\n{}",
        machine("ethercat_position = 0", "")
    );
    assert!(parse(&ecat).is_ok(), "{:#?}", problems(&ecat));
}

#[test]
fn the_engine_rules_by_axis_key_and_code() {
    let sim = "limit_switches = [-90.0, 90.0]";
    for (extra, want) in [
        (
            "limit_switches = false",
            "axis X: limit_switches: homing on a limit switch needs limit switches \
             (limit_switches = false) (ERR 41 EXERR 38)",
        ),
        (
            "home_offset = 0.001",
            "axis X: home_offset: 0.001 would leave the axis at (or on) the negative limit",
        ),
        (
            "home_direction = \"unidirectional_reverse\"",
            "axis X: home_direction: a limit switch sequence comes back off the limit",
        ),
        (
            "home_sequence = \"limit_switch_then_marker\"",
            "axis X: home_sequence: marker sequence but the feedback device has no marker",
        ),
        (
            "home_sequence = \"marker\"\nmarker = true\nhome_reverse_at_limit = true",
            "axis X: home_reverse_at_limit: only an active bidirectional switch or \
             switch_then_marker search can reverse at a limit",
        ),
    ] {
        // Later keys of the same name win in this test's TOML: rebuild the
        // axis with `extra` replacing its own line.
        let key = extra.split(' ').next().unwrap();
        let text = machine("", sim)
            .lines()
            .filter(|l| !l.starts_with(&format!("{key} ")))
            .chain(std::iter::once(""))
            .collect::<Vec<_>>()
            .join("\n")
            .replacen("[axis.sim]", &format!("{extra}\n[axis.sim]"), 1);
        refused_with(&text, want);
    }
    // 41/36 carries its code, and the margin is one cycle at R: 2 u/s ×
    // 1 ms = 0.002 with the default 1 ms cycle.
    let p = problems(&machine("", sim).replace("home_offset = 2.0", "home_offset = 0.002"));
    assert!(p[0].ends_with("(ERR 41 EXERR 36)"), "{p:#?}");
    assert!(parse(&machine("", sim).replace("home_offset = 2.0", "home_offset = 0.0021")).is_ok());
}

#[test]
fn a_gantry_cannot_reverse_at_a_limit() {
    let side = |name: &str| {
        format!(
            "[[axis]]\nname = \"{name}\"\nhome_sequence = \"switch\"\nhome_speed = 20.0\n\
             home_return_speed = 2.0\nhome_acceleration = 500.0\nhome_deceleration = 500.0\n\
             home_reverse_at_limit = true\n[axis.sim]\nswitch = [0.0, 5.0]\n\
             limit_switches = [-90.0, 90.0]\nhard_stop = [-100.0, 100.0]\n"
        )
    };
    let text = format!(
        "{}{}[[gantry]]\nname = \"Y\"\naxes = [\"Y1\", \"Y2\"]\nmax_skew = 1.0\n",
        side("Y1"),
        side("Y2")
    );
    refused_with(
        &text,
        "axis Y1: home_reverse_at_limit: gantry Y: a gantry's sides cannot reverse at a limit",
    );
    // Alone, each side may.
    assert!(parse(&side("Y1")).is_ok(), "{:#?}", problems(&side("Y1")));
}
