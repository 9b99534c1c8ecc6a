//! A tiny command-line reader: `--flag value`, `--flag=value` and boolean
//! `--flag`; every unknown or malformed argument is an error.

use std::str::FromStr;

pub struct Args {
    items: Vec<String>,
}

impl Args {
    /// The process's arguments after the program name.
    pub fn from_env() -> Self {
        Self::new(std::env::args().skip(1))
    }

    pub fn new<I: IntoIterator<Item = String>>(args: I) -> Self {
        let mut items = Vec::new();
        for a in args {
            match a.split_once('=') {
                Some((flag, v)) if flag.starts_with("--") => {
                    items.push(flag.to_string());
                    items.push(v.to_string());
                }
                _ => items.push(a),
            }
        }
        Self { items }
    }

    /// True (and consumed) if `name` was given.
    pub fn flag(&mut self, name: &str) -> bool {
        match self.items.iter().position(|a| a == name) {
            Some(i) => {
                self.items.remove(i);
                true
            }
            None => false,
        }
    }

    /// The value after `name`, if given.
    pub fn value(&mut self, name: &str) -> Result<Option<String>, String> {
        let Some(i) = self.items.iter().position(|a| a == name) else {
            return Ok(None);
        };
        if i + 1 >= self.items.len() || self.items[i + 1].starts_with("--") {
            return Err(format!("{name} needs a value"));
        }
        let v = self.items.remove(i + 1);
        self.items.remove(i);
        if self.items.iter().any(|a| a == name) {
            return Err(format!("{name} given twice"));
        }
        Ok(Some(v))
    }

    /// The value after `name` parsed as `T`, or `default`.
    pub fn num<T: FromStr>(&mut self, name: &str, default: T) -> Result<T, String> {
        match self.value(name)? {
            None => Ok(default),
            Some(v) => v
                .parse()
                .map_err(|_| format!("{name} {v:?}: not a valid number")),
        }
    }

    /// Errors on anything not consumed.
    pub fn finish(self) -> Result<(), String> {
        match self.items.first() {
            None => Ok(()),
            Some(a) => Err(format!("unexpected argument {a:?}")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_flags_and_values() {
        let mut a = Args::new(
            ["--duration=10", "--stress", "--slice", "2.5", "--x"]
                .iter()
                .map(|s| s.to_string()),
        );
        assert_eq!(a.num("--duration", 60.0).unwrap(), 10.0);
        assert_eq!(a.num("--slice", 5.0).unwrap(), 2.5);
        assert_eq!(a.num("--period-us", 1000u32).unwrap(), 1000);
        assert!(a.flag("--stress"));
        assert!(!a.flag("--stress"));
        assert!(a.value("--x").is_err());
    }
}
