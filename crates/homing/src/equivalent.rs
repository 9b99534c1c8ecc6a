//! What a configured sequence is called elsewhere: the CiA 402 homing method
//! (object 0x6098) a drive would run for it, and the PLCopen Part 5
//! (homing) function blocks that make it up.
//!
//! Given only where the correspondence is exact: the limit-switch sequences
//! and the bidirectional switch searches that reverse at a limit. (The CIP
//! sequences without a limit have no exact CiA 402 twin: methods 19–22 read
//! the direction from a switch covering one end of the travel, 23–30 reverse
//! at a limit.) The home switch of methods 7–14 / 23–30 is the `switch`
//! interval; "left" is the negative side.
//!
//! | home_sequence | direction | reverse at limit | CiA 402 | PLCopen Part 5 |
//! |---|---|---|---|---|
//! | `limit_switch` | bidirectional_reverse | — | 17: negative limit, its falling edge | MC_StepLimitSwitch (negative, edge off) |
//! | `limit_switch` | bidirectional_forward | — | 18: positive limit, its falling edge | MC_StepLimitSwitch (positive, edge off) |
//! | `limit_switch_then_marker` | bidirectional_reverse | — | 1: negative limit, first index pulse to its right | MC_StepLimitSwitch + MC_StepReferencePulse |
//! | `limit_switch_then_marker` | bidirectional_forward | — | 2: positive limit, first index pulse to its left | MC_StepLimitSwitch + MC_StepReferencePulse |
//! | `switch` | bidirectional_forward | true | 23: home switch's left edge, falling; reverses at the positive limit | MC_StepAbsoluteSwitch (with its limit switch inputs) |
//! | `switch` | bidirectional_reverse | true | 27: home switch's right edge, falling; reverses at the negative limit | MC_StepAbsoluteSwitch (with its limit switch inputs) |
//! | `switch_then_marker` | bidirectional_forward | true | 7: first index pulse left of the home switch; reverses at the positive limit | MC_StepAbsoluteSwitch + MC_StepReferencePulse |
//! | `switch_then_marker` | bidirectional_reverse | true | 11: first index pulse right of the home switch; reverses at the negative limit | MC_StepAbsoluteSwitch + MC_StepReferencePulse |

use crate::config::{AxisConfig, HomeDirection, HomeMode, HomeSequence};

/// The names of a configured sequence in CiA 402 and PLCopen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Equivalent {
    /// CiA 402 homing method (0x6098).
    pub cia402_method: u8,
    /// PLCopen Part 5 function block(s), in the order they run.
    pub plcopen: &'static str,
}

/// The table of the module docs; `None` where there is no exact equivalent
/// (and for passive, unidirectional or invalid combinations).
pub fn equivalent(cfg: &AxisConfig) -> Option<Equivalent> {
    use HomeSequence as S;
    if cfg.home_mode != HomeMode::Active {
        return None;
    }
    let forward = match cfg.home_direction {
        HomeDirection::BidirectionalForward => true,
        HomeDirection::BidirectionalReverse => false,
        _ => return None,
    };
    let (method, plcopen) = match (cfg.home_sequence, cfg.home_reverse_at_limit) {
        (S::LimitSwitch, _) => (
            if forward { 18 } else { 17 },
            "MC_StepLimitSwitch (edge off)",
        ),
        (S::LimitSwitchThenMarker, _) => (
            if forward { 2 } else { 1 },
            "MC_StepLimitSwitch + MC_StepReferencePulse",
        ),
        (S::Switch, true) => (
            if forward { 23 } else { 27 },
            "MC_StepAbsoluteSwitch (with its limit switch inputs)",
        ),
        (S::SwitchThenMarker, true) => (
            if forward { 7 } else { 11 },
            "MC_StepAbsoluteSwitch (with its limit switch inputs) + MC_StepReferencePulse",
        ),
        _ => return None,
    };
    Some(Equivalent {
        cia402_method: method,
        plcopen,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use HomeDirection as D;
    use HomeSequence as S;

    fn method(seq: HomeSequence, dir: HomeDirection, reverse: bool) -> Option<u8> {
        equivalent(&AxisConfig {
            home_sequence: seq,
            home_direction: dir,
            home_reverse_at_limit: reverse,
            ..AxisConfig::default()
        })
        .map(|e| e.cia402_method)
    }

    #[test]
    fn the_table() {
        let f = D::BidirectionalForward;
        let r = D::BidirectionalReverse;
        assert_eq!(method(S::LimitSwitch, r, false), Some(17));
        assert_eq!(method(S::LimitSwitch, f, false), Some(18));
        assert_eq!(method(S::LimitSwitchThenMarker, r, false), Some(1));
        assert_eq!(method(S::LimitSwitchThenMarker, f, false), Some(2));
        assert_eq!(method(S::Switch, f, true), Some(23));
        assert_eq!(method(S::Switch, r, true), Some(27));
        assert_eq!(method(S::SwitchThenMarker, f, true), Some(7));
        assert_eq!(method(S::SwitchThenMarker, r, true), Some(11));
        // No exact twin without the reversal, nor unidirectional.
        assert_eq!(method(S::SwitchThenMarker, f, false), None);
        assert_eq!(method(S::Marker, f, true), None);
        assert_eq!(
            method(S::LimitSwitch, D::UnidirectionalForward, false),
            None
        );
    }
}
