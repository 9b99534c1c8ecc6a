//! `{"errors": [...]}` (interface.md, "Errors as JSON"): with `--json`, every
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
