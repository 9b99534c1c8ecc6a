//! What one row of the status table says about a field, and the rules of
//! the wire entry that carries the rows.
//!
//! A row names a field once: its name (the wire entry's accessor, the
//! Python property), its [`Type`], where it lives on the wire (a bit of the
//! entry's one `flags` word, or a slot of its `ints` or `values` area, by
//! type), its [`Unit`], its JSON key in `status --json`, its mark in
//! `motionctl status`'s flags column (if shown), its OPC UA browse name (if
//! published) and its meaning. [`crate::axis`] holds the rows; the
//! [`status_table!`](crate::status_table) macro below turns them into the
//! filler, the entry's accessors, the typed JSON row and the row list every
//! other layer (the layout description, the Python package, the OPC UA
//! variables, the docs page, `motionctl`'s table) reads.
//!
//! **The layout rule.** Every place is written in the row, never counted
//! from the order of rows, and the areas have room (64 flags, 24 integers,
//! 32 values): adding a row in the room moves nothing, so a client that
//! knows an older table still reads every field it knows (a new field is
//! simply not shown by it). Moving or removing a row, or changing its type,
//! changes what an older client reads: that bumps `CONTROL_LAYOUT` (the
//! iceoryx2 type names carry it, so an older client cannot open the
//! services at all).

/// Bits of an entry's `flags` word.
pub const FLAG_BITS: usize = 64;
/// Slots of an entry's `ints` area (`u32` each).
pub const INT_SLOTS: usize = 24;
/// Slots of an entry's `values` area (`f64` each).
pub const VALUE_SLOTS: usize = 32;

/// What a field is, which decides where it lives and how each layer shows it.
#[derive(Clone, Copy, Debug)]
pub enum Type {
    /// A bit of `flags`. JSON boolean; OPC UA Boolean.
    Flag,
    /// A number in a `values` slot, always present. JSON number; OPC UA
    /// Double.
    Value,
    /// A number in a `values` slot that may be absent (no fresh feedback,
    /// not latched yet): NaN on the wire, `null` in JSON, an empty value
    /// with a Bad status in OPC UA.
    Maybe,
    /// An integer in an `ints` slot (codes). OPC UA UInt16.
    U16,
    /// An integer in an `ints` slot (ids, counts). OPC UA UInt32.
    U32,
    /// An enumeration's number in an `ints` slot: JSON its spelling; OPC UA
    /// a Byte with `EnumStrings`. The function names a number (the enum's
    /// `spellings!` table); `None` for a number without a variant.
    Enum(fn(u32) -> Option<&'static str>),
}

impl Type {
    /// The area of the wire entry the field lives in.
    pub fn area(&self) -> Area {
        match self {
            Type::Flag => Area::Flags,
            Type::Value | Type::Maybe => Area::Values,
            Type::U16 | Type::U32 | Type::Enum(_) => Area::Ints,
        }
    }

    /// As the layout description and the docs spell it.
    pub fn name(&self) -> &'static str {
        match self {
            Type::Flag => "flag",
            Type::Value => "value",
            Type::Maybe => "maybe",
            Type::U16 => "u16",
            Type::U32 => "u32",
            Type::Enum(_) => "enum",
        }
    }

    /// An enumeration's spellings by number, from 0 to its last (a number
    /// without a variant: `""`, so an enum whose numbers have a gap keeps
    /// every later spelling at its number); empty for other types.
    pub fn enum_names(&self) -> Vec<&'static str> {
        match self {
            Type::Enum(name) => {
                let last = (0..=u32::from(u8::MAX)).rfind(|&n| name(n).is_some());
                last.map_or(Vec::new(), |l| {
                    (0..=l).map(|n| name(n).unwrap_or("")).collect()
                })
            }
            _ => Vec::new(),
        }
    }
}

/// The three areas of a wire entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Area {
    Flags,
    Ints,
    Values,
}

impl Area {
    /// The entry's field that holds the area.
    pub fn field(self) -> &'static str {
        match self {
            Area::Flags => "flags",
            Area::Ints => "ints",
            Area::Values => "values",
        }
    }

    /// How many places it has.
    pub fn room(self) -> usize {
        match self {
            Area::Flags => FLAG_BITS,
            Area::Ints => INT_SLOTS,
            Area::Values => VALUE_SLOTS,
        }
    }
}

/// What a number measures. An axis's positions are in its units
/// (`counts_per_unit`); OPC UA names the engineering unit from this and the
/// `[opcua] units` of the axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// No unit: flags, codes, ids, enumerations.
    None,
    /// Axis units.
    Units,
    /// Axis units per second.
    UnitsPerSecond,
    /// Percent of rated torque.
    Percent,
    /// Seconds.
    Seconds,
}

impl Unit {
    /// As the docs and the layout description write it ("" for none).
    pub fn symbol(self) -> &'static str {
        match self {
            Unit::None => "",
            Unit::Units => "units",
            Unit::UnitsPerSecond => "units/s",
            Unit::Percent => "% rated",
            Unit::Seconds => "s",
        }
    }

    /// Decimals `status --json` keeps (what a reader can use, not float
    /// noise): milliseconds for times, 6 decimals for the rest.
    pub fn json_digits(self) -> i32 {
        match self {
            Unit::Seconds => 3,
            _ => 6,
        }
    }
}

/// One field of the status table.
#[derive(Clone, Copy, Debug)]
pub struct Row {
    /// The wire entry's accessor and the Python property.
    pub name: &'static str,
    pub ty: Type,
    /// Its bit in `flags`, or its slot in `ints` / `values` (by `ty`).
    pub place: u8,
    pub unit: Unit,
    /// Its key in `status --json`'s axis rows.
    pub json: &'static str,
    /// Its mark in `motionctl status`'s flags column (a flag only).
    pub mark: Option<&'static str>,
    /// Its OPC UA browse name under `Objects/Machine/Axes/<axis>`.
    pub opcua: Option<&'static str>,
    /// What it means (one or more lines; the docs page joins them).
    pub doc: &'static str,
}

impl Row {
    /// The meaning on one line.
    pub fn doc_line(&self) -> String {
        self.doc.split_whitespace().collect::<Vec<_>>().join(" ")
    }

    /// Where it lives, as the docs write it: `flags bit 3`, `values[2]`.
    pub fn place_text(&self) -> String {
        match self.ty.area() {
            Area::Flags => format!("flags bit {}", self.place),
            a => format!("{}[{}]", a.field(), self.place),
        }
    }
}

/// `-` → `None`, a literal → `Some(literal)`.
#[doc(hidden)]
#[macro_export]
macro_rules! __opt {
    (-) => {
        None
    };
    ($x:literal) => {
        Some($x)
    };
}

/// The Rust type of a row's getter and of its typed JSON field.
#[doc(hidden)]
#[macro_export]
macro_rules! __json_ty {
    (Flag) => { bool };
    (Value) => { f64 };
    (Maybe) => { Option<f64> };
    (U16) => { u16 };
    (U32) => { u32 };
    (Enum) => { String };
}

/// The Rust type of the wire entry's accessor.
#[doc(hidden)]
#[macro_export]
macro_rules! __wire_ty {
    (Flag) => { bool };
    (Value) => { f64 };
    (Maybe) => { Option<f64> };
    (U16) => { u16 };
    (U32) => { u32 };
    (Enum) => { &'static str };
}

/// The row's [`Type`] value.
#[doc(hidden)]
#[macro_export]
macro_rules! __type {
    (Enum, $en:ty) => {
        $crate::schema::Type::Enum(|n| {
            u8::try_from(n)
                .ok()
                .and_then(<$en>::from_number)
                .map(<$en>::name)
        })
    };
    ($ty:ident) => {
        $crate::schema::Type::$ty
    };
}

/// Reads a row from a wire entry `$e` (the accessor's body).
#[doc(hidden)]
#[macro_export]
macro_rules! __read {
    (Flag, $e:expr, $p:expr) => {
        $e.flags >> $p & 1 != 0
    };
    (Value, $e:expr, $p:expr) => {
        $e.values[$p as usize]
    };
    (Maybe, $e:expr, $p:expr) => {
        Some($e.values[$p as usize]).filter(|v| v.is_finite())
    };
    (U16, $e:expr, $p:expr) => {
        $e.ints[$p as usize] as u16
    };
    (U32, $e:expr, $p:expr) => {
        $e.ints[$p as usize]
    };
    (Enum, $e:expr, $p:expr, $en:ty) => {
        u8::try_from($e.ints[$p as usize])
            .ok()
            .and_then(<$en>::from_number)
            .map_or("?", <$en>::name)
    };
}

/// Writes a row's value `$v` into a wire entry `$e` (the filler).
#[doc(hidden)]
#[macro_export]
macro_rules! __write {
    (Flag, $e:expr, $p:expr, $v:expr) => {
        if $v {
            $e.flags |= 1u64 << $p;
        }
    };
    (Value, $e:expr, $p:expr, $v:expr) => {
        $e.values[$p as usize] = $v
    };
    (Maybe, $e:expr, $p:expr, $v:expr) => {
        $e.values[$p as usize] = $v.unwrap_or(f64::NAN)
    };
    (U16, $e:expr, $p:expr, $v:expr) => {
        $e.ints[$p as usize] = u32::from($v)
    };
    (U32, $e:expr, $p:expr, $v:expr) => {
        $e.ints[$p as usize] = $v
    };
    (Enum, $e:expr, $p:expr, $v:expr) => {
        $e.ints[$p as usize] = $v as u32
    };
}

/// A row's value for `status --json`, from the entry's accessor `$v`.
#[doc(hidden)]
#[macro_export]
macro_rules! __json {
    (Value, $v:expr, $unit:ident) => {
        $crate::schema::round($v, $crate::schema::Unit::$unit.json_digits())
    };
    (Maybe, $v:expr, $unit:ident) => {
        $v.map(|x| $crate::schema::round(x, $crate::schema::Unit::$unit.json_digits()))
    };
    (Enum, $v:expr, $unit:ident) => {
        $v.to_string()
    };
    ($ty:ident, $v:expr, $unit:ident) => {
        $v
    };
}

/// A flag row's value for the marks of `motionctl status` (other types
/// carry no mark: `false`, never evaluated).
#[doc(hidden)]
#[macro_export]
macro_rules! __flag {
    (Flag, $v:expr) => {
        $v
    };
    ($ty:ident, $v:expr) => {
        false
    };
}

/// Rounds to `digits` decimals for printing.
pub fn round(x: f64, digits: i32) -> f64 {
    let k = 10f64.powi(digits);
    (x * k).round() / k
}

/// Calls a row's getter (a closure over the source), so its argument's type
/// is known where the closure is written.
#[doc(hidden)]
pub fn get<S, T>(source: &S, getter: impl Fn(&S) -> T) -> T {
    getter(source)
}

/// Turns the status table into everything derived from it. Each row:
///
/// ```text
/// /// doc
/// name: Type @ place, Unit, "json key", mark | -, "OpcUaName" | -, |s| getter;
/// ```
///
/// (`Type` is `Flag`, `Value`, `Maybe`, `U16`, `U32` or `Enum<T>` for an
/// enum with a `spellings!` table). It gives:
///
/// * `ROWS`: every row as a [`Row`] (for the layout description, the
///   Python package, OPC UA, the docs page, the checks);
/// * an accessor per row on the wire entry `$entry` (`entry.homed()`,
///   `entry.position()`);
/// * `fill(entry, source)`: the entry's flags, ints and values from the
///   getters (no allocation: the status service fills a frame every 10 ms);
/// * the typed JSON row `$json` (`name`, `io`, `phase`, then a field per
///   row named as the row, its key the row's JSON key, then `owner`,
///   `error`, `warnings`), `$json::from_entry` (the rows' part) and
///   `$json::marks` (the flags column of `motionctl status`) with its
///   header `$json::marks_header`.
#[macro_export]
macro_rules! status_table {
    (
        entry $entry:ident, source $source:ty, json $json:ident;
        $(
            $(#[doc = $doc:literal])+
            $name:ident : $ty:ident $(<$en:ty>)? @ $place:literal, $unit:ident,
                $key:literal, $mark:tt, $opcua:tt, $get:expr;
        )+
    ) => {
        /// Every row of the table, in table order.
        pub const ROWS: &[$crate::schema::Row] = &[$(
            $crate::schema::Row {
                name: stringify!($name),
                ty: $crate::__type!($ty $(, $en)?),
                place: $place,
                unit: $crate::schema::Unit::$unit,
                json: $key,
                mark: $crate::__opt!($mark),
                opcua: $crate::__opt!($opcua),
                doc: concat!($($doc, "\n"),+),
            }
        ),+];

        impl $entry {
            $(
                $(#[doc = $doc])+
                pub fn $name(&self) -> $crate::__wire_ty!($ty) {
                    $crate::__read!($ty, self, $place $(, $en)?)
                }
            )+
        }

        /// Fills the flags, ints and values of `e` from `s`: every flag
        /// cleared first, unused integers 0, unused values NaN.
        pub fn fill(e: &mut $entry, s: &$source) {
            e.flags = 0;
            e.ints = [0; $crate::schema::INT_SLOTS];
            e.values = [f64::NAN; $crate::schema::VALUE_SLOTS];
            $(
                $crate::__write!($ty, e, $place, $crate::schema::get(s, $get));
            )+
        }

        /// One axis of `status --json`.
        #[derive(Clone, Debug, Default, PartialEq, ::serde::Serialize, ::serde::Deserialize)]
        #[serde(default)]
        pub struct $json {
            pub name: String,
            /// Its I/O process by name.
            pub io: String,
            /// Homing phase by name (`idle`, `seek`, `return`, `move_home`, ...).
            pub phase: String,
            $(
                $(#[doc = $doc])+
                #[serde(rename = $key)]
                pub $name: $crate::__json_ty!($ty),
            )+
            /// The program that owns the axis (setpoint stream), if any.
            pub owner: Option<String>,
            /// What went wrong, in words, if anything.
            #[serde(skip_serializing_if = "Option::is_none")]
            pub error: Option<String>,
            /// Warnings of the last homing, in words.
            #[serde(skip_serializing_if = "Vec::is_empty")]
            pub warnings: Vec<String>,
        }

        impl $json {
            /// The rows' part of the JSON row (name, io, phase, owner,
            /// error and warnings left empty).
            pub fn from_entry(e: &$entry) -> Self {
                Self {
                    $($name: $crate::__json!($ty, e.$name(), $unit),)+
                    ..Self::default()
                }
            }

            /// The flags column of `motionctl status`: each marked row's
            /// mark when set, dots when not; a mark longer than one
            /// character stands apart.
            pub fn marks(&self) -> String {
                $crate::schema::marks(&[$(
                    ($crate::__opt!($mark), $crate::__flag!($ty, self.$name)),
                )+])
            }

            /// The flags column's header: every mark.
            pub fn marks_header() -> String {
                $crate::schema::marks(&[$(($crate::__opt!($mark), true),)+])
            }
        }
    };
}

/// The flags column from `(mark, set)` of every row: marks of one character
/// run together, longer ones stand apart (`EN DN ER IP PC SJMTxF-+`).
#[doc(hidden)]
pub fn marks(cells: &[(Option<&str>, bool)]) -> String {
    let mut out = String::new();
    let mut last_long = false;
    for (mark, set) in cells {
        let Some(m) = mark else { continue };
        let long = m.chars().count() > 1;
        if !out.is_empty() && (long || last_long) {
            out.push(' ');
        }
        if *set {
            out.push_str(m);
        } else {
            out.extend(m.chars().map(|_| '.'));
        }
        last_long = long;
    }
    out
}
