//! The status of `motion-supervisor`, declared once.
//!
//! * [`axis`] — **the status table**: every field of an axis's status in one
//!   row (name, type, place in the wire entry, unit, JSON key, mark in
//!   `motionctl status`, OPC UA browse name, doc, and its getter from the
//!   cycle's snapshot). The wire entry's accessors, the filler, the typed
//!   JSON row ([`AxisStatus`]) and the row list ([`axis::ROWS`]) the other
//!   layers read are generated from it by [`status_table!`].
//! * [`schema`] — what a row says, the entry's areas and their room, the
//!   layout rule (adding a row moves nothing; moving or removing one bumps
//!   the layout).
//! * [`entry`] — the axis's wire entry ([`AxisStatusEntry`]); [`snap`] —
//!   what the getters read ([`AxisSnap`], [`AxisNote`], [`Source`]).
//! * [`io`] — an I/O process's counters, declared once for the cycle, the
//!   frame and the reports; [`stream`] — the setpoint stream's counters,
//!   likewise.
//! * [`docs`] — the docs page of the fields (`docs/status.md`).
//! * [`text`] — NUL-padded text fields.
//!
//! `motion-control` builds its status frame from these entries (and turns on
//! the `zero-copy` feature), `motion-report` re-exports the JSON types,
//! `motion-supervisor` fills entries from its snapshots, `motion-opcua`
//! publishes the rows, and the Python package builds its classes from the
//! layout description written from them.

#[macro_use]
pub mod schema;
pub mod axis;
pub mod docs;
pub mod entry;
pub mod io;
pub mod snap;
pub mod stream;
pub mod text;

pub use axis::{AxisStatus, NO_AXIS};
pub use entry::AxisStatusEntry;
pub use io::{GapCounts, IoCounters, IoReport, IoSnap, IoStatus, IoStatusEntry, START_ERROR_LEN};
pub use schema::{Row, Type, Unit};
pub use snap::{AxisNote, AxisSnap, LostCause, Source};
pub use stream::StreamCounts;
pub use text::{get_str, put_str, NAME_LEN, PHASE_LEN};

#[cfg(test)]
mod tests;
