//! What the end-to-end tests check again and again, on the typed reports:
//! a row by name, a position within a tolerance, a homed axis, a whole
//! `home --json` run.

use std::fmt::Debug;

use motion_report::{AxisResult, AxisStatus, HomeReport, IoReport, IoStatus};

use crate::commands::supervisor;
use crate::leftovers::assert_clean;
use crate::machines::TempConfig;
use crate::process::Ended;

/// One count at 1000 counts per unit, plus rounding.
pub const COUNT: f64 = 0.001 + 1e-9;

/// A report row with a name (axis or I/O process).
pub trait Named {
    fn name(&self) -> &str;
}

macro_rules! named_rows {
    ($($t:ty),*) => {$(
        impl Named for $t {
            fn name(&self) -> &str {
                &self.name
            }
        }
    )*};
}
named_rows!(AxisResult, AxisStatus, IoReport, IoStatus);

/// The row called `name`; panics listing the rows there are.
#[track_caller]
pub fn named<'a, T: Named + Debug>(rows: &'a [T], name: &str) -> &'a T {
    rows.iter()
        .find(|r| r.name() == name)
        .unwrap_or_else(|| panic!("no {name} in {rows:#?}"))
}

/// Asserts `row.field` (an `f64` or `Option<f64>`) is within `tol` of
/// `want`, naming the row, the field and showing the row when it is not.
#[macro_export]
macro_rules! assert_close {
    ($row:expr, $field:ident, $want:expr, $tol:expr) => {{
        let row = &$row;
        let got: Option<f64> = row.$field.into();
        let (want, tol): (f64, f64) = ($want, $tol);
        assert!(
            got.is_some_and(|g| (g - want).abs() <= tol),
            "{} {} = {:?}, want {} ± {}\n{:#?}",
            row.name,
            stringify!($field),
            got,
            want,
            tol,
            row
        );
    }};
}

/// The value of an `Option<f64>` field; panics naming it.
#[track_caller]
pub fn value(v: Option<f64>, what: impl Debug) -> f64 {
    v.unwrap_or_else(|| panic!("no value: {what:#?}"))
}

/// The row of axis `name`, which homed: PC set, no error, HomedStatus, a
/// duration.
#[track_caller]
pub fn homed<'a>(report: &'a HomeReport, name: &str) -> &'a AxisResult {
    let a = named(&report.axes, name);
    assert!(a.pc && !a.er && a.homed, "{a:#?}");
    assert!(a.duration_s.is_some_and(|d| d >= 0.0), "{a:#?}");
    a
}

/// `motion-supervisor home --json --config CFG`: exit 0, the latency of
/// more than 500 cycles reported, nothing left in `/dev/shm`. Returns the
/// report and the run (its stderr carries motion-io's start-up report).
#[track_caller]
pub fn home_all(cfg: &TempConfig) -> (HomeReport, Ended) {
    let run = supervisor(&["home", "--json", "--config", cfg.arg()]);
    let v: HomeReport = run.expect_code(0).report();
    assert!(v.run.latency.cycles > 500, "{:#?}", v.run.latency);
    assert_clean(&cfg.prefix);
    (v, run)
}

/// At rest: no operation's motion (jog, move, stream, gear), not stopping,
/// no operation in process.
pub fn at_rest(a: &motion_report::AxisStatus) -> bool {
    !a.jogging && !a.moving && !a.streaming && !a.gearing && !a.stopping && !a.op_ip
}
