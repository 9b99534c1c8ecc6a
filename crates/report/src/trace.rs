//! The trace CSV (`motionctl trace --out FILE.csv`): one [`TraceRow`] per
//! cycle of a recorded homing. The daemon writes it ([`csv`]) and
//! `motionctl` reads it back to plot and summarize it ([`parse_csv`]): the
//! columns are defined here once, for both.
//!
//! Written by hand rather than with a CSV crate: fourteen plain columns that
//! never need quoting (phase names have no commas), numbers with six
//! decimals and empty where there is no value, flags as `0`/`1`.

use motion_homing::Phase;
use std::fmt::Write;

/// The header line: the columns in order.
pub const HEADER: &str = "t_s,phase,cmd_position,cmd_velocity,position,velocity,torque,switch,marker,fresh,event,event_raw,err,exerr\n";

/// Columns in a row (the header's).
const COLUMNS: usize = 14;

/// One cycle of a traced homing.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraceRow {
    /// Time since the homing started, s.
    pub t_s: f64,
    /// The homing phase (`None`: a number or name this version does not
    /// know, written `?`).
    pub phase: Option<Phase>,
    /// Command position (raw) and velocity, units and units/s.
    pub cmd_position: Option<f64>,
    pub cmd_velocity: Option<f64>,
    /// Actual position (raw), velocity and torque (% rated): `None` without
    /// feedback in this cycle.
    pub position: Option<f64>,
    pub velocity: Option<f64>,
    pub torque: Option<f64>,
    /// The sequence's reference switch actuated (logical: the home switch,
    /// or the limit switch a limit-switch sequence homes on), a marker
    /// passed or latched, fresh feedback this cycle.
    pub switch: bool,
    pub marker: bool,
    pub fresh: bool,
    /// The home event was found in this cycle, at `event_raw` (raw units).
    pub event: bool,
    pub event_raw: Option<f64>,
    pub err: u16,
    pub exerr: u16,
}

fn num(out: &mut String, x: Option<f64>) {
    if let Some(x) = x.filter(|x| x.is_finite()) {
        let _ = write!(out, "{x:.6}");
    }
}

fn flag(b: bool) -> u8 {
    u8::from(b)
}

impl TraceRow {
    /// The phase's spelling (`?` when unknown).
    pub fn phase_name(&self) -> &'static str {
        self.phase.map_or("?", Phase::name)
    }

    /// Appends the row as one CSV line (newline included). The event's
    /// position is written only in the row of the event.
    pub fn write_line(&self, out: &mut String) {
        let _ = write!(out, "{:.6},{},", self.t_s, self.phase_name());
        for x in [
            self.cmd_position,
            self.cmd_velocity,
            self.position,
            self.velocity,
            self.torque,
        ] {
            num(out, x);
            out.push(',');
        }
        let _ = write!(
            out,
            "{},{},{},{},",
            flag(self.switch),
            flag(self.marker),
            flag(self.fresh),
            flag(self.event)
        );
        num(out, self.event_raw.filter(|_| self.event));
        let _ = writeln!(out, ",{},{}", self.err, self.exerr);
    }

    /// One CSV line; `None` when it has fewer than the header's columns.
    /// A field that does not parse reads as absent (0 for the codes).
    pub fn parse_line(line: &str) -> Option<Self> {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() < COLUMNS {
            return None;
        }
        let num = |s: &str| s.parse::<f64>().ok().filter(|x| x.is_finite());
        let event = f[10] == "1";
        Some(Self {
            t_s: num(f[0]).unwrap_or(0.0),
            phase: f[1].parse().ok(),
            cmd_position: num(f[2]),
            cmd_velocity: num(f[3]),
            position: num(f[4]),
            velocity: num(f[5]),
            torque: num(f[6]),
            switch: f[7] == "1",
            marker: f[8] == "1",
            fresh: f[9] == "1",
            event,
            event_raw: if event { num(f[11]) } else { None },
            err: f[12].trim().parse().unwrap_or(0),
            exerr: f[13].trim().parse().unwrap_or(0),
        })
    }
}

/// The rows as CSV text, header first.
pub fn csv(rows: impl ExactSizeIterator<Item = TraceRow>) -> String {
    let mut s = String::with_capacity(HEADER.len() + rows.len() * 96);
    s += HEADER;
    for r in rows {
        r.write_line(&mut s);
    }
    s
}

/// Parses CSV text (header first); lines with too few columns are skipped.
pub fn parse_csv(text: &str) -> Vec<TraceRow> {
    text.lines()
        .skip(1)
        .filter_map(TraceRow::parse_line)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(k: u32) -> TraceRow {
        TraceRow {
            t_s: f64::from(k) * 0.001,
            phase: Some(if k < 2 { Phase::Seek } else { Phase::Return }),
            cmd_position: Some(f64::from(k) * 0.25),
            cmd_velocity: Some(-1.5),
            position: (k != 1).then_some(0.125),
            velocity: (k != 1).then_some(2.0),
            torque: (k != 1).then_some(-3.0),
            switch: k == 2,
            marker: false,
            fresh: k != 1,
            event: k == 3,
            event_raw: (k == 3).then_some(1.5),
            err: 0,
            exerr: 0,
        }
    }

    #[test]
    fn written_as_the_columns_say() {
        let text = csv((0..4).map(row));
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], HEADER.trim_end());
        assert_eq!(
            lines[1],
            "0.000000,seek,0.000000,-1.500000,0.125000,2.000000,-3.000000,0,0,1,0,,0,0"
        );
        assert_eq!(lines[2], "0.001000,seek,0.250000,-1.500000,,,,0,0,0,0,,0,0");
        assert_eq!(
            lines[4],
            "0.003000,return,0.750000,-1.500000,0.125000,2.000000,-3.000000,0,0,1,1,1.500000,0,0"
        );
        let unknown = TraceRow {
            phase: None,
            err: 12,
            exerr: 40,
            event_raw: Some(9.0),
            ..TraceRow::default()
        };
        let mut line = String::new();
        unknown.write_line(&mut line);
        assert_eq!(line, "0.000000,?,,,,,,0,0,0,0,,12,40\n");
    }

    #[test]
    fn read_back_as_written() {
        let rows: Vec<TraceRow> = (0..4).map(row).collect();
        assert_eq!(parse_csv(&csv(rows.iter().copied())), rows);
        assert!(TraceRow::parse_line("1,seek,2").is_none());
        let r = TraceRow::parse_line("x,nonsense,,,,,,1,1,1,0,7,y,3").unwrap();
        assert_eq!((r.t_s, r.phase, r.event_raw), (0.0, None, None));
        assert_eq!((r.switch, r.err, r.exerr), (true, 0, 3));
    }
}
