//! Homing done by the drive (CiA 402 homing mode 6): which standard method
//! number does what a CIP sequence and direction do, and which sequences a
//! drive that lists its methods in 0x60E3 can serve that way.
//!
//! | CIP sequence, direction | CiA 402 method | the drive |
//! |---|---|---|
//! | switch, bidirectional forward | 19 | positive home switch: forward onto it, back until it clears; home = the edge approached in reverse |
//! | switch, bidirectional reverse | 21 | negative home switch, mirrored |
//! | switch then marker, bidirectional forward | 3 | as 19, then the first index pulse on the negative side of the edge |
//! | switch then marker, bidirectional reverse | 5 | as 21, then the first index pulse on the positive side |
//! | marker, forward (either form) | 34 | the first index pulse in the positive direction |
//! | marker, reverse (either form) | 33 | the first index pulse in the negative direction |
//!
//! Unidirectional switch sequences (the event is where the switch is
//! detected, approached forward) and torque (hard stop) sequences have no
//! standard method: they need `drive_homing_method` (the drive's vendor
//! method; hard-stop methods are negative on most drives). Immediate and
//! the passive and absolute modes are not homed by the drive.

use motion_homing::{HomeDirection as D, HomeSequence as S};

/// The standard CiA 402 method for `seq` homed in `dir`; `None` where no
/// standard method does the same (see the module docs).
pub fn standard_method(seq: S, dir: D) -> Option<i8> {
    let forward = matches!(dir, D::BidirectionalForward | D::UnidirectionalForward);
    let bidirectional = !dir.is_unidirectional();
    match seq {
        S::Switch if bidirectional => Some(if forward { 19 } else { 21 }),
        S::SwitchThenMarker if bidirectional => Some(if forward { 3 } else { 5 }),
        S::Marker => Some(if forward { 34 } else { 33 }),
        _ => None,
    }
}

/// What a CiA 402 homing method does, in a few words (scan, messages).
pub fn method_name(method: i8) -> &'static str {
    match method {
        1 => "negative limit switch and index pulse",
        2 => "positive limit switch and index pulse",
        3 | 4 => "positive home switch and index pulse",
        5 | 6 => "negative home switch and index pulse",
        7..=14 => "home switch, index pulse and limit switch reversal",
        17 => "negative limit switch",
        18 => "positive limit switch",
        19 | 20 => "positive home switch",
        21 | 22 => "negative home switch",
        23..=30 => "home switch and limit switch reversal",
        33 => "index pulse, negative direction",
        34 => "index pulse, positive direction",
        35 | 37 => "current position",
        m if m < 0 => "manufacturer-specific (often a hard stop)",
        _ => "reserved",
    }
}

/// The (sequence, direction) pairs a drive listing `methods` (0x60E3) can
/// home by itself with a standard method, as config spellings.
pub fn sequences_served(methods: &[i8]) -> Vec<String> {
    let mut out = Vec::new();
    for seq in [S::Switch, S::Marker, S::SwitchThenMarker] {
        for dir in [
            D::BidirectionalForward,
            D::BidirectionalReverse,
            D::UnidirectionalForward,
            D::UnidirectionalReverse,
        ] {
            if let Some(m) = standard_method(seq, dir) {
                if methods.contains(&m) {
                    out.push(format!("{} {} (method {m})", seq.name(), dir.name()));
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sequences_map_to_standard_methods() {
        assert_eq!(
            standard_method(S::Switch, D::BidirectionalForward),
            Some(19)
        );
        assert_eq!(
            standard_method(S::Switch, D::BidirectionalReverse),
            Some(21)
        );
        assert_eq!(
            standard_method(S::SwitchThenMarker, D::BidirectionalForward),
            Some(3)
        );
        assert_eq!(
            standard_method(S::SwitchThenMarker, D::BidirectionalReverse),
            Some(5)
        );
        assert_eq!(
            standard_method(S::Marker, D::UnidirectionalForward),
            Some(34)
        );
        assert_eq!(
            standard_method(S::Marker, D::BidirectionalReverse),
            Some(33)
        );
        for dir in [D::UnidirectionalForward, D::UnidirectionalReverse] {
            assert_eq!(standard_method(S::Switch, dir), None);
            assert_eq!(standard_method(S::SwitchThenMarker, dir), None);
        }
        for seq in [S::Torque, S::TorqueThenMarker, S::Immediate] {
            assert_eq!(standard_method(seq, D::BidirectionalForward), None);
        }
        assert_eq!(
            sequences_served(&[19, 34]),
            [
                "switch bidirectional_forward (method 19)",
                "marker bidirectional_forward (method 34)",
                "marker unidirectional_forward (method 34)"
            ]
        );
        assert_eq!(method_name(-1), "manufacturer-specific (often a hard stop)");
    }
}
