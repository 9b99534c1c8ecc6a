//! Fixed-width text tables of the reports.

use crate::AxisResult;

fn opt(x: Option<f64>, width: usize) -> String {
    match x {
        Some(v) => format!("{v:>width$.4}"),
        None => format!("{:>width$}", "-"),
    }
}

/// One row per axis, as `home` prints it; errors and warnings on a line below.
pub fn axis_results(rows: &[AxisResult]) -> String {
    let w = rows
        .iter()
        .map(|r| r.name.chars().count())
        .max()
        .unwrap_or(4)
        .max(4)
        + 2;
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
        for wrn in &r.warnings {
            s += &format!("  └ warning: {wrn}\n");
        }
    }
    s
}
