//! `{"errors": [...]}` (docs/commands.md, "JSON"): with `--json`, every
//! command prints exactly one JSON object, also when it fails before doing
//! anything.

use serde::{Deserialize, Serialize};

/// One problem. `axis`, `key`, `err`, `exerr` are `null` where they do not apply.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ErrorEntry {
    pub axis: Option<String>,
    pub key: Option<String>,
    pub err: Option<u16>,
    pub exerr: Option<u16>,
    pub message: String,
}

impl ErrorEntry {
    /// A problem with no axis, key or code (a bad argument, no supervisor, ...).
    pub fn message(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            ..Self::default()
        }
    }
}

#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct ErrorReport {
    pub errors: Vec<ErrorEntry>,
}

impl ErrorReport {
    pub fn one(e: ErrorEntry) -> Self {
        Self { errors: vec![e] }
    }

    pub fn message(message: impl Into<String>) -> Self {
        Self::one(ErrorEntry::message(message))
    }
}

/// As a log line: `axis A: key: message (ERR n EXERR m)`, each part only
/// where it applies.
impl std::fmt::Display for ErrorEntry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if let Some(a) = &self.axis {
            write!(f, "axis {a}: ")?;
        }
        if let Some(k) = &self.key {
            write!(f, "{k}: ")?;
        }
        f.write_str(&self.message)?;
        if let (Some(err), Some(exerr)) = (self.err, self.exerr) {
            write!(f, " (ERR {err} EXERR {exerr})")?;
        }
        Ok(())
    }
}

/// Reports `errors` — one JSON object with `json`, else one log line each
/// (stderr) — and returns `code`: how every binary fails.
pub fn fail(json: bool, errors: Vec<ErrorEntry>, code: i32) -> i32 {
    if json {
        crate::print_json(&ErrorReport { errors });
    } else {
        for e in &errors {
            log::error!("{e}");
        }
    }
    code
}

/// A command line clap refused: its message on stderr and exit code 2, or
/// with `--json` among the arguments one JSON error object on stdout (its
/// first line). `--help` / `--version` print and exit 0.
pub fn argument_error(e: clap::Error) -> i32 {
    use clap::error::ErrorKind;
    if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
        let _ = e.print();
        return 0;
    }
    if std::env::args().any(|a| a == "--json") {
        let text = e.render().to_string();
        let first = text
            .lines()
            .next()
            .unwrap_or("bad argument")
            .trim_start_matches("error: ")
            .to_string();
        crate::print_json(&ErrorReport::message(first));
    } else {
        let _ = e.print();
    }
    2
}

#[cfg(test)]
mod display_tests {
    use super::*;

    #[test]
    fn a_line_names_what_applies() {
        let e = ErrorEntry {
            axis: Some("X".into()),
            key: Some("home_speed".into()),
            err: Some(12),
            exerr: Some(40),
            message: "bad".into(),
        };
        assert_eq!(e.to_string(), "axis X: home_speed: bad (ERR 12 EXERR 40)");
        let e = ErrorEntry {
            axis: Some("X".into()),
            ..ErrorEntry::message("gone")
        };
        assert_eq!(e.to_string(), "axis X: gone");
        assert_eq!(ErrorEntry::message("m").to_string(), "m");
    }
}
