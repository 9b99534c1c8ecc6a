//! No input makes the config reader panic, and whatever it accepts is safe
//! for the engine: arbitrary bytes, arbitrary TOML built from the real keys
//! with hostile values (NaN, ±inf, 1e308, huge integers, control
//! characters, wrong types, huge strings).

use motion_homing::{Axis, DriveState, Feedback, Request};
use proptest::prelude::*;

#[rustfmt::skip]
const SUPERVISOR_KEYS: &[&str] = &[
    "cycle_us", "cpu", "priority", "io", "service_prefix", "feedback_timeout_ms",
    "feedback_loss_drain", "stale_cycles", "io_watchdog_cycles", "lock_memory", "io_priority",
    "io_cpu", "cpu_dma_latency_us", "runtime_dir", "bogus",
];
#[rustfmt::skip]
const AXIS_KEYS: &[&str] = &[
    "name", "io", "configuration", "control_mode", "travel", "unwind", "counts_per_unit",
    "marker", "registration", "home_mode", "home_direction", "home_sequence",
    "home_switch_normally_closed", "home_position", "home_offset", "home_speed",
    "home_return_speed", "home_acceleration", "home_deceleration", "home_torque_level",
    "home_torque_threshold", "home_torque_time", "home_timeout", "home_creep_speed",
    "search_limit", "torque_limit", "max_position", "travel_limits", "home_order",
    "enable_timeout", "marker_latch", "ethercat_position", "ethercat_name",
    "ethercat_index_pulse_bit", "home_reverse_at_limit", "limit_switches",
];
#[rustfmt::skip]
const IO_KEYS: &[&str] = &[
    "spawn", "cpu", "priority", "backend", "interface", "dc", "sm_watchdog_ms",
    "reply_timeout_us", "startup_timeout_s", "mode_in_pdo", "dc_static_sync_iterations",
];
#[rustfmt::skip]
const SIM_KEYS: &[&str] = &[
    "start", "switch", "marker_every", "marker_at", "hard_stop", "overtravel",
    "external_speed", "push_gain", "inertia_gain", "friction", "enable_delay_cycles",
    "limit_switches", "limit_switches_normally_closed",
];
#[rustfmt::skip]
const WORDS: &[&str] = &[
    "sim", "external", "servo", "feedback_only", "virtual", "position", "velocity", "torque",
    "linear", "cyclic", "active", "passive", "absolute", "bidirectional_forward",
    "unidirectional_reverse", "switch", "marker", "switch_then_marker", "torque_then_marker",
    "immediate", "X", "io", "bus0", "a/b", "\u{1b}[31m", "", "../x", "ethercat", "supervisor",
    "eth0", "auto", "on", "off", "limit_switch", "limit_switch_then_marker",
];

#[rustfmt::skip]
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        prop::sample::select(vec![
            "nan", "inf", "-inf", "1e308", "-1e308", "1e-300", "0", "-0.0", "4294967295",
            "9223372036854775807", "-1", "true", "false", "[]", "[1]", "[1, 2]", "[inf, -inf]",
            "[nan, 0]", "{}", "[[1]]", "\"\"",
        ])
        .prop_map(str::to_string),
        any::<f64>().prop_map(|x| format!("{x:?}")),
        any::<i64>().prop_map(|x| x.to_string()),
        prop::sample::select(WORDS.to_vec()).prop_map(|w| format!("{w:?}")),
        "[ -~]{0,40}".prop_map(|s| format!("{s:?}")),
        (1usize..200_000).prop_map(|n| format!("\"{}\"", "n".repeat(n))),
    ]
}

fn table(keys: &'static [&'static str]) -> impl Strategy<Value = String> {
    prop::collection::vec((prop::sample::select(keys.to_vec()), value()), 0..12).prop_map(|kv| {
        let mut seen = Vec::new();
        let mut out = String::new();
        for (k, v) in kv {
            if !seen.contains(&k) {
                seen.push(k);
                out += &format!("{k} = {v}\n");
            }
        }
        out
    })
}

fn machine() -> impl Strategy<Value = String> {
    (
        table(SUPERVISOR_KEYS),
        prop::collection::vec((table(AXIS_KEYS), table(SIM_KEYS)), 0..4),
        prop::collection::vec(table(IO_KEYS), 0..3),
    )
        .prop_map(|(sup, axes, ios)| {
            let mut t = format!("[supervisor]\n{sup}\n");
            for (k, io) in ios.iter().enumerate() {
                t += &format!("[[io]]\nname = \"bus{k}\"\n{io}\n");
            }
            for (i, (a, s)) in axes.iter().enumerate() {
                t += &format!("[[axis]]\nname = \"A{i}\"\n{a}\n[axis.sim]\n{s}\n");
            }
            t
        })
}

/// What the config accepts must be safe for the engine: step it with
/// garbage feedback and look at the commands.
fn engine_survives(m: &motion_config::MachineConfig) {
    for a in &m.axes {
        let mut ax = Axis::new(a.engine);
        let req = Request {
            home: true,
            ..Request::default()
        };
        for (k, x) in [0.0, f64::NAN, 1e300, -5.0, f64::INFINITY, 3.0]
            .iter()
            .enumerate()
        {
            let fb = Feedback {
                position: *x,
                velocity: *x,
                torque: *x,
                drive: DriveState {
                    enabled: true,
                    fault: false,
                },
                ..Feedback::default()
            };
            let c = ax.step(k as u64 * 1_000_000, Some(&fb), &req);
            assert!(c.position.is_finite() && c.velocity.is_finite(), "{c:?}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..2048)) {
        let text = String::from_utf8_lossy(&bytes);
        if let Ok(m) = motion_config::parse(&text) {
            engine_survives(&m);
        }
    }

    #[test]
    fn hostile_toml_is_refused_by_key_or_safe(text in machine()) {
        match motion_config::parse(&text) {
            Ok(m) => engine_survives(&m),
            Err(problems) => {
                prop_assert!(!problems.is_empty());
                for p in &problems {
                    let line = p.to_string();
                    // Never echoes a huge or escaping value.
                    prop_assert!(line.len() < 1000, "{}", line.len());
                    prop_assert!(!line.contains('\x1b'), "escape in {}", line);
                }
            }
        }
    }
}
