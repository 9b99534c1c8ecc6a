//! `stream --csv FILE`: the file of timed setpoints, read and checked
//! before anything is acquired, and the points `stream` publishes.

use std::path::Path;

/// One row: time (s, from the file) and one position per axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub t: f64,
    pub p: Vec<f64>,
}

/// Longest time between two published points. An axis stops (ERR 1019 /
/// EXERR 5) when no setpoint has arrived for its `stream_timeout_ms`
/// (default 50, at least 1) — however far ahead the last one lay: a row
/// seconds away is not a promise that keeps the axis moving. So rows
/// further apart are filled in by linear interpolation (the very line the
/// supervisor would interpolate anyway) and a point goes out at least
/// every 5 ms: enough for any `stream_timeout_ms` of 10 or more, with room
/// for a descheduled moment of this process.
pub const FILL_S: f64 = 0.005;

/// Reads `path` (a regular file of at most 1 MiB): rows `t,p1[,p2...]`,
/// one position per axis, `t` increasing; blank lines and `#` comments are
/// skipped, and a first line that is not numbers (a header).
pub fn read(path: &Path, axes: usize) -> Result<Vec<Row>, String> {
    let text = motion_config::file::read_config_file(path)?;
    parse(&text, axes).map_err(|e| format!("{}: {e}", path.display()))
}

/// [`read`] on text.
pub fn parse(text: &str, axes: usize) -> Result<Vec<Row>, String> {
    let mut rows: Vec<Row> = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Result<Vec<f64>, _> =
            line.split(',').map(|f| f.trim().parse::<f64>()).collect();
        let Ok(v) = fields else {
            if rows.is_empty() && n == 0 {
                continue; // a header
            }
            return Err(format!("line {}: not numbers: {line:?}", n + 1));
        };
        if v.len() != axes + 1 {
            return Err(format!(
                "line {}: {} values, expected t and {axes} position(s)",
                n + 1,
                v.len()
            ));
        }
        if v.iter().any(|x| !x.is_finite() || x.abs() > 1e9) {
            return Err(format!(
                "line {}: a value is not finite or beyond 1e9",
                n + 1
            ));
        }
        if rows.last().is_some_and(|r| v[0] <= r.t) {
            return Err(format!("line {}: t = {} does not increase", n + 1, v[0]));
        }
        rows.push(Row {
            t: v[0],
            p: v[1..].to_vec(),
        });
    }
    if rows.is_empty() {
        return Err("no rows".into());
    }
    Ok(rows)
}

/// The points to publish, in order: every row, plus points on the line
/// between rows further apart than [`FILL_S`] — made as they are asked
/// for (a long file at 200 points a second is never held in memory).
pub fn points(rows: &[Row]) -> impl Iterator<Item = Row> + '_ {
    let filled = rows.windows(2).flat_map(|w| {
        let (a, b) = (&w[0], &w[1]);
        let n = ((b.t - a.t) / FILL_S).ceil().max(1.0) as usize;
        (0..n).map(move |k| {
            let f = k as f64 / n as f64;
            Row {
                t: a.t + f * (b.t - a.t),
                p: a.p.iter().zip(&b.p).map(|(x, y)| x + f * (y - x)).collect(),
            }
        })
    });
    filled.chain(rows.last().cloned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_are_checked_and_gaps_filled() {
        let r = parse("t,x\n0,0\n# c\n\n0.012,1\n1.0,1\n", 1).unwrap();
        assert_eq!(r.len(), 3);
        let p: Vec<Row> = points(&r).collect();
        // 0.012 s in 3 pieces, 0.988 s in 198, and the last row
        assert_eq!(p.len(), 3 + 198 + 1, "{p:?}");
        assert!((p[1].p[0] - 1.0 / 3.0).abs() < 1e-12);
        assert_eq!((p[3].t, p[3].p[0]), (0.012, 1.0), "every row itself");
        assert_eq!(p.last(), r.last());
        assert!(p.windows(2).all(|w| w[1].t - w[0].t <= FILL_S + 1e-12));
        for bad in [
            "0,0\n0,1\n",
            "0,0,1\n",
            "0,nan\n",
            "0,1\nx,2\n",
            "",
            "0,1e300\n",
        ] {
            assert!(parse(bad, 1).is_err(), "{bad:?}");
        }
    }
}
