//! An operation's parameters, declared once with the operation's spec type
//! ([`op_spec!`](crate::op_spec)) and derived everywhere else.
//!
//! A spec (`MoveSpec`, `JogSpec`, … in [`operation`](crate::operation)) is
//! the one place a parameter is written: its Rust field, and a [`Param`]
//! row that says how every layer outside the engine carries and offers it —
//! its name (the Rust field, the JSON / Python keyword, motionctl's flag),
//! its OPC UA title, its [`Kind`], its [`Unit`], where a value left out
//! comes from ([`Fallback`]), how an operator gives it on a command line
//! ([`Form`]) and its doc (the field's doc comment). From that row:
//!
//! * the wire: [`Carried`], an operation's parameters as plain slots — a
//!   number per slot (NaN: left out), a switch per bit, one axis name —
//!   which the control request carries as they are
//!   (`motion_control::request`), so the daemon decodes every operation
//!   with one function ([`Spec::take`]) and a client encodes it with one
//!   ([`Spec::carry`]);
//! * the engine: [`Spec::resolve`] fills what was left out from the axis's
//!   configuration, in the engine (which has it), once per operation;
//! * the layout description the Python package reads (`layout.json`), the
//!   OPC UA methods' arguments (`motion-opcua`'s `methods.rs`) and
//!   motionctl's flags (`motionctl`'s `spec_args.rs`), each a loop over
//!   [`Spec::PARAMS`].
//!
//! The slots are given out in declaration order (a pair takes two, a
//! switch takes a bit instead): a new parameter is appended to its spec,
//! so the ones before keep their slots. Nothing here allocates: an
//! operation with its parameters crosses the real-time thread's queue by
//! value.

use crate::config::AxisConfig;
use crate::names::Spelled;

/// Number slots an operation may use (a pair takes two).
pub const SLOTS: usize = 8;
/// Bytes of an axis name (as the control service carries names).
pub const AXIS_NAME_LEN: usize = 32;

/// What a parameter holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A number that must be given (`f64`).
    Number,
    /// A number that may be left out (`Option<f64>`); left out, its
    /// [`Fallback`] applies (or none: the operation does without).
    Optional,
    /// Yes or no (`bool`); not given: no.
    Switch,
    /// One of these spellings (an enum with a `spellings!` table),
    /// carried as the index of its spelling.
    Choice(&'static [&'static str]),
    /// An axis or gantry of the machine ([`AxisRef`]), given by name; at
    /// most one per operation (it rides in the request's name field).
    Axis,
    /// Two numbers given together or not at all (`Option<(f64, f64)>`,
    /// e.g. a window LO HI).
    Pair,
}

/// The unit a number is given in (axis units: the config's `units`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// No unit (a ratio, a choice, a switch).
    None,
    /// Position or distance: units.
    Position,
    /// units/s.
    Speed,
    /// units/s².
    Acceleration,
    /// units/s³.
    Jerk,
    /// Seconds.
    Seconds,
}

impl Unit {
    /// As the docs, flags and OPC UA descriptions write it.
    pub const fn symbol(self) -> &'static str {
        match self {
            Unit::None => "",
            Unit::Position => "units",
            Unit::Speed => "units/s",
            Unit::Acceleration => "units/s²",
            Unit::Jerk => "units/s³",
            Unit::Seconds => "s",
        }
    }
}

/// Default lease of a hold-to-run jog, s: renewed every 100 ms by
/// motionctl, it rides out four lost renewals.
pub const JOG_LEASE_S: f64 = 0.5;

/// Where the value of a parameter left out comes from: resolved once, in
/// the engine ([`Spec::resolve`]), from the axis's own configuration. (A
/// gantry's sides must have equal homing dynamics — the configuration
/// refuses them otherwise — so every side resolves to the same numbers.)
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fallback {
    /// None: left out means left out (or, for a number that must be given,
    /// is refused).
    None,
    /// The axis's `home_speed`.
    HomeSpeed,
    /// The axis's `home_acceleration`.
    HomeAcceleration,
    /// The axis's `home_deceleration`.
    HomeDeceleration,
    /// [`JOG_LEASE_S`].
    JogLease,
    /// The axis's `jerk` (0: trapezoidal).
    Jerk,
}

impl Fallback {
    /// The configuration key (or the value) it names, for docs and help.
    pub const fn describe(self) -> Option<&'static str> {
        match self {
            Fallback::None => None,
            Fallback::HomeSpeed => Some("the axis's home_speed"),
            Fallback::HomeAcceleration => Some("the axis's home_acceleration"),
            Fallback::HomeDeceleration => Some("the axis's home_deceleration"),
            Fallback::JogLease => Some("0.5 s"),
            Fallback::Jerk => Some("the axis's jerk"),
        }
    }

    /// The value for an axis of configuration `cfg`.
    pub fn value(self, cfg: &AxisConfig) -> Option<f64> {
        match self {
            Fallback::None => None,
            Fallback::HomeSpeed => Some(cfg.home_speed),
            Fallback::HomeAcceleration => Some(cfg.home_acceleration),
            Fallback::HomeDeceleration => Some(cfg.home_deceleration),
            Fallback::JogLease => Some(JOG_LEASE_S),
            Fallback::Jerk => Some(cfg.jerk),
        }
    }
}

/// How an operator gives a parameter on a command line (motionctl derives
/// its flags from it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Form {
    /// `--flag VALUE` (a switch: `--flag`); `metavar` names the value.
    Flag {
        flag: &'static str,
        metavar: &'static str,
    },
    /// A number given as one of two flags that also set a switch of the
    /// same spec: `--off P` (switch off) or `--on D` (switch on), exactly
    /// one of them (a move's `--to P | --by D`).
    Either {
        off: (&'static str, &'static str),
        on: (&'static str, &'static str),
        switch: &'static str,
    },
    /// Set through the [`Form::Either`] of another parameter.
    Implied,
    /// The lease of a hold-to-run operation: set by whoever holds it (the
    /// client library that renews it; an OPC UA caller, who renews by
    /// calling again), never a flag.
    Lease,
}

/// Where a parameter is carried in [`Carried`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Place {
    /// `values[slot]` (a pair: and `slot + 1`); an axis: the name field.
    Slot(usize),
    /// Bit `n` of `switches`.
    Bit(u32),
    /// The axis name field.
    Name,
}

/// One parameter of an operation, as every layer outside the engine needs
/// it. Written with the spec's field ([`op_spec!`](crate::op_spec)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Param {
    /// The field's name: JSON and Python keyword too.
    pub name: &'static str,
    /// OPC UA's argument name.
    pub title: &'static str,
    pub kind: Kind,
    pub unit: Unit,
    pub fallback: Fallback,
    pub form: Form,
    /// The field's doc comment.
    pub doc: &'static str,
    pub place: Place,
}

impl Param {
    /// A row with its title and unit; the macro names it.
    pub const fn new(title: &'static str, unit: Unit) -> Param {
        Param {
            name: "",
            title,
            kind: Kind::Number,
            unit,
            fallback: Fallback::None,
            form: Form::Implied,
            doc: "",
            place: Place::Slot(0),
        }
    }

    /// Left out: `f`.
    pub const fn or(mut self, f: Fallback) -> Param {
        self.fallback = f;
        self
    }

    /// `--flag METAVAR` on a command line.
    pub const fn flag(mut self, flag: &'static str, metavar: &'static str) -> Param {
        self.form = Form::Flag { flag, metavar };
        self
    }

    /// Any other [`Form`].
    pub const fn form(mut self, form: Form) -> Param {
        self.form = form;
        self
    }

    /// Completed by [`op_spec!`](crate::op_spec): the field's name, the
    /// kind of its type, its doc comment.
    #[doc(hidden)]
    pub const fn named(mut self, name: &'static str, kind: Kind, doc: &'static str) -> Param {
        self.name = name;
        self.kind = kind;
        self.doc = doc;
        self
    }
}

/// Gives every parameter its place, in declaration order (see the module
/// doc); a spec that needs more slots or bits than a request has, or two
/// axis parameters, does not compile.
#[doc(hidden)]
pub const fn placed<const N: usize>(mut ps: [Param; N]) -> [Param; N] {
    let (mut slot, mut bit, mut names, mut i) = (0, 0, 0, 0);
    while i < N {
        ps[i].place = match ps[i].kind {
            Kind::Switch => {
                bit += 1;
                Place::Bit(bit - 1)
            }
            Kind::Axis => {
                names += 1;
                Place::Name
            }
            Kind::Pair => {
                slot += 2;
                Place::Slot(slot - 2)
            }
            _ => {
                slot += 1;
                Place::Slot(slot - 1)
            }
        };
        i += 1;
    }
    assert!(slot <= SLOTS, "more number slots than a request has");
    assert!(bit <= 32, "more switches than a request has");
    assert!(names <= 1, "at most one axis parameter");
    ps
}

/// An operation's parameters as they cross every boundary outside the
/// engine (the control request carries exactly this).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Carried {
    /// Numbers by slot; NaN: left out.
    pub values: [f64; SLOTS],
    /// Switches by bit.
    pub switches: u32,
    /// The axis parameter's name, UTF-8, NUL-padded (empty: none).
    pub name: [u8; AXIS_NAME_LEN],
}

impl Carried {
    /// Nothing given.
    pub const EMPTY: Carried = Carried {
        values: [f64::NAN; SLOTS],
        switches: 0,
        name: [0; AXIS_NAME_LEN],
    };

    fn value(&self, at: Place) -> f64 {
        match at {
            Place::Slot(s) if s < SLOTS => self.values[s],
            _ => f64::NAN,
        }
    }

    fn set(&mut self, at: Place, x: f64) {
        if let Place::Slot(s) = at {
            if s < SLOTS {
                self.values[s] = x;
            }
        }
    }
}

impl Default for Carried {
    fn default() -> Self {
        Carried::EMPTY
    }
}

/// Why carried parameters are not an operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Refused {
    /// The parameter.
    pub param: &'static str,
    pub why: Why,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Why {
    /// A number that must be given was left out (NaN).
    Missing,
    /// Not one of the spellings.
    UnknownChoice,
    /// Not a name (empty, not UTF-8, too long).
    BadName,
    /// One number of a pair given without the other.
    HalfPair,
    /// The named axis is not one of the machine's.
    UnknownAxis,
    /// Not an operation clients may ask for, or not one at all.
    NotAnOperation,
}

impl core::fmt::Display for Refused {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let why = match self.why {
            Why::Missing => "must be given",
            Why::UnknownChoice => "is none of its choices",
            Why::BadName => "is not an axis name",
            Why::HalfPair => "needs both of its numbers",
            Why::UnknownAxis => "names no axis of the machine",
            Why::NotAnOperation => "is not an operation a client may ask for",
        };
        write!(f, "{} {why}", self.param)
    }
}

/// An axis of the machine as an operation's parameter (a gear's master):
/// by name as a client gives it; by index once the control thread has
/// resolved the name ([`Spec::resolve_axes`]) — the engine and the cycle
/// only ever see an index.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisRef {
    Name([u8; AXIS_NAME_LEN]),
    Index(u16),
}

impl AxisRef {
    /// `name` as given (`None`: empty, longer than the field, or with NUL).
    pub fn named(name: &str) -> Option<AxisRef> {
        let b = name.as_bytes();
        if b.is_empty() || b.len() > AXIS_NAME_LEN || b.contains(&0) {
            return None;
        }
        let mut n = [0; AXIS_NAME_LEN];
        n[..b.len()].copy_from_slice(b);
        Some(AxisRef::Name(n))
    }

    /// The name, when given by name and valid UTF-8.
    pub fn name(&self) -> Option<&str> {
        let AxisRef::Name(n) = self else {
            return None;
        };
        let end = n.iter().position(|&c| c == 0).unwrap_or(n.len());
        core::str::from_utf8(&n[..end]).ok()
    }
}

/// A field type an operation's parameter may have: how it is carried, and
/// filled from its fallback.
pub trait Carry: Sized {
    const KIND: Kind;
    fn put(&self, c: &mut Carried, at: Place);
    fn take(c: &Carried, at: Place) -> Result<Self, Why>;
    /// Left out: the fallback's value (only an optional number has one).
    fn resolve(&mut self, _f: Fallback, _cfg: &AxisConfig) {}
    /// An axis by name: its index, by `lookup` (false: no such axis).
    fn resolve_axis(&mut self, _lookup: &mut dyn FnMut(&str) -> Option<u16>) -> bool {
        true
    }
}

impl Carry for f64 {
    const KIND: Kind = Kind::Number;
    fn put(&self, c: &mut Carried, at: Place) {
        c.set(at, *self);
    }
    fn take(c: &Carried, at: Place) -> Result<Self, Why> {
        let x = c.value(at);
        if x.is_nan() {
            Err(Why::Missing)
        } else {
            Ok(x)
        }
    }
}

impl Carry for Option<f64> {
    const KIND: Kind = Kind::Optional;
    fn put(&self, c: &mut Carried, at: Place) {
        c.set(at, self.unwrap_or(f64::NAN));
    }
    fn take(c: &Carried, at: Place) -> Result<Self, Why> {
        let x = c.value(at);
        Ok((!x.is_nan()).then_some(x))
    }
    fn resolve(&mut self, f: Fallback, cfg: &AxisConfig) {
        if self.is_none() {
            *self = f.value(cfg);
        }
    }
}

impl Carry for bool {
    const KIND: Kind = Kind::Switch;
    fn put(&self, c: &mut Carried, at: Place) {
        if let (Place::Bit(b), true) = (at, *self) {
            c.switches |= 1 << b;
        }
    }
    fn take(c: &Carried, at: Place) -> Result<Self, Why> {
        Ok(matches!(at, Place::Bit(b) if c.switches & (1 << b) != 0))
    }
}

impl Carry for Option<(f64, f64)> {
    const KIND: Kind = Kind::Pair;
    fn put(&self, c: &mut Carried, at: Place) {
        let (a, b) = self.unwrap_or((f64::NAN, f64::NAN));
        c.set(at, a);
        if let Place::Slot(s) = at {
            c.set(Place::Slot(s + 1), b);
        }
    }
    fn take(c: &Carried, at: Place) -> Result<Self, Why> {
        let Place::Slot(s) = at else {
            return Ok(None);
        };
        match (c.value(at), c.value(Place::Slot(s + 1))) {
            (a, b) if a.is_nan() && b.is_nan() => Ok(None),
            (a, b) if a.is_nan() || b.is_nan() => Err(Why::HalfPair),
            (a, b) => Ok(Some((a, b))),
        }
    }
}

impl Carry for AxisRef {
    const KIND: Kind = Kind::Axis;
    /// Carried by name (an index has none: it never leaves the daemon).
    fn put(&self, c: &mut Carried, _at: Place) {
        if let AxisRef::Name(n) = self {
            c.name = *n;
        }
    }
    fn take(c: &Carried, _at: Place) -> Result<Self, Why> {
        let end = c.name.iter().position(|&b| b == 0).unwrap_or(AXIS_NAME_LEN);
        let ok = end > 0
            && core::str::from_utf8(&c.name[..end]).is_ok()
            && c.name[end..].iter().all(|&b| b == 0);
        if ok {
            Ok(AxisRef::Name(c.name))
        } else {
            Err(Why::BadName)
        }
    }
    fn resolve_axis(&mut self, lookup: &mut dyn FnMut(&str) -> Option<u16>) -> bool {
        match self.name().map(&mut *lookup) {
            Some(Some(i)) => {
                *self = AxisRef::Index(i);
                true
            }
            Some(None) => false,
            // Already an index (or not UTF-8, which `take` refused).
            None => matches!(self, AxisRef::Index(_)),
        }
    }
}

impl<T: Spelled> Carry for T {
    const KIND: Kind = Kind::Choice(T::SPELLINGS);
    fn put(&self, c: &mut Carried, at: Place) {
        c.set(at, self.index() as f64);
    }
    fn take(c: &Carried, at: Place) -> Result<Self, Why> {
        let x = c.value(at);
        let i = x as usize;
        if x >= 0.0 && x == i as f64 {
            T::from_index(i).ok_or(Why::UnknownChoice)
        } else {
            Err(Why::UnknownChoice)
        }
    }
}

/// An operation's spec type: its parameters and how they are carried. Only
/// [`op_spec!`](crate::op_spec) implements it.
pub trait Spec: Sized + Copy {
    /// One row per field, in declaration order, placed.
    const PARAMS: &'static [Param];
    /// The carried form (what a client sends).
    fn carry(&self, c: &mut Carried);
    /// From the carried form (what the daemon decodes), or which parameter
    /// is wrong.
    fn take(c: &Carried) -> Result<Self, Refused>;
    /// Every parameter left out that has a [`Fallback`]: its value for an
    /// axis of configuration `cfg`.
    fn resolve(&mut self, cfg: &AxisConfig);
    /// Every axis named by a parameter: its index (`Err`: the parameter
    /// naming no axis of the machine).
    fn resolve_axes(&mut self, lookup: &mut dyn FnMut(&str) -> Option<u16>) -> Result<(), Refused>;
}

/// Declares an operation's spec: the struct (`Clone, Copy, Debug,
/// PartialEq`), one [`Param`] row per field, and its [`Spec`] impl. Each
/// field is written once: its doc comment, its name and type, and its row
/// (title, unit, fallback, command-line form).
///
/// ```
/// use motion_homing::params::{Param, Spec, Unit, Fallback, Carried};
/// motion_homing::op_spec! {
///     /// Halts at a deceleration.
///     pub struct HaltSpec {
///         /// units/s²; left out: the axis's home_deceleration.
///         decel: Option<f64> = Param::new("Decel", Unit::Acceleration)
///             .or(Fallback::HomeDeceleration).flag("decel", "D"),
///     }
/// }
/// let mut c = Carried::EMPTY;
/// HaltSpec { decel: Some(5.0) }.carry(&mut c);
/// assert_eq!(HaltSpec::take(&c), Ok(HaltSpec { decel: Some(5.0) }));
/// assert_eq!(HaltSpec::PARAMS[0].name, "decel");
/// ```
#[macro_export]
macro_rules! op_spec {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            $(
                $(#[doc = $doc:literal])*
                $field:ident : $ty:ty = $param:expr
            ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct $name {
            $( $(#[doc = $doc])* pub $field: $ty, )*
        }

        impl $crate::params::Spec for $name {
            const PARAMS: &'static [$crate::params::Param] = &$crate::params::placed([
                $( $param.named(
                    stringify!($field),
                    <$ty as $crate::params::Carry>::KIND,
                    concat!($($doc, "\n"),*),
                ) ),*
            ]);

            fn carry(&self, c: &mut $crate::params::Carried) {
                let mut _i = 0;
                $(
                    $crate::params::Carry::put(&self.$field, c, Self::PARAMS[_i].place);
                    _i += 1;
                )*
            }

            fn take(c: &$crate::params::Carried) -> Result<Self, $crate::params::Refused> {
                let mut _i = 0;
                Ok(Self {
                    $( $field: {
                        let p = &Self::PARAMS[_i];
                        _i += 1;
                        $crate::params::Carry::take(c, p.place)
                            .map_err(|why| $crate::params::Refused { param: p.name, why })?
                    }, )*
                })
            }

            fn resolve(&mut self, _cfg: &$crate::config::AxisConfig) {
                let mut _i = 0;
                $(
                    $crate::params::Carry::resolve(&mut self.$field, Self::PARAMS[_i].fallback, _cfg);
                    _i += 1;
                )*
            }

            fn resolve_axes(
                &mut self,
                _lookup: &mut dyn FnMut(&str) -> Option<u16>,
            ) -> Result<(), $crate::params::Refused> {
                let mut _i = 0;
                $(
                    if !$crate::params::Carry::resolve_axis(&mut self.$field, _lookup) {
                        return Err($crate::params::Refused {
                            param: Self::PARAMS[_i].name,
                            why: $crate::params::Why::UnknownAxis,
                        });
                    }
                    _i += 1;
                )*
                Ok(())
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An edge as a choice (as registration will have it).
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    pub enum Edge {
        Rising,
        Falling,
    }
    crate::spellings!(Edge {
        Rising => "rising",
        Falling => "falling",
    });

    #[test]
    fn a_choice_keeps_its_number() {
        assert_eq!(Edge::from_number(1), Some(Edge::Falling));
    }

    crate::op_spec! {
        /// Every kind of parameter at once, as the operations still to come
        /// have them (a gear's master and ratio, a registration's edge and
        /// window, a clutch): each a line here, nothing elsewhere.
        pub struct EveryKind {
            /// The master axis.
            master: AxisRef = Param::new("Master", Unit::None).flag("master", "AXIS"),
            /// Signed.
            ratio: f64 = Param::new("Ratio", Unit::None).flag("ratio", "R"),
            /// Follow the actual position.
            actual: bool = Param::new("Actual", Unit::None).flag("actual", ""),
            /// Ramp-in acceleration.
            clutch: Option<f64> = Param::new("Clutch", Unit::Acceleration).flag("clutch", "A"),
            /// Which edge.
            edge: Edge = Param::new("Edge", Unit::None).flag("edge", "rising|falling"),
            /// LO HI.
            window: Option<(f64, f64)> = Param::new("Window", Unit::Position).flag("window", "LO HI"),
            /// units/s, defaulted.
            speed: Option<f64> = Param::new("Speed", Unit::Speed)
                .or(Fallback::HomeSpeed).flag("speed", "V"),
            /// Another switch.
            late: bool = Param::new("Late", Unit::None).flag("late", ""),
        }
    }

    fn every() -> EveryKind {
        EveryKind {
            master: AxisRef::named("Y").unwrap(),
            ratio: -0.5,
            actual: true,
            clutch: None,
            edge: Edge::Falling,
            window: Some((-1.0, 2.0)),
            speed: Some(3.0),
            late: false,
        }
    }

    #[test]
    fn every_kind_is_placed_in_declaration_order() {
        let places: Vec<(&str, Place, Kind)> = EveryKind::PARAMS
            .iter()
            .map(|p| (p.name, p.place, p.kind))
            .collect();
        assert_eq!(
            places,
            [
                ("master", Place::Name, Kind::Axis),
                ("ratio", Place::Slot(0), Kind::Number),
                ("actual", Place::Bit(0), Kind::Switch),
                ("clutch", Place::Slot(1), Kind::Optional),
                ("edge", Place::Slot(2), Kind::Choice(&["rising", "falling"])),
                ("window", Place::Slot(3), Kind::Pair),
                ("speed", Place::Slot(5), Kind::Optional),
                ("late", Place::Bit(1), Kind::Switch),
            ]
        );
        assert_eq!(EveryKind::PARAMS[1].doc.trim(), "Signed.");
        assert_eq!(EveryKind::PARAMS[6].fallback, Fallback::HomeSpeed);
    }

    #[test]
    fn every_kind_survives_being_carried() {
        let mut c = Carried::EMPTY;
        every().carry(&mut c);
        assert_eq!(c.switches, 0b01);
        assert_eq!(&c.name[..2], b"Y\0");
        assert_eq!(EveryKind::take(&c), Ok(every()));
        let none = EveryKind {
            window: None,
            clutch: Some(2.0),
            edge: Edge::Rising,
            ..every()
        };
        let mut c = Carried::EMPTY;
        none.carry(&mut c);
        assert_eq!(EveryKind::take(&c), Ok(none));
    }

    #[test]
    fn carried_garbage_is_refused_by_name() {
        let mut good = Carried::EMPTY;
        every().carry(&mut good);
        let refused = |f: &dyn Fn(&mut Carried)| {
            let mut c = good;
            f(&mut c);
            EveryKind::take(&c).map(|_| ())
        };
        let err = |param, why| Err(Refused { param, why });
        assert_eq!(
            refused(&|c| c.values[0] = f64::NAN),
            err("ratio", Why::Missing)
        );
        assert_eq!(
            refused(&|c| c.values[2] = 2.0),
            err("edge", Why::UnknownChoice)
        );
        assert_eq!(
            refused(&|c| c.values[2] = 0.5),
            err("edge", Why::UnknownChoice)
        );
        assert_eq!(
            refused(&|c| c.values[2] = -1.0),
            err("edge", Why::UnknownChoice)
        );
        assert_eq!(
            refused(&|c| c.values[4] = f64::NAN),
            err("window", Why::HalfPair)
        );
        assert_eq!(
            refused(&|c| c.name = [0; AXIS_NAME_LEN]),
            err("master", Why::BadName)
        );
        assert_eq!(refused(&|c| c.name[0] = 0xff), err("master", Why::BadName));
        assert_eq!(refused(&|c| c.name[5] = b'x'), err("master", Why::BadName));
        // Unknown switches and slots no parameter uses are not read.
        assert_eq!(refused(&|c| c.switches |= 1 << 31), Ok(()));
        assert_eq!(refused(&|c| c.values[7] = 1e300), Ok(()));
    }

    #[test]
    fn defaults_and_axes_are_resolved_in_one_place() {
        let cfg = AxisConfig {
            home_speed: 7.0,
            ..AxisConfig::default()
        };
        let mut s = EveryKind {
            speed: None,
            ..every()
        };
        s.resolve(&cfg);
        assert_eq!((s.speed, s.clutch), (Some(7.0), None));
        let mut unknown = s;
        assert_eq!(
            unknown.resolve_axes(&mut |_| None),
            Err(Refused {
                param: "master",
                why: Why::UnknownAxis
            })
        );
        s.resolve_axes(&mut |n| (n == "Y").then_some(3)).unwrap();
        assert_eq!(s.master, AxisRef::Index(3));
    }
}
