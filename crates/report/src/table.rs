//! Fixed-width text tables of the reports: the rows of `home` and `status`,
//! and the cells and lines the benches build their percentile tables from
//! (a line is cells in columns of fixed widths; most are a name, then
//! right-aligned cells of 9 characters).

use crate::{AxisResult, Percentiles};
use std::fmt::Display;

/// Column names of [`Percentiles::values`].
pub const COLUMNS: [&str; 6] = ["min", "p50", "p99", "p99.9", "p99.99", "max"];

/// A µs figure for a table cell: one decimal below 1000, none above.
pub fn us(x: f64) -> String {
    if x >= 1000.0 {
        format!("{x:.0}")
    } else {
        format!("{x:.1}")
    }
}

/// A ratio for a table cell (`-` where there is none).
pub fn ratio(x: Option<f64>) -> String {
    x.map_or("-".into(), |r| format!("{r:.2}"))
}

/// `a / b` when both are there and `b` > 0.
pub fn ratio_of(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    a.zip(b).filter(|(_, b)| *b > 0.0).map(|(a, b)| a / b)
}

/// `cells` in columns of `widths` characters, right-aligned (a negative
/// width: left-aligned in its absolute value).
pub fn line<S: Display>(widths: &[i32], cells: impl IntoIterator<Item = S>) -> String {
    let cell = |(c, &w): (S, &i32)| match w < 0 {
        true => format!("{c:<0$}", w.unsigned_abs() as usize),
        false => format!("{c:>0$}", w as usize),
    };
    cells.into_iter().zip(widths).map(cell).collect()
}

/// `name` left-aligned in `width`, then each cell right-aligned in 9.
pub fn row<S: Display>(name: &str, width: usize, cells: impl IntoIterator<Item = S>) -> String {
    let mut s = format!("{name:<width$}");
    for c in cells {
        s += &format!("{c:>9}");
    }
    s
}

/// The cells of `p` at the columns `cols` (indices into
/// [`Percentiles::values`]).
pub fn us_cells(p: &Percentiles, cols: &[usize]) -> Vec<String> {
    let v = p.values();
    cols.iter().map(|&i| us(v[i])).collect()
}

/// The ratios `a / b` at the columns `cols`.
pub fn ratio_cells(a: &Percentiles, b: &Percentiles, cols: &[usize]) -> Vec<String> {
    let r = a.ratio(b);
    cols.iter().map(|&i| ratio(r[i])).collect()
}

/// A report's text, one line at a time.
#[derive(Default)]
pub struct Text(pub String);

impl Text {
    pub fn line(&mut self, s: impl AsRef<str>) {
        self.0.push_str(s.as_ref());
        self.0.push('\n');
    }
}

/// 12345678 → "12,345,678": sample counts in the benches' tables and plots.
pub fn thousands(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

fn opt(x: Option<f64>, width: usize) -> String {
    match x {
        Some(v) => format!("{v:>width$.4}"),
        None => format!("{:>width$}", "-"),
    }
}

/// The width of the first column: the longest axis name (at least the
/// header's "axis"), and two spaces.
fn name_width<'a>(names: impl Iterator<Item = &'a str>) -> usize {
    names.map(|n| n.chars().count()).max().unwrap_or(4).max(4) + 2
}

/// One row per axis, as `home` prints it; errors and warnings on a line below.
pub fn axis_results(rows: &[AxisResult]) -> String {
    let w = name_width(rows.iter().map(|r| r.name.as_str()));
    let mut s = format!(
        "{:<w$}{:<8}{:<20}{:<24}{:>4}{:>4}{:>10}{:>7}{:>12}{:>12}{:>12}{:>9}\n",
        "axis",
        "mode",
        "sequence",
        "direction",
        "PC",
        "ER",
        "ERR/EXERR",
        "homed",
        "event raw",
        "final pos",
        "final raw",
        "time s"
    );
    for r in rows {
        let b = |x: bool| if x { "1" } else { "0" };
        s += &format!(
            "{:<w$}{:<8}{:<20}{:<24}{:>4}{:>4}{:>10}{:>7}{}{}{}{}\n",
            r.name,
            r.mode,
            r.sequence,
            r.direction,
            b(r.pc),
            b(r.er),
            format!("{}/{}", r.err, r.exerr),
            if r.homed { "yes" } else { "no" },
            opt(r.event_raw, 12),
            opt(r.final_position, 12),
            opt(r.final_raw, 12),
            opt(r.duration_s, 9),
        );
        if let Some(e) = &r.error {
            s += &format!("  └ {e}\n");
        }
        if let Some(k) = r.skew {
            s += &format!(
                "  └ gantry side: skew {k:.4} (how far apart the sides latched their events)\n"
            );
        }
        for wrn in &r.warnings {
            s += &format!("  └ warning: {wrn}\n");
        }
    }
    s
}

/// `status` as text: one line per axis, one per I/O process. The flags
/// column is the status table's marks (`motion_status::axis`: each marked
/// flag's mark when set, dots when not; the legend is `docs/status.md`).
pub fn status(r: &crate::StatusReport) -> String {
    let w = name_width(r.axes.iter().map(|a| a.name.as_str()));
    let every = crate::AxisStatus::marks_header();
    let fw = every.chars().count() + 2;
    let mut s = format!(
        "{:<w$}{:<8}{:<13}{:<fw$}{:>7}{:>10}{:>12}{:>12}{:>10}{:>8}{:>18} {:>19}\n",
        "axis",
        "io",
        "phase",
        every,
        "homed",
        "ERR/EXERR",
        "position",
        "raw",
        "velocity",
        "torque",
        "elapsed/timeout s",
        "travel/limit"
    );
    for a in &r.axes {
        let f = |x: Option<f64>, p: usize, width: usize| {
            x.map_or(format!("{:>width$}", "-"), |v| format!("{v:>width$.p$}"))
        };
        s += &format!(
            "{:<w$}{:<8}{:<13}{:<fw$}{:>7}{:>10}{}{}{}{}{:>18} {:>19}\n",
            a.name,
            a.io,
            a.phase,
            a.marks(),
            match (a.homed, a.restored) {
                (true, true) => "stored",
                (true, false) => "yes",
                _ => "no",
            },
            format!("{}/{}", a.err, a.exerr),
            f(a.position, 4, 12),
            f(a.raw, 4, 12),
            f(a.velocity, 3, 10),
            f(a.torque, 1, 8),
            format!(
                "{:.2}/{}",
                a.elapsed_s,
                if a.timeout_s > 0.0 {
                    format!("{}", a.timeout_s)
                } else {
                    "-".into()
                }
            ),
            format!(
                "{:.3}/{}",
                a.search_travel,
                a.search_limit
                    .map_or("-".to_string(), |l| format!("{l:.3}"))
            ),
        );
        if let Some(e) = &a.error {
            s += &format!("  └ {e}\n");
        }
        for wrn in &a.warnings {
            s += &format!("  └ warning: {wrn}\n");
        }
        if let Some(o) = &a.owner {
            s += &format!("  └ owned by {o} (setpoint stream)\n");
        }
        if a.op_err != 0 {
            s += &format!(
                "  └ last operation refused: ERR {} EXERR {}: {}\n",
                a.op_err,
                a.op_exerr,
                crate::codes::explain(a.op_err, a.op_exerr)
            );
        }
    }
    for io in &r.io {
        let c = &io.counters;
        s += &format!(
            "I/O {}: {}; frames {} received, {} missing, {} refused; attached {} time(s); gaps 1: {}, 2-3: {}, 4-10: {}, >10: {}, longest {} cycles{}\n",
            io.name,
            if io.attached { "attached" } else { "NOT attached" },
            c.frames_received,
            c.frames_missing,
            c.frames_refused,
            c.attachments,
            c.gaps.one,
            c.gaps.two_to_three,
            c.gaps.four_to_ten,
            c.gaps.over_ten,
            c.gaps.longest_cycles,
            if c.gap_cycles > 0 {
                format!(", now {} cycles without an answer", c.gap_cycles)
            } else {
                String::new()
            }
        );
    }
    s
}

/// One row per axis, as `move`, `jog` and `stream` print how they ended.
pub fn motion_rows(rows: &[crate::MotionRow]) -> String {
    let w = name_width(rows.iter().map(|r| r.name.as_str()));
    let mut s = format!(
        "{:<w$}{:>4}{:>4}{:>10}{:>12}{:>14}{:>12}\n",
        "axis", "PC", "ER", "ERR/EXERR", "position", "follow err max", "final err"
    );
    for r in rows {
        let b = |x: bool| if x { "1" } else { "0" };
        s += &format!(
            "{:<w$}{:>4}{:>4}{:>10}{}{}{}\n",
            r.name,
            b(r.pc),
            b(r.er),
            format!("{}/{}", r.err, r.exerr),
            opt(r.position, 12),
            opt(r.following_error_max, 14),
            opt(r.final_error, 12),
        );
        if let Some(e) = &r.error {
            s += &format!("  └ {e}\n");
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_and_lines() {
        let t = |n| thousands(n);
        assert_eq!(
            [t(1234567), t(12), t(999), t(1000)],
            ["1,234,567", "12", "999", "1,000"]
        );
        assert_eq!([us(999.94), us(1234.4)], ["999.9", "1234"]);
        assert_eq!([ratio(Some(0.5)), ratio(None)], ["0.50", "-"]);
        assert_eq!(ratio_of(Some(1.0), Some(4.0)), Some(0.25));
        assert_eq!(ratio_of(Some(1.0), Some(0.0)), None);
        assert_eq!(row("ab", 4, ["1", "x"]), "ab          1        x");
        assert_eq!(line(&[-4, 3, 2], ["ab", "1", "x", "cut"]), "ab    1 x");
        let a = Percentiles {
            p50: 3.0,
            max: 1500.0,
            ..Default::default()
        };
        let b = Percentiles {
            p50: 2.0,
            ..Default::default()
        };
        assert_eq!(us_cells(&a, &[1, 5]), ["3.0", "1500"]);
        assert_eq!(ratio_cells(&a, &b, &[0, 1]), ["-", "1.50"]);
        let mut text = Text::default();
        text.line("a");
        text.line(String::from("b"));
        assert_eq!(text.0, "a\nb\n");
    }
}
