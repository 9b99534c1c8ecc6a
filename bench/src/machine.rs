//! The machines the benches generate: the demo machine's axes with another
//! `[supervisor]` section (period, CPU, priority, service prefix), and the
//! machines of the soak, dead-peer and 64-axis benches. Written by code, not
//! kept as fixtures: their size and timing are the benches' parameters, and
//! `soak --print-config` shows the text as generated here.

use motion_config::{MachineConfig, DEMO_TOML};
use motion_harness::machines::checked;
use std::fmt::Write as _;

/// What goes into `[supervisor]`.
#[derive(Clone, Debug)]
pub struct Supervisor {
    pub cycle_us: u32,
    pub cpu: usize,
    pub priority: i32,
    pub service_prefix: String,
}

/// Which machine a `motion-supervisor run` of the jitter bench drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Machine {
    /// `deploy/demo.toml`'s four axes, idle (frames exchanged, no homing).
    Demo,
    /// [`axes64_with`]: 64 axes, homed all in parallel again and again.
    Axes64,
}

impl Machine {
    pub fn name(self) -> &'static str {
        match self {
            Machine::Demo => "demo",
            Machine::Axes64 => "axes64",
        }
    }

    /// `demo`, `axes64`.
    pub fn parse(s: &str) -> Result<Self, String> {
        match s {
            "demo" => Ok(Machine::Demo),
            "axes64" => Ok(Machine::Axes64),
            _ => Err(format!("{s:?}: not a machine (demo, axes64)")),
        }
    }

    /// The machine's config text with `s` as its `[supervisor]` section.
    pub fn with(self, s: &Supervisor) -> Result<(String, MachineConfig), String> {
        match self {
            Machine::Demo => demo_with(s),
            Machine::Axes64 => axes64_with(s),
        }
    }
}

/// A `[supervisor]` section with nothing but `s` (and, if given,
/// `state_dir`): every other key at its default (`feedback_timeout_ms` 10,
/// `io_watchdog_cycles` 50, motion-io spawned on the cycle's CPU at
/// priority − 10, `cpu_dma_latency_us` 0).
fn default_section(s: &Supervisor, state_dir: Option<&str>) -> String {
    let mut t = format!(
        "[supervisor]\n\
         cycle_us = {}\n\
         cpu = {}\n\
         priority = {}\n\
         io = \"sim\"\n\
         service_prefix = \"{}\"\n",
        s.cycle_us, s.cpu, s.priority, s.service_prefix
    );
    if let Some(d) = state_dir {
        let _ = writeln!(t, "state_dir = \"{d}\"");
    }
    t.push('\n');
    t
}

/// The four kinds of axis of the 64-axis machine, in the order they repeat.
pub const AXES64_KINDS: [&str; 4] = [
    "S: switch (bidirectional forward, offset -3)",
    "M: switch then marker (the demo's X, closer)",
    "C: cyclic marker, unidirectional (the demo's C)",
    "T: torque into a hard stop (the demo's Z, closer)",
];

/// Number of axes of [`axes64_with`].
pub const AXES64: usize = 64;

/// A 64-axis machine (the most one supervisor drives) whose axes all have
/// `home_order = 0`: "home every axis" homes all 64 in parallel. Four kinds
/// of axis repeat (`S00`, `M01`, `C02`, `T03`, `S04`, ...; [`AXES64_KINDS`]),
/// each one's plant a little shifted so that the events do not all fall in
/// the same cycle. Every axis ends where it can be homed again at once, so
/// the machine can be homed over and over; one parallel homing of all 64
/// takes about 1.5 s (the torque axes, once at their stop, are the slowest).
pub fn axes64_with(s: &Supervisor) -> Result<(String, MachineConfig), String> {
    let mut t = String::from(
        "# Written by motion-bench: 64 axes, all home_order = 0 (homed in parallel).\n",
    );
    t += &default_section(s, None);
    for i in 0..AXES64 {
        // 0.0 .. 0.93 units of shift, different for neighbours
        let d = ((i * 37) % 32) as f64 * 0.03;
        let _ = match i % 4 {
            0 => write!(
                t,
                "[[axis]]\nname = \"S{i:02}\"\nconfiguration = \"servo\"\ncontrol_mode = \"position\"\n\
                 travel = \"linear\"\ncounts_per_unit = 1000.0\nmarker = false\nhome_mode = \"active\"\n\
                 home_direction = \"bidirectional_forward\"\nhome_sequence = \"switch\"\n\
                 home_position = 0.0\nhome_offset = -3.0\nhome_speed = 20.0\nhome_return_speed = 5.0\n\
                 home_acceleration = 500.0\nhome_deceleration = 500.0\nhome_timeout = 20.0\nhome_order = 0\n\
                 travel_limits = [-100.0, 100.0]\n\n\
                 [axis.sim]\nstart = {:.3}\nswitch = [{d:.3}, {:.3}]\nhard_stop = [-110.0, 110.0]\n\n",
                -3.0 + d,
                d + 5.0
            ),
            1 => write!(
                t,
                "[[axis]]\nname = \"M{i:02}\"\nconfiguration = \"servo\"\ncontrol_mode = \"position\"\n\
                 travel = \"linear\"\ncounts_per_unit = 1000.0\nmarker = true\nhome_mode = \"active\"\n\
                 home_direction = \"bidirectional_forward\"\nhome_sequence = \"switch_then_marker\"\n\
                 home_position = 0.0\nhome_offset = 0.0\nhome_speed = 20.0\nhome_return_speed = 8.0\n\
                 home_acceleration = 500.0\nhome_deceleration = 500.0\nhome_timeout = 20.0\nhome_order = 0\n\
                 travel_limits = [-100.0, 100.0]\nposition_error_tolerance = 1.0\n\n\
                 [axis.sim]\nstart = {:.3}\nswitch = [{d:.3}, {:.3}]\nmarker_every = 10.0\nmarker_at = {:.3}\n\
                 hard_stop = [-110.0, 110.0]\novertravel = [-105.0, 105.0]\n\n",
                -5.0 + d,
                d + 5.0,
                d - 2.5
            ),
            2 => write!(
                t,
                "[[axis]]\nname = \"C{i:02}\"\nconfiguration = \"servo\"\ncontrol_mode = \"position\"\n\
                 travel = \"cyclic\"\nunwind = 360.0\ncounts_per_unit = 1000.0\nmarker = true\n\
                 home_mode = \"active\"\nhome_direction = \"unidirectional_forward\"\nhome_sequence = \"marker\"\n\
                 home_position = 0.0\nhome_offset = 45.0\nhome_speed = 180.0\nhome_return_speed = 10.0\n\
                 home_acceleration = 1440.0\nhome_deceleration = 1440.0\nhome_timeout = 20.0\nhome_order = 0\n\n\
                 [axis.sim]\nstart = {:.3}\nmarker_every = 360.0\nmarker_at = {:.3}\n\n",
                d * 10.0,
                123.4 + d * 10.0
            ),
            _ => write!(
                t,
                "[[axis]]\nname = \"T{i:02}\"\nconfiguration = \"servo\"\ncontrol_mode = \"position\"\n\
                 travel = \"linear\"\ncounts_per_unit = 1000.0\nmarker = false\nhome_mode = \"active\"\n\
                 home_direction = \"bidirectional_reverse\"\nhome_sequence = \"torque\"\n\
                 home_position = 0.0\nhome_offset = 2.0\nhome_speed = 10.0\nhome_return_speed = 4.0\n\
                 home_acceleration = 200.0\nhome_deceleration = 200.0\nhome_torque_level = 40.0\n\
                 home_torque_threshold = 25.0\nhome_torque_time = 0.02\nhome_timeout = 20.0\nhome_order = 0\n\
                 travel_limits = [-35.0, 200.0]\nposition_error_tolerance = 0.5\n\n\
                 [axis.sim]\nstart = {:.3}\nhard_stop = [-30.0, 210.0]\n\n",
                -26.0 + d
            ),
        };
    }
    checked(t)
}

/// A one-axis machine `X`: a plain switch homing (bidirectional forward,
/// Home Offset −3, so it ends 3 units before the switch and can be homed
/// again at once; ~0.9 s per homing) at the supervisor's default settings
/// (the soak bench).
pub fn one_switch_axis_with(
    s: &Supervisor,
    state_dir: Option<&str>,
) -> Result<(String, MachineConfig), String> {
    let mut t = String::from("# Written by motion-bench: one switch axis, default settings.\n");
    t += &default_section(s, state_dir);
    t += "[[axis]]\nname = \"X\"\nconfiguration = \"servo\"\ncontrol_mode = \"position\"\n\
          travel = \"linear\"\ncounts_per_unit = 1000.0\nmarker = false\nhome_mode = \"active\"\n\
          home_direction = \"bidirectional_forward\"\nhome_sequence = \"switch\"\n\
          home_position = 0.0\nhome_offset = -3.0\nhome_speed = 20.0\nhome_return_speed = 5.0\n\
          home_acceleration = 500.0\nhome_deceleration = 500.0\nhome_timeout = 20.0\n\n\
          [axis.sim]\nstart = -3.0\nswitch = [0.0, 5.0]\nhard_stop = [-100.0, 100.0]\n";
    checked(t)
}

/// A one-axis machine `X` whose switch homing starts with a long seek at
/// `speed` units/s (the switch is `distance` units away): the dead-peer
/// bench signals motion-io while the axis cruises.
pub fn long_seek_axis_with(
    s: &Supervisor,
    state_dir: Option<&str>,
    speed: f64,
    distance: f64,
) -> Result<(String, MachineConfig), String> {
    let mut t = String::from("# Written by motion-bench: one switch axis with a long seek.\n");
    t += &default_section(s, state_dir);
    let _ = write!(
        t,
        "[[axis]]\nname = \"X\"\nconfiguration = \"servo\"\ncontrol_mode = \"position\"\n\
         travel = \"linear\"\ncounts_per_unit = 1000.0\nmarker = false\nhome_mode = \"active\"\n\
         home_direction = \"bidirectional_forward\"\nhome_sequence = \"switch\"\n\
         home_position = 0.0\nhome_offset = 0.0\nhome_speed = {speed}\nhome_return_speed = 5.0\n\
         home_acceleration = 500.0\nhome_deceleration = 500.0\nhome_timeout = 0.0\n\n\
         [axis.sim]\nstart = {:.3}\nswitch = [0.0, 5.0]\nhard_stop = [{:.3}, 100.0]\n",
        -distance,
        -distance - 100.0
    );
    checked(t)
}

/// The demo machine (`deploy/demo.toml`) with `s` as its `[supervisor]`
/// section, checked by `motion_config::parse`.
pub fn demo_with(s: &Supervisor) -> Result<(String, MachineConfig), String> {
    let start = DEMO_TOML
        .find("[supervisor]")
        .ok_or("deploy/demo.toml has no [supervisor] section")?;
    let end = DEMO_TOML[start..]
        .find("[[axis]]")
        .map(|i| start + i)
        .ok_or("deploy/demo.toml has no [[axis]]")?;
    let section = format!(
        "[supervisor]\n\
         cycle_us = {}\n\
         cpu = {}\n\
         priority = {}\n\
         io = \"sim\"\n\
         service_prefix = \"{}\"\n\
         feedback_timeout_ms = 10\n\
         io_watchdog_cycles = 50\n\
         cpu_dma_latency_us = 0\n\n",
        s.cycle_us, s.cpu, s.priority, s.service_prefix
    );
    checked(format!(
        "# Written by motion-bench: deploy/demo.toml's axes, [supervisor] changed.\n{}{}{}",
        &DEMO_TOML[..start],
        section,
        &DEMO_TOML[end..]
    ))
}

/// `counts_per_unit` of every axis of [`streamed_with`]: 1e5, so that
/// consecutive setpoints of the stream bench's latency ramp (≥ 25 counts
/// apart) are told apart in the command frames.
pub const STREAMED_COUNTS_PER_UNIT: f64 = 1e5;

/// A machine of `n` linear axes `A00`.. for streaming (immediate homing:
/// homed where they stand, no motion; all `home_order = 0`, travel ±1000,
/// max_speed 100, stream_acceleration from home_acceleration 1000 →
/// 10,000 u/s²), not checked (the daemon that runs it checks it).
pub fn streamed_with(s: &Supervisor, n: usize) -> String {
    let mut t = format!("# Written by motion-bench stream: {n} linear axes, immediate homing.\n");
    t += &default_section(s, None);
    for i in 0..n {
        let _ = write!(
            t,
            "[[axis]]\nname = \"A{i:02}\"\ncounts_per_unit = {STREAMED_COUNTS_PER_UNIT}\n\
             home_sequence = \"immediate\"\nhome_order = 0\nhome_speed = 10.0\n\
             home_return_speed = 2.0\nhome_acceleration = 1000.0\nhome_deceleration = 1000.0\n\
             max_speed = 100.0\ntravel_limits = [-1000.0, 1000.0]\n\
             [axis.sim]\nstart = 0.0\nhard_stop = [-1100.0, 1100.0]\n\n"
        );
    }
    t
}

/// The axis names of [`streamed_with`].
pub fn streamed_names(n: usize) -> Vec<String> {
    (0..n).map(|i| format!("A{i:02}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sup(prefix: &str) -> Supervisor {
        Supervisor {
            cycle_us: 1000,
            cpu: 1,
            priority: 80,
            service_prefix: prefix.into(),
        }
    }

    #[test]
    fn axes64_is_valid_and_parallel() {
        let (text, m) = Machine::Axes64.with(&sup("mb_t64")).unwrap();
        assert_eq!(m.axes.len(), AXES64);
        assert_eq!(m.axes.len(), motion_config::MAX_AXES);
        assert_eq!(text.matches("\nhome_order = 0\n").count(), AXES64);
        assert!(m.axes.iter().all(|a| a.home_order == Some(0)));
        assert_eq!(m.supervisor.service_prefix, "mb_t64");
        assert_eq!(m.supervisor.feedback_timeout_ms, 10.0);
        let names: std::collections::BTreeSet<_> = m.axes.iter().map(|a| &a.name).collect();
        assert_eq!(names.len(), AXES64);
    }

    #[test]
    fn one_axis_machines_are_valid() {
        let (_, m) = one_switch_axis_with(&sup("mb_t1"), Some("/tmp/mb-state")).unwrap();
        assert_eq!(m.axes.len(), 1);
        assert_eq!(m.supervisor.feedback_timeout_ms, 10.0, "default settings");
        let (_, m) = long_seek_axis_with(&sup("mb_t2"), None, 20.0, 1000.0).unwrap();
        assert_eq!(m.axes.len(), 1);
        assert!(Machine::parse("demo").is_ok() && Machine::parse("x").is_err());
    }

    #[test]
    fn streamed_machines_are_valid() {
        for n in [1, 2, AXES64] {
            let (_, m) = checked(streamed_with(&sup("mb_ts"), n)).unwrap();
            let names: Vec<String> = m.axes.iter().map(|a| a.name.clone()).collect();
            assert_eq!(names, streamed_names(n));
            assert!(m.axes.iter().all(|a| a.home_order == Some(0)));
        }
    }

    #[test]
    fn changes_only_the_supervisor() {
        let (_, m) = demo_with(&Supervisor {
            cycle_us: 125,
            cpu: 0,
            priority: 70,
            service_prefix: "mb_test".into(),
        })
        .unwrap();
        let demo = motion_config::parse(DEMO_TOML).unwrap();
        // The axes are the demo's; only what is stated per cycle differs:
        // the ambiguous-marker distance is two cycles of return travel, and
        // the engine's cycle.
        let same = |a: &[motion_config::AxisEntry]| {
            let mut a = a.to_vec();
            for x in &mut a {
                x.engine.marker_min_distance = 0.0;
                x.engine.cycle_ns = 0;
            }
            a
        };
        assert_eq!(same(&m.axes), same(&demo.axes));
        assert_eq!(
            m.axes[1].engine.feedback_timeout_ns, 10_000_000,
            "the same time at 8 kHz"
        );
        assert_eq!(m.supervisor.cycle_us, 125);
        assert_eq!(m.supervisor.cpu, 0);
        assert_eq!(m.supervisor.priority, 70);
        assert_eq!(m.supervisor.io_priority, 60);
        assert_eq!(m.supervisor.service_prefix, "mb_test");
        assert!(demo_with(&Supervisor {
            cycle_us: 5,
            cpu: 0,
            priority: 70,
            service_prefix: "x".into(),
        })
        .is_err());
    }
}
