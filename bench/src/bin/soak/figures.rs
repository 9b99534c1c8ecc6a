//! What a part of the soak counts: the homings' results (a [`Tally`]) and
//! the figures of the supervisors that ran them (cycles, misses, feedback
//! gaps, warnings), so that the failures can be read next to what the
//! cycle and the I/O link did meanwhile.

use motion_bench::drive::{HomeRun, Tally};
use motion_report::GapCounts;
use serde_json::{json, Value};

/// Latency and I/O figures of the supervisors of one part, summed.
#[derive(Default)]
pub struct RunFigures {
    pub runs: u64,
    pub cycles: u64,
    pub deadline_misses: u64,
    pub late_replies: u64,
    pub frames_missing: u64,
    pub gaps: GapCounts,
    pub wakeup_max_us: f64,
    pub warnings: Vec<String>,
}

impl RunFigures {
    /// Adds a `run --json` / `home --json` object's latency and I/O figures.
    pub fn add(&mut self, v: &Value) {
        self.runs += 1;
        let lat = &v["latency"];
        self.cycles += lat["cycles"].as_u64().unwrap_or(0);
        self.deadline_misses += lat["deadline_misses"].as_u64().unwrap_or(0);
        self.late_replies += lat["late_replies"].as_u64().unwrap_or(0);
        self.wakeup_max_us = self
            .wakeup_max_us
            .max(lat["wakeup_us"]["max"].as_f64().unwrap_or(0.0));
        for io in v["io"].as_array().into_iter().flatten() {
            self.frames_missing += io["frames_missing"].as_u64().unwrap_or(0);
            if let Ok(g) = serde_json::from_value::<GapCounts>(io["gaps"].clone()) {
                self.gaps.merge(&g);
            }
        }
    }

    pub fn json(&self) -> Value {
        json!({
            "supervisor_runs": self.runs,
            "cycles": self.cycles,
            "deadline_misses": self.deadline_misses,
            "late_replies": self.late_replies,
            "frames_missing": self.frames_missing,
            "gaps": self.gaps,
            "wakeup_max_us": self.wakeup_max_us,
            "warnings": self.warnings,
        })
    }
}

/// One part (unloaded one-axis, stressed one-axis, 64-axis).
#[derive(Default)]
pub struct Part {
    pub tally: Tally,
    pub figures: RunFigures,
    pub seconds: f64,
}

impl Part {
    pub fn json(&self) -> Value {
        json!({
            "seconds": (self.seconds * 10.0).round() / 10.0,
            "tally": self.tally,
            "supervisors": self.figures.json(),
        })
    }
}

/// Counts one `home --json` run (rows, latency, gaps) into `p`.
pub fn count_home_run(p: &mut Part, what: &str, run: &HomeRun) {
    p.tally.add(what, run);
    if let Some(j) = &run.json {
        if j.get("latency").is_some() {
            p.figures.add(j);
        }
        if let Some(w) = j["warnings"].as_array() {
            for w in w.iter().filter_map(|w| w.as_str()) {
                if !p.figures.warnings.iter().any(|x| x == w) {
                    p.figures.warnings.push(w.to_string());
                }
            }
        }
    }
}
