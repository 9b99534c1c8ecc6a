//! The cells and lines of the benches' printed tables: a line is cells in
//! columns of fixed widths; most tables are a name, then right-aligned
//! cells of 9 characters.

pub use motion_report::table::thousands;
use motion_report::Percentiles;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells() {
        assert_eq!([us(999.94), us(1234.4)], ["999.9", "1234"]);
        assert_eq!([ratio(Some(0.5)), ratio(None)], ["0.50", "-"]);
        assert_eq!(ratio_of(Some(1.0), Some(4.0)), Some(0.25));
        assert_eq!(ratio_of(Some(1.0), Some(0.0)), None);
        assert_eq!(row("ab", 4, ["1", "x"]), "ab          1        x");
        assert_eq!(line(&[-4, 3, 2], ["ab", "1", "x", "cut"]), "ab    1 x");
    }
}
