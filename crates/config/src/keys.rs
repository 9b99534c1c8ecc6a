//! Typed reads from a TOML table that record a [`Problem`] instead of
//! stopping, and report every key nobody read (a typo is a problem too).
//! Every read names a key of the key table ([`crate::keytable`]): its
//! default, range and unit come from there.

pub(crate) use crate::keytable::number as num;
use crate::keytable::{self, Key, Section};
use crate::Problem;
use std::collections::BTreeSet;

pub(crate) struct Reader<'a> {
    table: &'a toml::Table,
    axis: Option<String>,
    section: Section,
    used: BTreeSet<String>,
    problems: &'a mut Vec<Problem>,
}

impl<'a> Reader<'a> {
    /// Reads `table`, a `section` (of `axis`, named in problems).
    pub fn new(
        table: &'a toml::Table,
        axis: Option<&str>,
        section: Section,
        problems: &'a mut Vec<Problem>,
    ) -> Self {
        Self {
            table,
            axis: axis.map(str::to_string),
            section,
            used: BTreeSet::new(),
            problems,
        }
    }

    /// A problem with `key`.
    pub fn problem(&mut self, key: &Key, message: String) {
        self.problem_at(key.name, message);
    }

    /// A problem named by a key below one of this section's keys
    /// (`units.X`).
    pub fn problem_at(&mut self, key: &str, message: String) {
        let key = format!("{}{key}", self.section.prefix());
        self.problems
            .push(Problem::new(self.axis.as_deref(), &key, message));
    }

    /// `key` is this section's and declared in the key table: a key read
    /// must be documented (debug builds and tests check it).
    fn declared(&self, key: &Key) {
        debug_assert!(
            key.section == self.section && keytable::find(key.section, key.name).is_some(),
            "{} is read in {} but not declared there in the key table",
            key.name,
            self.section.header()
        );
    }

    pub fn mark_used(&mut self, key: &Key) {
        self.declared(key);
        self.used.insert(key.name.to_string());
    }

    /// The raw value of `key`, marked as read.
    pub fn value(&mut self, key: &Key) -> Option<&'a toml::Value> {
        self.mark_used(key);
        self.table.get(key.name)
    }

    fn wrong_type(&mut self, key: &Key, want: &str, v: &toml::Value) {
        self.problem(key, format!("expected {want}, found {}", v.type_str()));
    }

    /// A number, or its default (the key's, `default` for a derived one).
    fn number(&mut self, key: &Key, default: f64) -> f64 {
        self.typed(key, default, "a number", |v| match v {
            toml::Value::Float(x) => Some(*x),
            toml::Value::Integer(i) => Some(*i as f64),
            _ => None,
        })
    }

    /// The key's value as `read` takes it, `default` when left out; a value
    /// `read` does not take (`None`) is a problem ("expected `want`") and
    /// gives `default`.
    fn typed<T>(
        &mut self,
        key: &Key,
        default: T,
        want: &str,
        read: impl FnOnce(&toml::Value) -> Option<T>,
    ) -> T {
        match self.value(key) {
            None => default,
            Some(v) => match read(v) {
                Some(x) => x,
                None => {
                    self.wrong_type(key, want, v);
                    default
                }
            },
        }
    }

    /// A number in the key's range (its default when left out).
    pub fn f64_in(&mut self, key: &Key) -> f64 {
        self.f64_in_or(key, key.default_f64())
    }

    /// A number in the key's range; anything else (NaN, ±inf, out of range)
    /// is a problem naming the key and the range, and gives `default` (the
    /// derived default of the key).
    pub fn f64_in_or(&mut self, key: &Key, default: f64) -> f64 {
        let (lo, hi) = key.range_of();
        let present = self.table.contains_key(key.name);
        let x = self.number(key, default);
        if present && !(x.is_finite() && x >= lo && x <= hi) {
            self.outside(key, x, &format!("{}..={}", num(lo), num(hi)));
            return default;
        }
        x
    }

    /// The problem of `x`, given for `key`, outside `allowed` (the range as
    /// the problem says it) or not a finite number at all.
    fn outside(&mut self, key: &Key, x: f64, allowed: &str) {
        let what = if x.is_finite() {
            "is outside"
        } else {
            "is not a finite number; allowed:"
        };
        let unit = key.unit;
        self.problem(key, format!("{} {what} {allowed} {unit}", num(x)));
    }

    /// A number in `(0, hi]` (the key's [`Bounds::AboveZero`](crate::keytable::Bounds::AboveZero)) when
    /// present; 0 when absent (the engine derives it). Zero given is a
    /// problem that says what leaving the key out means (`default`, in
    /// words); anything else outside is `f64_in`'s problem.
    pub fn f64_positive(&mut self, key: &Key, default: &str) -> f64 {
        let (_, hi) = key.range_of();
        let unit = key.unit;
        let present = self.table.contains_key(key.name);
        let x = self.number(key, 0.0);
        if present && x == 0.0 {
            self.problem(
                key,
                format!("must be above 0 {unit} (leave it out for the default: {default})"),
            );
            return 0.0;
        }
        if present && !(x.is_finite() && x > 0.0 && x <= hi) {
            self.outside(key, x, &format!("0 (excluded)..={}", num(hi)));
            return 0.0;
        }
        x
    }

    /// `[lo, hi]` of two finite numbers within the key's range, `lo < hi`.
    pub fn interval(&mut self, key: &Key) -> Option<(f64, f64)> {
        let (_, bound) = key.range_of();
        let (a, b) = self.pair(key)?;
        if !(a.is_finite() && b.is_finite() && a.abs() <= bound && b.abs() <= bound) {
            self.problem(
                key,
                format!(
                    "[{}, {}]: both ends must be finite numbers within ±{}",
                    num(a),
                    num(b),
                    num(bound)
                ),
            );
            return None;
        }
        if a >= b {
            self.problem(
                key,
                format!("[{}, {}]: low must be below high", num(a), num(b)),
            );
            return None;
        }
        Some((a, b))
    }

    /// A non-negative integer in the key's range (its default when left
    /// out).
    pub fn u32_in(&mut self, key: &Key) -> u32 {
        let (lo, hi) = key.range_of();
        self.u32_within(key, key.default_f64() as u32, lo as u32, hi as u32)
    }

    /// A non-negative integer in the key's range, `default` when left out
    /// or wrong.
    pub fn u32_in_or(&mut self, key: &Key, default: u32) -> u32 {
        let (lo, hi) = key.range_of();
        self.u32_within(key, default, lo as u32, hi as u32)
    }

    /// A non-negative integer in `lo..=hi` (a range the key's words state,
    /// computed by the caller).
    pub fn u32_within(&mut self, key: &Key, default: u32, lo: u32, hi: u32) -> u32 {
        let present = self.table.contains_key(key.name);
        let x = self.u32_or(key, default);
        if present && !(lo..=hi).contains(&x) {
            self.problem(key, format!("{x} is outside {lo}..={hi}"));
            return default;
        }
        x
    }

    pub fn has(&self, key: &Key) -> bool {
        self.declared(key);
        self.table.contains_key(key.name)
    }

    /// A non-negative 32-bit integer (its default when left out).
    pub fn u32(&mut self, key: &Key) -> u32 {
        self.u32_or(key, key.default_f64() as u32)
    }

    pub fn u32_or(&mut self, key: &Key, default: u32) -> u32 {
        self.integer(key, default, "a non-negative 32-bit integer")
    }

    /// A 32-bit integer (its default when left out).
    pub fn i32(&mut self, key: &Key) -> i32 {
        self.i32_or(key, key.default_f64() as i32)
    }

    pub fn i32_or(&mut self, key: &Key, default: i32) -> i32 {
        self.integer(key, default, "a 32-bit integer")
    }

    /// An integer key that must fit `T` (`what` names the range in the
    /// problem).
    fn integer<T: TryFrom<i64>>(&mut self, key: &Key, default: T, what: &str) -> T {
        match self.typed(key, None, "an integer", |v| v.as_integer().map(Some)) {
            None => default,
            Some(i) => T::try_from(i).unwrap_or_else(|_| {
                self.problem(key, format!("{i} is not {what}"));
                default
            }),
        }
    }

    /// true or false (its default when left out).
    pub fn bool(&mut self, key: &Key) -> bool {
        self.bool_or(key, key.default_bool())
    }

    pub fn bool_or(&mut self, key: &Key, default: bool) -> bool {
        self.typed(key, default, "true or false", toml::Value::as_bool)
    }

    /// A string (its default when left out; "" for a key without one).
    pub fn string(&mut self, key: &Key) -> String {
        let default = key.default_text().to_string();
        self.typed(key, default, "a string", |v| v.as_str().map(str::to_string))
    }

    /// An absolute path of at most 200 characters without `..` (a
    /// directory the daemon keeps files in); a problem otherwise.
    pub fn directory(&mut self, key: &Key) -> std::path::PathBuf {
        let d = self.string(key);
        if !d.starts_with('/') || d.len() > 200 || d.contains("..") {
            self.problem(
                key,
                format!(
                    "{} must be an absolute path of at most 200 characters without \"..\"",
                    crate::names::shown(&d)
                ),
            );
        }
        d.into()
    }

    /// One of `options` (the key's default, by name, when left out or
    /// wrong; the first option for a key without one).
    pub fn choice<T: Copy>(&mut self, key: &Key, options: &[(&str, T)]) -> T {
        let default = options
            .iter()
            .find(|(n, _)| *n == key.default_text())
            .unwrap_or(&options[0])
            .1;
        match self.value(key) {
            None => default,
            Some(toml::Value::String(s)) => match options.iter().find(|(n, _)| n == s) {
                Some((_, t)) => *t,
                None => {
                    let names: Vec<String> =
                        options.iter().map(|(n, _)| format!("\"{n}\"")).collect();
                    self.problem(
                        key,
                        format!(
                            "{} is not one of {}",
                            crate::names::shown(s),
                            names.join(", ")
                        ),
                    );
                    default
                }
            },
            Some(v) => {
                self.wrong_type(key, "a string", v);
                default
            }
        }
    }

    /// `[lo, hi]` of two numbers.
    fn pair(&mut self, key: &Key) -> Option<(f64, f64)> {
        let v = self.value(key)?;
        let num = |x: &toml::Value| match x {
            toml::Value::Float(f) => Some(*f),
            toml::Value::Integer(i) => Some(*i as f64),
            _ => None,
        };
        match v.as_array().map(|a| a.as_slice()) {
            Some([a, b]) => match (num(a), num(b)) {
                (Some(a), Some(b)) => Some((a, b)),
                _ => {
                    self.problem(key, "expected [low, high] of two numbers".into());
                    None
                }
            },
            _ => {
                self.problem(key, "expected [low, high] of two numbers".into());
                None
            }
        }
    }

    pub fn table(&mut self, key: &Key) -> Option<toml::Table> {
        match self.value(key)? {
            toml::Value::Table(t) => Some(t.clone()),
            v => {
                self.wrong_type(key, "a table", v);
                None
            }
        }
    }

    pub fn array_of_tables(&mut self, key: &Key) -> Vec<toml::Table> {
        let name = key.name;
        match self.value(key) {
            None => Vec::new(),
            Some(toml::Value::Array(a)) => {
                let mut out = Vec::new();
                for v in a {
                    match v {
                        toml::Value::Table(t) => out.push(t.clone()),
                        other => self.wrong_type(key, &format!("[[{name}]] tables"), other),
                    }
                }
                out
            }
            Some(v) => {
                self.wrong_type(key, &format!("[[{name}]] tables"), v);
                Vec::new()
            }
        }
    }

    /// Reports every key of the table that no read asked for.
    pub fn finish(self) {
        for k in self.table.keys() {
            if !self.used.contains(k) {
                self.problems.push(Problem::new(
                    self.axis.as_deref(),
                    &format!("{}{k}", self.section.prefix()),
                    "unknown key (misspelt?)",
                ));
            }
        }
    }
}
