//! The stored reference of an absolute axis.
//!
//! An absolute encoder keeps its raw position over power cycles, so the
//! reference found once (the raw → axis offset) stays true until something
//! changes what raw positions mean: another encoder, another I/O slot,
//! another scaling, another Home Position. The file therefore stores, next
//! to the offset, the [`AxisIdentity`] it was found with; a reference whose
//! identity differs from the running configuration is invalidated, not
//! restored.
//!
//! An invalidated reference stays in its file with the reason (so an
//! operator can see why the axis did not come up homed); only a successful
//! homing replaces it.

use crate::atomic;
use crate::dir::StateDir;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Files above this size are refused, not parsed.
const MAX_FILE: u64 = 16 * 1024;
/// The file format written by this version.
pub const FORMAT: u32 = 1;

/// What a raw position means for this axis: the configuration keys that,
/// when changed, make a stored offset meaningless (key → value as text).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct AxisIdentity(pub BTreeMap<String, String>);

impl AxisIdentity {
    pub fn with(mut self, key: &str, value: impl ToString) -> Self {
        self.0.insert(key.into(), value.to_string());
        self
    }

    /// The keys whose values differ, as `key a → b` (empty: the same).
    pub fn differences(&self, now: &AxisIdentity) -> Vec<String> {
        let mut keys: Vec<&String> = self.0.keys().chain(now.0.keys()).collect();
        keys.sort();
        keys.dedup();
        keys.into_iter()
            .filter_map(|k| {
                let (a, b) = (self.0.get(k), now.0.get(k));
                (a != b).then(|| {
                    format!(
                        "{k} {} → {}",
                        a.map_or("(none)", String::as_str),
                        b.map_or("(none)", String::as_str)
                    )
                })
            })
            .collect()
    }
}

/// Why a stored reference can no longer be trusted, and since when.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Invalidation {
    pub reason: String,
    pub at: String,
}

/// One axis's stored reference file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StoredReference {
    pub format: u32,
    pub axis: String,
    /// Raw → axis offset: axis position = raw + offset.
    pub offset: f64,
    /// The part of `offset` redefine position added after homing: the soft
    /// limits read `travel_limits` + `shift`, so they stay on the machine
    /// across a restart. Absent (0) in a file no redefine touched.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub shift: f64,
    /// Raw and axis position when the reference was found.
    pub raw: f64,
    pub position: f64,
    /// When it was found (RFC 3339).
    pub homed_at: String,
    pub identity: AxisIdentity,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub invalidated: Option<Invalidation>,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// What [`References::load`] found.
#[derive(Clone, Debug, PartialEq)]
pub enum Loaded {
    /// No stored reference.
    None,
    /// A reference that may be restored (identity not yet compared).
    Valid(StoredReference),
    /// A reference invalidated earlier, with its reason.
    Invalidated(StoredReference),
    /// A file that failed a check (owner, size, symlink, syntax, format,
    /// axis name, non-finite numbers): never restored.
    Unreadable(String),
}

/// The reference files of one state directory.
#[derive(Clone, Debug)]
pub struct References {
    dir: StateDir,
}

impl References {
    pub fn new(dir: StateDir) -> Self {
        Self { dir }
    }

    /// `reference.AXIS.json` (axis names are `[A-Za-z0-9_.-]`, checked by
    /// the configuration; the fixed prefix keeps `.` and `..` harmless).
    pub fn path(&self, axis: &str) -> PathBuf {
        self.dir.file(&format!("reference.{axis}.json"))
    }

    pub fn load(&self, axis: &str) -> Loaded {
        let path = self.path(axis);
        let bytes = match atomic::read_own(&path, MAX_FILE) {
            Ok(None) => return Loaded::None,
            Ok(Some(b)) => b,
            Err(e) => return Loaded::Unreadable(format!("{}: {e}", path.display())),
        };
        let r: StoredReference = match serde_json::from_slice(&bytes) {
            Ok(r) => r,
            Err(e) => return Loaded::Unreadable(format!("{}: {e}", path.display())),
        };
        if r.format != FORMAT {
            return Loaded::Unreadable(format!(
                "{}: format {} (this version reads {FORMAT})",
                path.display(),
                r.format
            ));
        }
        if r.axis != axis {
            return Loaded::Unreadable(format!(
                "{}: stored for axis {:?}, not {axis}",
                path.display(),
                r.axis
            ));
        }
        let numbers = [r.offset, r.shift, r.raw, r.position];
        if !numbers.iter().all(|x| x.is_finite()) {
            return Loaded::Unreadable(format!("{}: a position is not finite", path.display()));
        }
        if r.invalidated.is_some() {
            Loaded::Invalidated(r)
        } else {
            Loaded::Valid(r)
        }
    }

    /// Stores `r` atomically (replacing what was there).
    pub fn save(&self, r: &StoredReference) -> std::io::Result<()> {
        let mut text = serde_json::to_vec_pretty(r).map_err(std::io::Error::other)?;
        text.push(b'\n');
        atomic::write(&self.path(&r.axis), &text)
    }

    /// Marks `r` invalid with `reason` and stores it.
    pub fn invalidate(&self, mut r: StoredReference, reason: &str) -> std::io::Result<()> {
        r.invalidated = Some(Invalidation {
            reason: reason.into(),
            at: crate::now_stamp().0,
        });
        self.save(&r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn store() -> (tempfile::TempDir, References) {
        let t = tempfile::tempdir().unwrap();
        let d = StateDir::open(&t.path().join("state")).unwrap();
        (t, References::new(d))
    }

    fn reference(axis: &str, offset: f64) -> StoredReference {
        StoredReference {
            format: FORMAT,
            axis: axis.into(),
            offset,
            shift: 0.0,
            raw: 113.4,
            position: 0.0,
            homed_at: "2026-11-30T12:00:00.000Z".into(),
            identity: AxisIdentity::default()
                .with("io", "io")
                .with("home_position", 0.0),
            invalidated: None,
        }
    }

    #[test]
    fn saved_references_load_back() {
        let (_t, s) = store();
        assert_eq!(s.load("Z"), Loaded::None);
        let r = reference("Z", -113.4);
        s.save(&r).unwrap();
        assert_eq!(s.load("Z"), Loaded::Valid(r.clone()));
        s.invalidate(r, "operator unhome").unwrap();
        match s.load("Z") {
            Loaded::Invalidated(r) => {
                assert_eq!(r.invalidated.unwrap().reason, "operator unhome");
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn identity_differences_name_the_keys() {
        let a = AxisIdentity::default()
            .with("home_position", 0.0)
            .with("io", "io");
        let b = AxisIdentity::default()
            .with("home_position", 5.0)
            .with("io", "io")
            .with("slot", 2);
        assert_eq!(
            a.differences(&b),
            vec![
                "home_position 0 → 5".to_string(),
                "slot (none) → 2".to_string()
            ]
        );
        assert!(a.differences(&a).is_empty());
    }

    #[test]
    fn hostile_files_are_unreadable_not_restored() {
        let (_t, s) = store();
        let p = s.path("Z");
        for (text, why) in [
            ("{\"format\":1", "EOF"),
            ("[]", "invalid length"),
            (
                r#"{"format":2,"axis":"Z","offset":1,"raw":0,"position":1,"homed_at":"","identity":{}}"#,
                "format 2",
            ),
            (
                r#"{"format":1,"axis":"X","offset":1,"raw":0,"position":1,"homed_at":"","identity":{}}"#,
                "not Z",
            ),
            (
                r#"{"format":1,"axis":"Z","offset":1,"raw":0,"position":1,"homed_at":"","identity":{},"extra":1}"#,
                "unknown field",
            ),
            (
                r#"{"format":1,"axis":"Z","offset":1e999,"raw":0,"position":1,"homed_at":"","identity":{}}"#,
                "",
            ),
        ] {
            std::fs::write(&p, text).unwrap();
            match s.load("Z") {
                Loaded::Unreadable(e) => assert!(e.contains(why), "{text}: {e}"),
                other => panic!("{text}: {other:?}"),
            }
        }
        std::fs::write(&p, vec![b' '; 20_000]).unwrap();
        assert!(matches!(s.load("Z"), Loaded::Unreadable(_)));
    }
}
