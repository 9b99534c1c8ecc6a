//! The TOML spellings of the enums (fixed by interface.md), in one place:
//! parsing reads them and reports print them.

use motion_homing::{
    AxisConfiguration as AC, ControlMode as CM, HomeDirection as HD, HomeMode as HM,
    HomeSequence as HS, TravelMode as TM,
};

pub const CONFIGURATIONS: &[(&str, AC)] = &[
    ("servo", AC::Servo),
    ("feedback_only", AC::FeedbackOnly),
    ("virtual", AC::Virtual),
];
pub const CONTROL_MODES: &[(&str, CM)] = &[
    ("position", CM::Position),
    ("velocity", CM::Velocity),
    ("torque", CM::Torque),
];
pub const TRAVEL_MODES: &[(&str, TM)] = &[("linear", TM::Linear), ("cyclic", TM::Cyclic)];
pub const HOME_MODES: &[(&str, HM)] = &[
    ("active", HM::Active),
    ("passive", HM::Passive),
    ("absolute", HM::Absolute),
];
pub const HOME_DIRECTIONS: &[(&str, HD)] = &[
    ("unidirectional_forward", HD::UnidirectionalForward),
    ("bidirectional_forward", HD::BidirectionalForward),
    ("unidirectional_reverse", HD::UnidirectionalReverse),
    ("bidirectional_reverse", HD::BidirectionalReverse),
];
pub const HOME_SEQUENCES: &[(&str, HS)] = &[
    ("immediate", HS::Immediate),
    ("switch", HS::Switch),
    ("marker", HS::Marker),
    ("switch_then_marker", HS::SwitchThenMarker),
    ("torque", HS::Torque),
    ("torque_then_marker", HS::TorqueThenMarker),
];

/// The spelling of `v` in `table` (every variant is in its table).
pub fn name_of<T: PartialEq>(table: &[(&'static str, T)], v: T) -> &'static str {
    table.iter().find(|(_, t)| *t == v).map_or("?", |(n, _)| n)
}
