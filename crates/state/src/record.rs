//! The homing record: every homing's outcome (and every restore or
//! invalidation of a stored reference) as one JSON line appended to
//! `state_dir/homing-record.jsonl`.
//!
//! JSON lines because the record is read by people (`tail`, `jq`) and by
//! programs (maintenance dashboards) alike, and appending a line is one
//! `write(2)` on an `O_APPEND` file: a crash loses at most the line being
//! written, never an earlier one, and a torn last line is skipped by readers.
//! The file is rotated once it passes [`ROTATE_AT`] (one older generation
//! kept: `homing-record.jsonl.1`).

use crate::atomic::libc_o_nofollow;
use crate::dir::StateDir;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::os::unix::fs::OpenOptionsExt;
use std::path::PathBuf;

pub const FILE: &str = "homing-record.jsonl";
/// Size at which the record is rotated (about 40 000 homings).
pub const ROTATE_AT: u64 = 16 * 1024 * 1024;
/// How much of the record's end is read back at start-up for the recent
/// events of every axis.
const TAIL: u64 = 1024 * 1024;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RecordKind {
    /// The Home instruction ran and ended (either way).
    Homing,
    /// A stored reference was applied without motion.
    Restored,
    /// A stored reference was invalidated (or found unreadable).
    Invalidated,
    /// Redefine position shifted the axis's positions without motion
    /// (`shift`: the shift in force since the reference was established;
    /// `offset`: the raw → axis offset after it; `position`: the command
    /// position after it).
    Redefined,
}

/// One line of the record. Positions are in the axis's units; `event_raw`
/// is the encoder (raw) position of the home event, `event` the same event
/// in the reference the axis had before this homing (absent when it had
/// none), `offset` the raw → axis offset the homing established.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RecordEntry {
    pub time: String,
    pub unix_ms: u64,
    pub kind: Option<RecordKind>,
    pub axis: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gantry: Option<String>,
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub mode: String,
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub sequence: String,
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub direction: String,
    /// `homed`, `failed`, `restored`, `invalidated`.
    pub result: String,
    #[serde(default)]
    pub pc: bool,
    #[serde(default)]
    pub homed: bool,
    #[serde(default)]
    pub err: u16,
    #[serde(default)]
    pub exerr: u16,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub event_raw: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub event: Option<f64>,
    /// Switch-then-marker: distance from the switch edge to the marker.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub switch_to_marker: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration_s: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skew: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Redefined: the shift in force since the reference was established
    /// (the sum of the redefines since homing), units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shift: Option<f64>,
    /// Redefined: the axis's command position after it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<f64>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

impl RecordEntry {
    /// A successful homing (what the drift history learns from).
    pub fn succeeded(&self) -> bool {
        self.kind == Some(RecordKind::Homing) && self.pc && self.homed && self.err == 0
    }
}

/// The record file, open for appending.
pub struct HomingRecord {
    path: PathBuf,
    file: Option<File>,
}

impl HomingRecord {
    pub fn new(dir: &StateDir) -> Self {
        Self {
            path: dir.file(FILE),
            file: None,
        }
    }

    pub fn path(&self) -> &std::path::Path {
        &self.path
    }

    fn open(&self) -> std::io::Result<File> {
        OpenOptions::new()
            .append(true)
            .create(true)
            .mode(0o600)
            .custom_flags(libc_o_nofollow())
            .open(&self.path)
    }

    /// Appends `e` as one line and syncs it (homing ends are rare; the
    /// record is evidence, so it reaches the disk).
    pub fn append(&mut self, e: &RecordEntry) -> std::io::Result<()> {
        let mut line = serde_json::to_vec(e).map_err(std::io::Error::other)?;
        line.push(b'\n');
        if self.file.is_none() {
            self.file = Some(self.open()?);
        }
        let Some(f) = self.file.as_mut() else {
            unreachable!("opened above")
        };
        if f.metadata()?.len() >= ROTATE_AT {
            let old = self.path.with_extension("jsonl.1");
            std::fs::rename(&self.path, old)?;
            self.file = Some(self.open()?);
        }
        let Some(f) = self.file.as_mut() else {
            unreachable!("opened above")
        };
        f.write_all(&line)?;
        f.sync_data()
    }

    /// The last `n` successful homings per axis, oldest first, read from
    /// the end of the record. Lines that do not parse (a torn last line, a
    /// hand edit) are skipped.
    pub fn recent(&self, n: usize) -> HashMap<String, Vec<RecordEntry>> {
        let mut by_axis: HashMap<String, Vec<RecordEntry>> = HashMap::new();
        let Ok(mut f) = OpenOptions::new()
            .read(true)
            .custom_flags(libc_o_nofollow())
            .open(&self.path)
        else {
            return by_axis;
        };
        let len = f.metadata().map_or(0, |m| m.len());
        let from = len.saturating_sub(TAIL);
        if f.seek(SeekFrom::Start(from)).is_err() {
            return by_axis;
        }
        let mut text = Vec::new();
        if f.take(TAIL).read_to_end(&mut text).is_err() {
            return by_axis;
        }
        let mut lines = text.split(|&b| b == b'\n');
        if from > 0 {
            // Starts mid-line.
            lines.next();
        }
        for line in lines {
            if let Ok(e) = serde_json::from_slice::<RecordEntry>(line) {
                if e.succeeded() {
                    let v = by_axis.entry(e.axis.clone()).or_default();
                    v.push(e);
                    if v.len() > n {
                        v.remove(0);
                    }
                }
            }
        }
        by_axis
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn homing(axis: &str, event: f64, ok: bool) -> RecordEntry {
        RecordEntry {
            time: "t".into(),
            kind: Some(RecordKind::Homing),
            axis: axis.into(),
            result: if ok { "homed" } else { "failed" }.into(),
            pc: ok,
            homed: ok,
            err: if ok { 0 } else { 12 },
            event: Some(event),
            ..Default::default()
        }
    }

    #[test]
    fn appends_lines_and_reads_recent_successes_back() {
        let t = tempfile::tempdir().unwrap();
        let d = StateDir::open(&t.path().join("s")).unwrap();
        let mut r = HomingRecord::new(&d);
        for k in 0..8 {
            r.append(&homing("X", f64::from(k), true)).unwrap();
        }
        r.append(&homing("X", 99.0, false)).unwrap();
        r.append(&homing("Y", 5.0, true)).unwrap();
        // A torn line, as a crash mid-append would leave it.
        std::fs::OpenOptions::new()
            .append(true)
            .open(r.path())
            .unwrap()
            .write_all(b"{\"time\":\"t\",\"ki")
            .unwrap();
        let recent = r.recent(5);
        let x: Vec<f64> = recent["X"].iter().map(|e| e.event.unwrap()).collect();
        assert_eq!(x, [3.0, 4.0, 5.0, 6.0, 7.0]);
        assert_eq!(recent["Y"].len(), 1);
        let text = std::fs::read_to_string(r.path()).unwrap();
        assert_eq!(text.lines().count(), 11);
    }
}
