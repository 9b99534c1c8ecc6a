//! A configuration problem, printed as `axis X: home_speed: …`.

use motion_homing::ConfigError;
use motion_report::ErrorEntry;
use std::fmt;

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Problem {
    /// The axis (by name, or `#n` when it has none), `None` for the rest.
    pub axis: Option<String>,
    /// The TOML key, dotted below the axis (`sim.switch`).
    pub key: String,
    pub message: String,
    /// CIP codes where the engine's validation found it (ERR, EXERR).
    pub code: Option<(u16, u16)>,
}

impl Problem {
    pub fn new(axis: Option<&str>, key: &str, message: impl Into<String>) -> Self {
        Self {
            axis: axis.map(str::to_string),
            key: key.to_string(),
            message: message.into(),
            code: None,
        }
    }

    pub fn from_engine(axis: &str, e: &ConfigError) -> Self {
        Self {
            axis: Some(axis.to_string()),
            key: e.attribute.to_string(),
            message: e.message.clone(),
            code: Some((e.err, e.exerr)),
        }
    }

    /// A TOML syntax error, located by line and column in `text`.
    pub fn syntax(text: &str, e: &toml::de::Error) -> Self {
        let msg = e.message().to_string();
        let key = match e.span() {
            Some(s) => {
                let before = &text[..s.start.min(text.len())];
                let line = before.matches('\n').count() + 1;
                let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
                format!("line {line}, column {col}")
            }
            None => "file".to_string(),
        };
        Self::new(None, &key, format!("TOML syntax: {msg}"))
    }
}

/// A problem as a JSON error entry (`{"errors": [...]}`, a fixed shape):
/// how every binary reports a configuration it refuses.
impl From<&Problem> for ErrorEntry {
    fn from(p: &Problem) -> Self {
        ErrorEntry {
            axis: p.axis.clone(),
            key: Some(p.key.clone()),
            err: p.code.map(|c| c.0),
            exerr: p.code.map(|c| c.1),
            message: p.message.clone(),
        }
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.axis {
            Some(a) => write!(f, "axis {a}: {}: {}", self.key, self.message)?,
            None => write!(f, "{}: {}", self.key, self.message)?,
        }
        if let Some((err, exerr)) = self.code {
            write!(f, " (ERR {err} EXERR {exerr})")?;
        }
        Ok(())
    }
}
