//! The cycle's end of the setpoint stream: every frame programs published
//! since the last cycle goes through the core's intake, before the engines
//! step, so a setpoint published during the cycle's sleep is in the command
//! frame of the very next cycle.

use crate::core::Core;
use crate::shared::{Ask, Control};
use motion_ipc::SetpointSubscriber;

/// Drains the setpoint subscriber into the core's intake. Bounded: at most
/// the subscriber's buffer (16 frames); `receive` allocates nothing. A
/// receive failure is not a frame (the stream's silence is the engines'
/// to judge).
pub(super) fn receive(sp: &mut SetpointSubscriber, core: &mut Core) {
    core.setpoints_begin();
    let _ = sp.drain(|f| core.setpoints_take(f));
}

/// Before a request is applied: a stream being granted maps its program's
/// publisher now (the one cycle per acquire that makes those system calls),
/// not inside a later receive.
pub(super) fn before(sp: &mut SetpointSubscriber, c: &Control) {
    if matches!(c.ask, Ask::StreamAcquire { .. }) {
        let _ = sp.update_connections();
    }
}
