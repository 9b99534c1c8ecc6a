//! ERR / EXERR in plain words: the short texts of the code table
//! (`motion_homing::code_table::TABLE`).

use motion_homing::code_table;
use motion_homing::codes::{ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST};

/// One line per ERR/EXERR.
pub fn explain(err: u16, exerr: u16) -> &'static str {
    match (err, code_table::lookup(err, exerr)) {
        (0, _) => "no error",
        (_, Some(c)) => c.short,
        (_, None) => "error",
    }
}

/// [`explain`], and for a loss of feedback how long it had been missing
/// when the rule tripped (`gap_s`, seconds; 0 or `None` = not known).
pub fn describe(err: u16, exerr: u16, gap_s: Option<f64>) -> String {
    let text = explain(err, exerr);
    match gap_s {
        Some(g) if (err, exerr) == (ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST) && g > 0.0 => {
            format!("{text}: no valid feedback for {:.1} ms", g * 1e3)
        }
        _ => text.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion_homing::codes::*;

    #[test]
    fn every_code_reads_as_its_row() {
        assert_eq!(explain(0, 0), "no error");
        assert_eq!(explain(ERR_SERVO_MESSAGE, EX_DRIVE_FAULT), "drive fault");
        assert_eq!(
            explain(ERR_ILLEGAL_HOMING_CONFIG, EX_HOME_SPEED_ZERO),
            "illegal homing configuration: home speed zero"
        );
        assert_eq!(
            explain(ERR_ILLEGAL_HOMING_CONFIG, 99),
            "illegal homing configuration"
        );
        assert_eq!(
            explain(ERR_SEARCH_LIMIT, EX_SEARCH_SEEK),
            "search travelled beyond the search limit"
        );
        assert_eq!(explain(ERR_SERVO_MESSAGE, 999), "error");
        assert_eq!(
            describe(ERR_SERVO_MESSAGE, EX_FEEDBACK_LOST, Some(0.0109)),
            "feedback lost (I/O process silent or gone): no valid feedback for 10.9 ms"
        );
    }
}
