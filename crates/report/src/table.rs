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

/// `status` as text: one line per axis, one per I/O process.
pub fn status(r: &crate::StatusReport) -> String {
    let w = r
        .axes
        .iter()
        .map(|a| a.name.chars().count())
        .max()
        .unwrap_or(4)
        .max(4)
        + 2;
    let b = |x: bool, c: &'static str| if x { c } else { "." };
    let mut s = format!(
        "{:<w$}{:<8}{:<13}{:<15}{:<9}{:>7}{:>10}{:>12}{:>12}{:>10}{:>8} {:<3}{:>17} {:>19}\n",
        "axis",
        "io",
        "phase",
        "EN DN ER IP PC",
        "SJMTxF-+",
        "homed",
        "ERR/EXERR",
        "position",
        "raw",
        "velocity",
        "torque",
        "in",
        "elapsed/timeout s",
        "travel/limit"
    );
    for a in &r.axes {
        let f = |x: Option<f64>, p: usize, width: usize| {
            x.map_or(format!("{:>width$}", "-"), |v| format!("{v:>width$.p$}"))
        };
        s += &format!(
            "{:<w$}{:<8}{:<13}{} {} {} {} {}  {:<9}{:>7}{:>10}{}{}{}{} {}{}{:>17} {:>19}\n",
            a.name,
            a.io,
            a.phase,
            b(a.en, "EN"),
            b(a.dn, "DN"),
            b(a.er, "ER"),
            b(a.ip, "IP"),
            b(a.pc, "PC"),
            motion_flags(a),
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
            if a.switch { "S" } else { "." },
            if a.marker { "M " } else { ". " },
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
        if a.op.err != 0 {
            s += &format!(
                "  └ last operation refused: ERR {} EXERR {}: {}\n",
                a.op.err,
                a.op.exerr,
                crate::codes::explain(a.op.err, a.op.exerr)
            );
        }
    }
    for io in &r.io {
        s += &format!(
            "I/O {}: {}; frames {} received, {} missing, {} refused; attached {} time(s); gaps 1: {}, 2-3: {}, 4-10: {}, >10: {}, longest {} cycles{}\n",
            io.name,
            if io.attached { "attached" } else { "NOT attached" },
            io.frames_received,
            io.frames_missing,
            io.frames_refused,
            io.attachments,
            io.gaps.one,
            io.gaps.two_to_three,
            io.gaps.four_to_ten,
            io.gaps.over_ten,
            io.gaps.longest_cycles,
            if io.gap_cycles > 0 {
                format!(", now {} cycles without an answer", io.gap_cycles)
            } else {
                String::new()
            }
        );
    }
    s
}

/// One row per axis, as `move`, `jog` and `stream` print how they ended.
pub fn motion_rows(rows: &[crate::MotionRow]) -> String {
    let w = rows
        .iter()
        .map(|r| r.name.chars().count())
        .max()
        .unwrap_or(4)
        .max(4)
        + 2;
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

/// The operation bits of an axis in eight characters (`.` = off):
/// ServoActionStatus `S`, jogging `J`, moving `M`, streaming `T`, stopping
/// `x`, faulted `F`, negative / positive limit switch `-` / `+`.
fn motion_flags(a: &crate::AxisStatus) -> String {
    [
        (a.servo_action, 'S'),
        (a.jogging, 'J'),
        (a.moving, 'M'),
        (a.streaming, 'T'),
        (a.stopping, 'x'),
        (a.faulted, 'F'),
        (a.limit_negative, '-'),
        (a.limit_positive, '+'),
    ]
    .iter()
    .map(|&(on, c)| if on { c } else { '.' })
    .collect()
}
