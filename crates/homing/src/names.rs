//! The spellings of the enums, each written once: next to the enum, in one
//! [`spellings!`](crate::spellings) table that gives it `NAMES`, `name()`,
//! `from_number`, `FromStr` and `Display`. Config files, JSON and text
//! reports, the status frame's phase and the trace CSV all read them from
//! there (the spellings are fixed: users' files and scripts use them).
//!
//! `name()` is a `const fn` match with no allocation: the real-time cycle
//! uses it to put the phase into the status frame.

use core::fmt;

/// A string that is none of an enum's spellings (its `FromStr` error).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnknownName;

impl fmt::Display for UnknownName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("not one of the known names")
    }
}

impl std::error::Error for UnknownName {}

/// An enum with a [`spellings!`](crate::spellings) table, as a generic
/// caller sees it: an operation's parameter of one of these types (a
/// choice, `params::Kind::Choice`) is carried as the index of its
/// spelling and offered by its spellings.
pub trait Spelled: Copy + 'static {
    /// The spellings, in the table's order.
    const SPELLINGS: &'static [&'static str];
    /// The position of `self`'s spelling in [`Self::SPELLINGS`].
    fn index(self) -> usize;
    /// The variant of the spelling at `i`.
    fn from_index(i: usize) -> Option<Self>;
}

/// Gives a fieldless enum its spellings from one table:
///
/// * `NAMES`: every variant with its spelling, in the order a configuration
///   error lists the choices (the table's order);
/// * `name()`: the spelling (a `const fn` match: the compiler checks that
///   every variant has one);
/// * `from_number(n)`: the variant whose discriminant is `n` (the CIP
///   attribute value where CIP defines one, as the frames carry it);
/// * `FromStr` (error [`UnknownName`](crate::names::UnknownName)) and
///   `Display` (the spelling);
/// * [`Spelled`](crate::names::Spelled): the same for generic callers.
///
/// ```
/// #[derive(Clone, Copy, Debug, PartialEq, Eq)]
/// pub enum Wiring { NormallyOpen, NormallyClosed }
/// motion_homing::spellings!(Wiring { NormallyOpen => "no", NormallyClosed => "nc" });
///
/// assert_eq!(Wiring::NormallyClosed.name(), "nc");
/// assert_eq!("no".parse(), Ok(Wiring::NormallyOpen));
/// assert_eq!(Wiring::from_number(1), Some(Wiring::NormallyClosed));
/// ```
#[macro_export]
macro_rules! spellings {
    ($ty:ident { $($variant:ident => $name:literal),+ $(,)? }) => {
        impl $ty {
            /// Every variant with its spelling, in the order a configuration
            /// error lists the choices.
            pub const NAMES: &'static [(&'static str, $ty)] = &[$(($name, $ty::$variant)),+];

            /// The spelling in config files, JSON and text.
            pub const fn name(self) -> &'static str {
                match self {
                    $($ty::$variant => $name),+
                }
            }

            /// The variant numbered `n` (its discriminant, as frames carry it).
            pub fn from_number(n: u8) -> Option<$ty> {
                Self::NAMES
                    .iter()
                    .map(|&(_, v)| v)
                    .find(|&v| v as u8 == n)
            }
        }

        impl $crate::names::Spelled for $ty {
            const SPELLINGS: &'static [&'static str] = &[$($name),+];

            fn index(self) -> usize {
                Self::NAMES.iter().position(|&(_, v)| v as u8 == self as u8).unwrap_or(0)
            }

            fn from_index(i: usize) -> Option<Self> {
                Self::NAMES.get(i).map(|&(_, v)| v)
            }
        }

        impl ::core::str::FromStr for $ty {
            type Err = $crate::names::UnknownName;

            fn from_str(s: &str) -> Result<Self, Self::Err> {
                Self::NAMES
                    .iter()
                    .find(|(n, _)| *n == s)
                    .map(|&(_, v)| v)
                    .ok_or($crate::names::UnknownName)
            }
        }

        impl ::core::fmt::Display for $ty {
            fn fmt(&self, f: &mut ::core::fmt::Formatter<'_>) -> ::core::fmt::Result {
                f.write_str(self.name())
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use crate::*;

    /// Every table holds every variant once, and parsing a name gives the
    /// variant back.
    fn round_trips<T>(names: &[(&'static str, T)], name: fn(T) -> &'static str)
    where
        T: Copy + PartialEq + core::fmt::Debug + core::str::FromStr,
        <T as core::str::FromStr>::Err: core::fmt::Debug,
    {
        for (i, &(n, v)) in names.iter().enumerate() {
            assert_eq!(name(v), n);
            assert_eq!(n.parse::<T>().unwrap(), v);
            assert!(names[..i].iter().all(|&(m, w)| m != n && w != v), "{n}");
        }
        assert!("no such name".parse::<T>().is_err());
    }

    #[test]
    fn every_table_round_trips() {
        round_trips(AxisConfiguration::NAMES, AxisConfiguration::name);
        round_trips(ControlMode::NAMES, ControlMode::name);
        round_trips(TravelMode::NAMES, TravelMode::name);
        round_trips(HomeMode::NAMES, HomeMode::name);
        round_trips(HomeDirection::NAMES, HomeDirection::name);
        round_trips(HomeSequence::NAMES, HomeSequence::name);
        round_trips(Phase::NAMES, Phase::name);
        round_trips(OpKind::NAMES, OpKind::name);
        round_trips(StopCause::NAMES, StopCause::name);
    }

    /// The numbers the status frame and the trace carry (CIP order).
    #[test]
    fn numbers_are_the_cip_values() {
        assert_eq!(HomeMode::from_number(0), Some(HomeMode::Passive));
        assert_eq!(HomeMode::from_number(1), Some(HomeMode::Active));
        assert_eq!(HomeMode::from_number(2), Some(HomeMode::Absolute));
        assert_eq!(HomeMode::from_number(3), None);
        assert_eq!(
            HomeDirection::from_number(2),
            Some(HomeDirection::UnidirectionalReverse)
        );
        assert_eq!(
            HomeSequence::from_number(5),
            Some(HomeSequence::TorqueThenMarker)
        );
        assert_eq!(Phase::from_number(10), Some(Phase::Creep));
        assert_eq!(Phase::from_number(11), Some(Phase::Reverse));
        assert_eq!(Phase::from_number(12), Some(Phase::DriveHoming));
        assert_eq!(Phase::from_number(13), None);
        assert_eq!(
            HomeSequence::from_number(7),
            Some(HomeSequence::LimitSwitchThenMarker)
        );
        assert_eq!(HomeSequence::from_number(8), None);
    }
}
