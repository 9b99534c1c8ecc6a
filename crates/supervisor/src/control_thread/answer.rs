//! The cycle's answers, in the domain's words ([`AxisAck`], [`Refusal`]),
//! as the control service states them ([`AxisOutcome`], [`Reason`]): the
//! one place the two vocabularies meet.

use crate::shared::{AxisAck, Refusal};
use motion_control::{AxisOutcome, Reason};

/// The wire's reason for a refusal; `None` for the refusals a client never
/// gets a reason of its own for (nothing started because of another axis;
/// a stored reference, which only the keeper asks for).
pub fn reason(r: Refusal) -> Option<Reason> {
    Some(match r {
        Refusal::AlreadyHoming => Reason::AlreadyHoming,
        Refusal::IoNotAttached => Reason::IoNotAttached,
        Refusal::Instruction { err, exerr } => Reason::Instruction { err, exerr },
        Refusal::Exiting => Reason::Exiting,
        Refusal::Busy => Reason::Busy,
        Refusal::Owned => Reason::Owned,
        Refusal::Token => Reason::Token,
        Refusal::Operation { err, exerr } => Reason::Operation { err, exerr },
        Refusal::NotStarted | Refusal::Restore(_) => return None,
    })
}

/// How one axis of a request came out, for the response.
pub fn outcome(a: AxisAck) -> AxisOutcome {
    match a {
        AxisAck::Accepted => AxisOutcome::Accepted,
        AxisAck::NotNamed => AxisOutcome::NotStarted,
        AxisAck::Refused(r) => reason(r).map_or(AxisOutcome::NotStarted, AxisOutcome::Refused),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion_control::*;

    #[test]
    fn every_refusal_keeps_its_number_on_the_wire() {
        let wire = |r| outcome(AxisAck::Refused(r)).answer("X");
        let a = wire(Refusal::Instruction { err: 41, exerr: 20 });
        assert_eq!(
            (a.accepted, a.reason, a.err, a.exerr),
            (0, REASON_INSTRUCTION, 41, 20)
        );
        for (r, code) in [
            (Refusal::AlreadyHoming, REASON_ALREADY_HOMING),
            (Refusal::IoNotAttached, REASON_IO_NOT_ATTACHED),
            (Refusal::Exiting, REASON_EXITING),
            (Refusal::Busy, REASON_BUSY),
            (Refusal::Token, REASON_TOKEN),
            (Refusal::NotStarted, REASON_NONE),
            (
                Refusal::Restore(motion_homing::RestoreRefusal::NoFeedback),
                REASON_NONE,
            ),
        ] {
            let a = wire(r);
            assert_eq!((a.accepted, a.reason, a.err), (0, code, 0), "{r:?}");
        }
        assert_eq!(outcome(AxisAck::Accepted).answer("X").accepted, 1);
        let a = wire(Refusal::Operation { err: 13, exerr: 4 });
        assert_eq!((a.reason, a.err, a.exerr), (REASON_OPERATION, 13, 4));
        let a = wire(Refusal::Owned);
        assert_eq!((a.reason, a.err, a.exerr), (REASON_OWNED, 3, 0));
    }
}
