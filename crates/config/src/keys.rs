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

    pub fn u32(&mut self, key: &str, default: u32) -> u32 {
        match self.get(key) {
            None => default,
            Some(toml::Value::Integer(i)) => match u32::try_from(*i) {
                Ok(x) => x,
                Err(_) => {
                    self.problem(key, format!("{i} is not a non-negative 32-bit integer"));
                    default
                }
            },
            Some(v) => {
                self.wrong_type(key, "an integer", v);
                default
            }
        }
    }

    pub fn i32(&mut self, key: &str, default: i32) -> i32 {
        match self.get(key) {
            None => default,
            Some(toml::Value::Integer(i)) => match i32::try_from(*i) {
                Ok(x) => x,
                Err(_) => {
                    self.problem(key, format!("{i} is not a 32-bit integer"));
                    default
                }
            },
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
                    self.problem(key, format!("\"{s}\" is not one of {}", names.join(", ")));
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
                        other => self.wrong_type(key, "[[axis]] tables", other),
                    }
                }
                out
            }
            Some(v) => {
                self.wrong_type(key, "[[axis]] tables", v);
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
