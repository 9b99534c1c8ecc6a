//! Every configuration key, declared once: its section, name, type,
//! default, bounds, unit, meaning and an example.
//!
//! The parser reads keys only through these declarations (every read of
//! [`crate::keys::Reader`] names a [`Key`], and a debug build checks that the
//! key is in [`GROUPS`]), and `motion-docgen` writes `docs/configuration.md`
//! and the man page `motion-machine.toml(5)` from the same rows — so a key
//! cannot be read without being documented, nor documented with a default
//! or a range the code does not have.
//!
//! Adding a key is one row in the group it belongs to (the `keys!` list of
//! one of the files below); the parser then reads it by that name.
//!
//! Defaults that follow from other keys ([`Default::Derived`]) are computed
//! by the parser, which passes the value (`Reader::f64_or`, ...); the row
//! says how in words. Bounds that depend on another key (a watchdog of at
//! most a second of cycles) are [`Bounds::Text`] and checked by the parser
//! with numbers it computes.

pub mod axis;
pub mod ethercat;
pub mod gantry;
pub mod io;
pub mod opcua;
pub mod operations;
pub mod sim;
pub mod supervisor;
pub mod top;

/// The tables of a machine configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Section {
    /// The file itself: the tables below.
    Top,
    Supervisor,
    Io,
    Axis,
    /// `[axis.sim]`, below an `[[axis]]`.
    AxisSim,
    Gantry,
    Opcua,
    /// `[[opcua.user]]`.
    OpcuaUser,
}

impl Section {
    /// How the table is written in a file.
    pub const fn header(self) -> &'static str {
        match self {
            Section::Top => "(top level)",
            Section::Supervisor => "[supervisor]",
            Section::Io => "[[io]]",
            Section::Axis => "[[axis]]",
            Section::AxisSim => "[axis.sim]",
            Section::Gantry => "[[gantry]]",
            Section::Opcua => "[opcua]",
            Section::OpcuaUser => "[[opcua.user]]",
        }
    }

    /// What a problem's key starts with (`supervisor.cycle_us`,
    /// `sim.switch` below an axis, `home_speed` of an axis).
    pub const fn prefix(self) -> &'static str {
        match self {
            Section::Top | Section::Axis => "",
            Section::Supervisor => "supervisor.",
            Section::Io => "io.",
            Section::AxisSim => "sim.",
            Section::Gantry => "gantry.",
            Section::Opcua => "opcua.",
            Section::OpcuaUser => "opcua.user.",
        }
    }
}

/// The names a choice takes, as its enum spells them (`spellings!`).
pub type Names = fn() -> Vec<&'static str>;

/// The spellings of a `spellings!` table (or any name → value list).
pub fn names_of<T>(table: &[(&'static str, T)]) -> Vec<&'static str> {
    table.iter().map(|(n, _)| *n).collect()
}

/// What a key holds.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    /// A whole number.
    Integer,
    /// A number (an integer is read as a number too).
    Number,
    Bool,
    /// A string.
    Text,
    /// One of the names.
    Choice(Names),
    /// A list of the names.
    ChoiceList(Names),
    /// `[low, high]`, two numbers.
    Interval,
    /// A list of names (strings).
    NameList,
    /// An inline table of name → one of the names (`{ X = "mm" }`).
    NameMap(Names),
    /// A table (`[name]`).
    Table,
    /// An array of tables (`[[name]]`).
    Tables,
}

impl Kind {
    /// The type in words, for the docs.
    pub fn describe(self) -> String {
        let quoted = |n: Names| {
            n().iter()
                .map(|s| format!("\"{s}\""))
                .collect::<Vec<_>>()
                .join(" | ")
        };
        match self {
            Kind::Integer => "integer".into(),
            Kind::Number => "number".into(),
            Kind::Bool => "boolean".into(),
            Kind::Text => "string".into(),
            Kind::Choice(n) => quoted(n),
            Kind::ChoiceList(n) => format!("list of {}", quoted(n)),
            Kind::Interval => "[low, high]".into(),
            Kind::NameList => "list of strings".into(),
            Kind::NameMap(n) => format!("{{ axis = {} }}", quoted(n)),
            Kind::Table => "table".into(),
            Kind::Tables => "array of tables".into(),
        }
    }
}

/// A key's value when it is left out.
#[derive(Clone, Copy, Debug)]
pub enum Default {
    /// The key must be given.
    Required,
    /// Nothing: what leaving it out means, in words ("none: no limits").
    Unset(&'static str),
    Int(i64),
    Num(f64),
    Bool(bool),
    /// A string, or the name of a choice.
    Text(&'static str),
    /// Computed from other keys, as the words say (the parser computes it).
    Derived(&'static str),
}

/// The values a key may take beyond its type.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bounds {
    /// Any value of the type.
    Any,
    /// `low..=high`.
    Range(f64, f64),
    /// Above 0 (0 excluded) up to and including the number.
    AboveZero(f64),
    /// At most the number.
    AtMost(f64),
    /// Depends on other keys, as the words say (the parser checks it).
    Text(&'static str),
}

/// Whether a key is current.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    Current,
    /// An older spelling still read, with the meaning of the key named.
    Alias(&'static str),
    /// Still read, converted; the words say to what.
    Deprecated(&'static str),
    /// Never accepted: the words say what to write instead.
    Refused(&'static str),
}

/// Where a key applies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Only {
    Always,
    /// An `[[io]]` with `backend = "ethercat"`, or an axis of one: a
    /// problem anywhere else.
    Ethercat,
}

/// One configuration key.
#[derive(Clone, Copy, Debug)]
pub struct Key {
    pub section: Section,
    pub name: &'static str,
    pub kind: Kind,
    pub default: Default,
    pub bounds: Bounds,
    /// Unit of a number ("units/s"; "" for none).
    pub unit: &'static str,
    /// Constraints beyond the bounds, in words ("and at least 3 cycles").
    pub note: &'static str,
    pub only: Only,
    pub status: Status,
    /// The name is one of the interface's fixed points: scripts and tools
    /// outside this repository depend on it, so it never changes.
    pub fixed: bool,
    /// What it does, in Markdown (code spans only: the man page renders
    /// them too).
    pub meaning: &'static str,
    /// A value, as written after `name = ` in a file.
    pub example: &'static str,
}

impl Key {
    pub const fn new(section: Section, name: &'static str, kind: Kind) -> Key {
        Key {
            section,
            name,
            kind,
            default: Default::Required,
            bounds: Bounds::Any,
            unit: "",
            note: "",
            only: Only::Always,
            status: Status::Current,
            fixed: false,
            meaning: "",
            example: "",
        }
    }
    pub const fn default(mut self, d: Default) -> Key {
        self.default = d;
        self
    }
    pub const fn num(self, x: f64) -> Key {
        self.default(Default::Num(x))
    }
    pub const fn int(self, x: i64) -> Key {
        self.default(Default::Int(x))
    }
    pub const fn flag(self, b: bool) -> Key {
        self.default(Default::Bool(b))
    }
    pub const fn text(self, s: &'static str) -> Key {
        self.default(Default::Text(s))
    }
    pub const fn unset(self, what: &'static str) -> Key {
        self.default(Default::Unset(what))
    }
    pub const fn derived(self, how: &'static str) -> Key {
        self.default(Default::Derived(how))
    }
    pub const fn range(mut self, lo: f64, hi: f64) -> Key {
        self.bounds = Bounds::Range(lo, hi);
        self
    }
    pub const fn above_zero(mut self, hi: f64) -> Key {
        self.bounds = Bounds::AboveZero(hi);
        self
    }
    pub const fn at_most(mut self, hi: f64) -> Key {
        self.bounds = Bounds::AtMost(hi);
        self
    }
    pub const fn bounded(mut self, words: &'static str) -> Key {
        self.bounds = Bounds::Text(words);
        self
    }
    pub const fn unit(mut self, u: &'static str) -> Key {
        self.unit = u;
        self
    }
    pub const fn note(mut self, n: &'static str) -> Key {
        self.note = n;
        self
    }
    pub const fn ethercat(mut self) -> Key {
        self.only = Only::Ethercat;
        self
    }
    pub const fn status(mut self, s: Status) -> Key {
        self.status = s;
        self
    }
    pub const fn fixed(mut self) -> Key {
        self.fixed = true;
        self
    }
    pub const fn meaning(mut self, m: &'static str) -> Key {
        self.meaning = m;
        self
    }
    pub const fn example(mut self, e: &'static str) -> Key {
        self.example = e;
        self
    }

    /// `(low, high)` of a [`Bounds::Range`] (the parser's check).
    pub const fn range_of(&self) -> (f64, f64) {
        match self.bounds {
            Bounds::Range(lo, hi) => (lo, hi),
            Bounds::AboveZero(hi) => (0.0, hi),
            Bounds::AtMost(hi) => (f64::NEG_INFINITY, hi),
            Bounds::Any | Bounds::Text(_) => (f64::NEG_INFINITY, f64::INFINITY),
        }
    }

    /// The default as a number (0 when it is not one: a derived default is
    /// passed by the parser, a required or unset key has none).
    pub const fn default_f64(&self) -> f64 {
        match self.default {
            Default::Num(x) => x,
            Default::Int(i) => i as f64,
            _ => 0.0,
        }
    }

    /// The default as a boolean (false when it is not one).
    pub const fn default_bool(&self) -> bool {
        matches!(self.default, Default::Bool(true))
    }

    /// The default as text ("" when it is not one).
    pub const fn default_text(&self) -> &'static str {
        match self.default {
            Default::Text(s) => s,
            _ => "",
        }
    }

    /// `section name` as the docs name a key (`[[axis]] home_speed`).
    pub fn qualified(&self) -> String {
        format!("{} {}", self.section.header(), self.name)
    }
}

/// Keys documented together, in the order of the docs.
#[derive(Debug)]
pub struct Group {
    pub section: Section,
    /// The group's heading.
    pub title: &'static str,
    /// A paragraph before its keys (Markdown, code spans only).
    pub intro: &'static str,
    pub keys: &'static [&'static Key],
}

/// Declares a group of keys: each row is `NAME: Key::new(..)...`, and the
/// group lists them in the order given.
macro_rules! keys {
    ($group:ident { section: $section:expr, title: $title:expr, intro: $intro:expr $(,)? }
     $($name:ident: $key:expr;)+) => {
        $(pub const $name: $crate::keytable::Key = $key;)+
        pub const $group: $crate::keytable::Group = $crate::keytable::Group {
            section: $section,
            title: $title,
            intro: $intro,
            keys: &[$(&$name),+],
        };
    };
}
pub(crate) use keys;

/// Every group, in the order of the docs.
pub const GROUPS: &[&Group] = &[
    &top::GROUP,
    &supervisor::GROUP,
    &io::GROUP,
    &ethercat::IO,
    &axis::IDENTITY,
    &axis::HOMING,
    &axis::SUPERVISION,
    &operations::GROUP,
    &ethercat::AXIS,
    &sim::GROUP,
    &gantry::GROUP,
    &opcua::GROUP,
    &opcua::USER_GROUP,
];

/// Every key.
pub fn all() -> impl Iterator<Item = &'static Key> {
    GROUPS.iter().flat_map(|g| g.keys.iter().copied())
}

/// The key `name` of `section`, if declared.
pub fn find(section: Section, name: &str) -> Option<&'static Key> {
    all().find(|k| k.section == section && k.name == name)
}

/// A number as a person reads it: plain in the usual range, scientific
/// beyond (`1e308`, not 309 digits).
pub fn number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e10).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

#[cfg(test)]
mod tests;
