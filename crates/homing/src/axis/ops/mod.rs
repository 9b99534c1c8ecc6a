//! The operations around homing: enable, disable, reset, jog, move, stop
//! and the supervised stream (see [`operation`](crate::operation)).
//!
//! Not built yet: every operation is refused with a placeholder code
//! (ERR 1021, not in the code table), so nothing moves.

use super::Axis;
use crate::operation::Operation;

/// The answer to every operation until they are built.
const PLACEHOLDER: (u16, u16) = (1021, 0);

impl Axis {
    /// Applies `op` (this step's `Request::op`), answering in `Status::op`.
    pub(super) fn operation(&mut self, _now: u64, _op: Operation) {
        self.status.op.refused = Some(PLACEHOLDER);
    }
}
