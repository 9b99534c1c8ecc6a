//! The cells and rows of the benches' printed tables: a name in a column of
//! its own width, then right-aligned cells of 9 characters.

use crate::hist::Pct;

/// Column names of [`Pct::values`].
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

/// 12345678 → "12,345,678".
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

/// `name` left-aligned in `width`, then each cell right-aligned in 9.
pub fn row<S: std::fmt::Display>(
    name: &str,
    width: usize,
    cells: impl IntoIterator<Item = S>,
) -> String {
    let mut s = format!("{name:<width$}");
    for c in cells {
        s += &format!("{c:>9}");
    }
    s
}

/// The cells of `p` at the columns `cols` (indices into [`Pct::values`]).
pub fn us_cells(p: &Pct, cols: &[usize]) -> Vec<String> {
    let v = p.values();
    cols.iter().map(|&i| us(v[i])).collect()
}

/// The ratios `a / b` at the columns `cols`.
pub fn ratio_cells(a: &Pct, b: &Pct, cols: &[usize]) -> Vec<String> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells() {
        assert_eq!(
            (thousands(1234567).as_str(), thousands(12).as_str()),
            ("1,234,567", "12")
        );
        assert_eq!(
            (us(999.94).as_str(), us(1234.4).as_str()),
            ("999.9", "1234")
        );
        assert_eq!(
            (ratio(Some(0.5)).as_str(), ratio(None).as_str()),
            ("0.50", "-")
        );
        assert_eq!(ratio_of(Some(1.0), Some(4.0)), Some(0.25));
        assert_eq!(ratio_of(Some(1.0), Some(0.0)), None);
        assert_eq!(row("ab", 4, ["1", "x"]), "ab          1        x");
    }
}
