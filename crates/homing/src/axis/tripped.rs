//! The cycle monitor (`motion-monitor`, apart from this engine) found a
//! command of this engine breaking one of its invariants and stops the
//! axis itself (ERR 1021): the engine learns it here, in the step it
//! happened, and stops commanding motion.

use super::state::State;
use super::{Abort, Axis};
use crate::operation::StopCause;

impl Axis {
    /// The monitor tripped on this step's command with `code` (ERR /
    /// EXERR) and commands the axis until a reset: homing in process fails
    /// with `code` (HomedStatus cleared, as for any homing failure); an
    /// operation's motion ends without PC (`StopCause::Monitor`); what waits
    /// for the axis to come to rest is answered as not done; the power stage
    /// is requested off and the command follows the actual position. The
    /// axis is faulted with `code` (ER, `Status::faulted`) until `Reset`:
    /// nothing enables or moves it by itself.
    pub fn monitor_tripped(&mut self, now_ns: u64, code: (u16, u16)) {
        if self.status.ip {
            self.fail(now_ns, code.0, code.1, Abort::Disable);
        }
        self.op_fault(now_ns, code, StopCause::Monitor, true);
        self.shutdown_ops(now_ns);
        self.overrides = false;
        self.state = State::Idle;
        self.set_fault(code);
        self.report(now_ns);
    }
}
