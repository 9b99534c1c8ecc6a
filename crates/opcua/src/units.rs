//! Engineering units (OPC UA `EUInformation`, UNECE Recommendation 20
//! codes) of every number we publish.
//!
//! An axis's positions are in whatever its `counts_per_unit` makes them:
//! with `[opcua] units = { X = "mm" }` they are millimetres (and its speeds
//! mm/s, …); without, a generic unit of our own namespace (`unitId` −1,
//! "units"), which says exactly what the config says.

use crate::space::{Kind, NAMESPACE_URI};
use motion_config::opcua::Unit;
use opcua::types::{EUInformation, LocalizedText, UAString};

/// The namespace of UNECE unit ids (OPC UA Part 8).
const UNECE: &str = "http://www.opcfoundation.org/UA/units/un/cefact";

/// A UNECE common code as the OPC UA `unitId`: its characters, big-endian.
pub fn unece_id(code: &str) -> i32 {
    code.bytes().fold(0i32, |acc, b| (acc << 8) | i32::from(b))
}

fn unece(code: &str, symbol: &str, description: &str) -> EUInformation {
    EUInformation {
        namespace_uri: UAString::from(UNECE),
        unit_id: unece_id(code),
        display_name: LocalizedText::new("", symbol),
        description: LocalizedText::new("", description),
    }
}

fn generic(symbol: &str, description: &str) -> EUInformation {
    EUInformation {
        namespace_uri: UAString::from(NAMESPACE_URI),
        unit_id: -1,
        display_name: LocalizedText::new("", symbol),
        description: LocalizedText::new("", description),
    }
}

/// The unit of a number of `kind` on an axis with `unit` (`None` for
/// unit-less numbers).
pub fn eu(kind: Kind, unit: Option<Unit>) -> Option<EUInformation> {
    use Unit::*;
    Some(match (kind, unit) {
        (Kind::Plain, _) => return None,
        (Kind::Torque, _) => unece("P1", "%", "percent of rated torque"),
        (Kind::Seconds, _) => unece("SEC", "s", "second"),
        (Kind::Micros, _) => unece("B98", "µs", "microsecond"),
        (Kind::Position, Some(Millimetre)) => unece("MMT", "mm", "millimetre"),
        (Kind::Position, Some(Metre)) => unece("MTR", "m", "metre"),
        (Kind::Position, Some(Inch)) => unece("INH", "in", "inch"),
        (Kind::Position, Some(Degree)) => unece("DD", "°", "degree"),
        (Kind::Position, Some(Radian)) => unece("C81", "rad", "radian"),
        (Kind::Speed, Some(Millimetre)) => unece("C16", "mm/s", "millimetre per second"),
        (Kind::Speed, Some(Metre)) => unece("MTS", "m/s", "metre per second"),
        (Kind::Speed, Some(Inch)) => unece("IU", "in/s", "inch per second"),
        (Kind::Speed, Some(Degree)) => unece("E96", "°/s", "degree per second"),
        (Kind::Speed, Some(Radian)) => unece("2A", "rad/s", "radian per second"),
        (Kind::Acceleration, Some(Millimetre)) => {
            unece("M41", "mm/s²", "millimetre per second squared")
        }
        (Kind::Acceleration, Some(Metre)) => unece("MSK", "m/s²", "metre per second squared"),
        (Kind::Acceleration, Some(Inch)) => unece("IV", "in/s²", "inch per second squared"),
        (Kind::Acceleration, Some(Degree)) => unece("M45", "°/s²", "degree per second squared"),
        (Kind::Acceleration, Some(Radian)) => unece("2B", "rad/s²", "radian per second squared"),
        (Kind::Position, None) => generic("units", "axis units (the config's counts_per_unit)"),
        (Kind::Speed, None) => generic("units/s", "axis units per second"),
        (Kind::Acceleration, None) => generic("units/s²", "axis units per second squared"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unece_ids_as_part_8_computes_them() {
        // Part 8's example: "MMT" (millimetre) → 5066068.
        assert_eq!(unece_id("MMT"), 5_066_068);
        assert_eq!(unece_id("C16"), 4_403_510);
        assert!(eu(Kind::Plain, Some(Unit::Millimetre)).is_none());
        let g = eu(Kind::Position, None).unwrap();
        assert_eq!(g.unit_id, -1);
        assert_eq!(g.display_name.text.as_ref(), "units");
    }
}
