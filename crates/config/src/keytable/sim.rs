//! `[axis.sim]`: the simulated plant behind an axis.

use super::{keys, Key, Kind, Section::AxisSim, Status};
use crate::limits::*;
use motion_plant::config::{
    DEFAULT_ENABLE_DELAY_CYCLES, DEFAULT_FRICTION, DEFAULT_INERTIA_GAIN, DEFAULT_PUSH_GAIN,
};

keys! {
    GROUP {
        section: AxisSim,
        title: "[axis.sim]",
        intro: "The simulated drive and mechanics behind an axis on the `sim` backend (and the \
                emulated EtherCAT drives of the tests). Positions are raw positions, in the \
                axis's units.",
    }
    START: Key::new(AxisSim, "start", Kind::Number)
        .num(0.0)
        .range(-POSITION, POSITION)
        .unit("units")
        .fixed()
        .meaning("Raw position at power-up.")
        .example("-50.0");
    SWITCH: Key::new(AxisSim, "switch", Kind::Interval)
        .unset("no home switch")
        .range(-POSITION, POSITION)
        .unit("units")
        .fixed()
        .meaning("The raw interval in which the home switch is actuated (wired as \
                  `home_switch_normally_closed` says).")
        .example("[0.0, 5.0]");
    MARKER_EVERY: Key::new(AxisSim, "marker_every", Kind::Number)
        .num(0.0)
        .range(0.0, POSITION)
        .unit("units")
        .fixed()
        .meaning("Raw distance between markers (one per revolution of the encoder); 0: one marker, \
                  at `marker_at`.")
        .example("10.0");
    MARKER_AT: Key::new(AxisSim, "marker_at", Kind::Number)
        .num(0.0)
        .range(-POSITION, POSITION)
        .unit("units")
        .fixed()
        .meaning("Raw position of one marker.")
        .example("2.5");
    HARD_STOP: Key::new(AxisSim, "hard_stop", Kind::Interval)
        .unset("no mechanical ends")
        .range(-POSITION, POSITION)
        .unit("units")
        .fixed()
        .meaning("The raw mechanical ends: pushing into one raises the torque.")
        .example("[-100.0, 100.0]");
    LIMIT_SWITCHES: Key::new(AxisSim, "limit_switches", Kind::Interval)
        .unset("no limit switches")
        .range(-POSITION, POSITION)
        .unit("units")
        .fixed()
        .meaning("The negative limit switch is actuated at or below the first number, the \
                  positive one at or above the second. An axis that homes on a limit switch or \
                  reverses at one needs them, with room to stop before the hard stop.")
        .example("[-120.0, 120.0]");
    OVERTRAVEL: Key::new(AxisSim, "overtravel", Kind::Interval)
        .unset("no limit switches")
        .range(-POSITION, POSITION)
        .unit("units")
        .status(Status::Alias("limit_switches"))
        .meaning("The older name of `limit_switches`, read with its rule (actuated at the ends); \
                  not together with it.")
        .example("[-120.0, 120.0]");
    LIMIT_SWITCHES_NORMALLY_CLOSED: Key::new(AxisSim, "limit_switches_normally_closed", Kind::Bool)
        .flag(false)
        .meaning("The limit switches are wired normally closed: a cut wire reads both actuated, \
                  and the drive faults.")
        .example("true");
    EXTERNAL_SPEED: Key::new(AxisSim, "external_speed", Kind::Number)
        .num(0.0)
        .range(-SPEED, SPEED)
        .unit("units/s")
        .fixed()
        .meaning("Passive homing: something else moves the axis at this speed (signed).")
        .example("5.0");
    PUSH_GAIN: Key::new(AxisSim, "push_gain", Kind::Number)
        .num(DEFAULT_PUSH_GAIN)
        .range(0.0, 1e6)
        .unit("% per unit")
        .meaning("Torque that pushing one unit into a hard stop raises.")
        .example("100.0");
    INERTIA_GAIN: Key::new(AxisSim, "inertia_gain", Kind::Number)
        .num(DEFAULT_INERTIA_GAIN)
        .range(0.0, 1e3)
        .unit("% per unit/s²")
        .meaning("Torque per unit of acceleration.")
        .example("0.01");
    FRICTION: Key::new(AxisSim, "friction", Kind::Number)
        .num(DEFAULT_FRICTION)
        .range(0.0, TORQUE)
        .unit("% rated")
        .meaning("Torque of friction while moving.")
        .example("1.0");
    ENABLE_DELAY_CYCLES: Key::new(AxisSim, "enable_delay_cycles", Kind::Integer)
        .int(DEFAULT_ENABLE_DELAY_CYCLES as i64)
        .range(0.0, 10_000.0)
        .unit("cycles")
        .meaning("Cycles the simulated drive takes to report enabled.")
        .example("2");
}
