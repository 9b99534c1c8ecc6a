//! Typed reads from a TOML table that record a [`Problem`] instead of
//! stopping, and report every key nobody read (a typo is a problem too).

use crate::Problem;
use std::collections::BTreeSet;

pub(crate) struct Reader<'a> {
    table: &'a toml::Table,
    axis: Option<String>,
    prefix: &'static str,
    used: BTreeSet<String>,
    problems: &'a mut Vec<Problem>,
}

impl<'a> Reader<'a> {
    pub fn new(
        table: &'a toml::Table,
        axis: Option<&str>,
        prefix: &'static str,
        problems: &'a mut Vec<Problem>,
    ) -> Self {
        Self {
            table,
            axis: axis.map(str::to_string),
            prefix,
            used: BTreeSet::new(),
            problems,
        }
    }

    pub fn problem(&mut self, key: &str, message: String) {
        let key = format!("{}{key}", self.prefix);
        self.problems
            .push(Problem::new(self.axis.as_deref(), &key, message));
    }

    pub fn mark_used(&mut self, key: &str) {
        self.used.insert(key.to_string());
    }

    fn get(&mut self, key: &str) -> Option<&'a toml::Value> {
        self.used.insert(key.to_string());
        self.table.get(key)
    }

    fn wrong_type(&mut self, key: &str, want: &str, v: &toml::Value) {
        self.problem(key, format!("expected {want}, found {}", v.type_str()));
    }

    pub fn f64(&mut self, key: &str, default: f64) -> f64 {
        match self.get(key) {
            None => default,
            Some(toml::Value::Float(x)) => *x,
            Some(toml::Value::Integer(i)) => *i as f64,
            Some(v) => {
                self.wrong_type(key, "a number", v);
                default
            }
        }
    }

    /// A number in `[lo, hi]`; anything else (NaN, ±inf, out of range) is a
    /// problem naming the key and the range, and gives `default`.
    pub fn f64_in(&mut self, key: &str, default: f64, lo: f64, hi: f64, unit: &str) -> f64 {
        let present = self.table.contains_key(key);
        let x = self.f64(key, default);
        if present && !(x.is_finite() && x >= lo && x <= hi) {
            let what = if x.is_finite() {
                "is outside"
            } else {
                "is not a finite number; allowed:"
            };
            self.problem(
                key,
                format!("{} {what} {}..={} {unit}", num(x), num(lo), num(hi)),
            );
            return default;
        }
        x
    }

    /// A number in `(0, hi]` when present; 0 when absent (the caller's
    /// "default"). Zero given is a problem that says what leaving the key
    /// out means (`default`); anything else outside is `f64_in`'s problem.
    pub fn f64_positive(&mut self, key: &str, hi: f64, unit: &str, default: &str) -> f64 {
        let present = self.table.contains_key(key);
        let x = self.f64(key, 0.0);
        if present && x == 0.0 {
            self.problem(
                key,
                format!("must be above 0 {unit} (leave it out for the default: {default})"),
            );
            return 0.0;
        }
        if present && !(x.is_finite() && x > 0.0 && x <= hi) {
            let what = if x.is_finite() {
                "is outside"
            } else {
                "is not a finite number; allowed:"
            };
            self.problem(
                key,
                format!("{} {what} 0 (excluded)..={} {unit}", num(x), num(hi)),
            );
            return 0.0;
        }
        x
    }

    /// `[lo, hi]` of two finite numbers within ±`bound`, `lo < hi`.
    pub fn interval(&mut self, key: &str, bound: f64) -> Option<(f64, f64)> {
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

    /// A non-negative integer of at most `hi`.
    pub fn u32_in(&mut self, key: &str, default: u32, lo: u32, hi: u32) -> u32 {
        let present = self.table.contains_key(key);
        let x = self.u32(key, default);
        if present && !(lo..=hi).contains(&x) {
            self.problem(key, format!("{x} is outside {lo}..={hi}"));
            return default;
        }
        x
    }

    pub fn has(&self, key: &str) -> bool {
        self.table.contains_key(key)
    }

    pub fn u32(&mut self, key: &str, default: u32) -> u32 {
        self.integer(key, default, "a non-negative 32-bit integer")
    }

    pub fn i32(&mut self, key: &str, default: i32) -> i32 {
        self.integer(key, default, "a 32-bit integer")
    }

    /// An integer key that must fit `T` (`what` names the range in the
    /// problem).
    fn integer<T: TryFrom<i64>>(&mut self, key: &str, default: T, what: &str) -> T {
        match self.get(key) {
            None => default,
            Some(toml::Value::Integer(i)) => {
                let i = *i;
                T::try_from(i).unwrap_or_else(|_| {
                    self.problem(key, format!("{i} is not {what}"));
                    default
                })
            }
            Some(v) => {
                self.wrong_type(key, "an integer", v);
                default
            }
        }
    }

    pub fn bool(&mut self, key: &str, default: bool) -> bool {
        match self.get(key) {
            None => default,
            Some(toml::Value::Boolean(b)) => *b,
            Some(v) => {
                self.wrong_type(key, "true or false", v);
                default
            }
        }
    }

    pub fn string(&mut self, key: &str, default: &str) -> String {
        match self.get(key) {
            None => default.to_string(),
            Some(toml::Value::String(s)) => s.clone(),
            Some(v) => {
                self.wrong_type(key, "a string", v);
                default.to_string()
            }
        }
    }

    pub fn choice<T: Copy>(&mut self, key: &str, options: &[(&str, T)], default: T) -> T {
        match self.get(key) {
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
    pub fn pair(&mut self, key: &str) -> Option<(f64, f64)> {
        let v = self.get(key)?;
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

    pub fn table(&mut self, key: &str) -> Option<toml::Table> {
        match self.get(key)? {
            toml::Value::Table(t) => Some(t.clone()),
            v => {
                self.wrong_type(key, "a table", v);
                None
            }
        }
    }

    pub fn array_of_tables(&mut self, key: &str) -> Vec<toml::Table> {
        match self.get(key) {
            None => Vec::new(),
            Some(toml::Value::Array(a)) => {
                let mut out = Vec::new();
                for v in a {
                    match v {
                        toml::Value::Table(t) => out.push(t.clone()),
                        other => self.wrong_type(key, &format!("[[{key}]] tables"), other),
                    }
                }
                out
            }
            Some(v) => {
                self.wrong_type(key, &format!("[[{key}]] tables"), v);
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
                    &format!("{}{k}", self.prefix),
                    "unknown key (misspelt?)",
                ));
            }
        }
    }
}

/// A number as a person reads it: plain in the usual range, scientific
/// beyond (`1e308`, not 309 digits).
pub(crate) fn num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e10).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}
