//! The drive's position latches (CiA 402 touch-probe style handshake).
//!
//! The engine arms a capture by sending a new non-zero id; the plant echoes
//! the id at once (arming happens at the start of the step, so an edge passed
//! in the very step the arm arrives is captured), captures the first
//! qualifying edge, and then holds that capture until a *different* id arms
//! again. Id 0 disarms. Because the id is echoed with the result, a capture
//! that belongs to an earlier arming can never be mistaken for a new one.

use motion_homing::{Edge, LatchArm, LatchFeedback};

/// One latch channel (marker or switch).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Latch {
    state: LatchFeedback,
    /// Edge taken when the current id armed. A changed edge with the same id
    /// is ignored, as a touch probe takes its configuration on arming.
    edge: Edge,
}

impl Latch {
    /// Start-of-step handling of the arm request.
    pub(crate) fn arm(&mut self, req: LatchArm) {
        if req.id == self.state.id {
            return;
        }
        self.state = LatchFeedback {
            id: req.id,
            latched: false,
            position: 0.0,
        };
        self.edge = req.edge;
    }

    /// Armed and still waiting for its edge.
    pub(crate) fn waiting(&self) -> bool {
        self.state.id != 0 && !self.state.latched
    }

    /// The edge the current arming asks for (switch latch only).
    pub(crate) fn edge(&self) -> Edge {
        self.edge
    }

    /// Capture `position` if waiting; later captures are ignored until the
    /// next arming.
    pub(crate) fn capture(&mut self, position: Option<f64>) {
        if let Some(p) = position {
            if self.waiting() && p.is_finite() {
                self.state.latched = true;
                self.state.position = p;
            }
        }
    }

    pub(crate) fn feedback(&self) -> LatchFeedback {
        self.state
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arm(id: u8) -> LatchArm {
        LatchArm {
            id,
            edge: Edge::Rising,
        }
    }

    #[test]
    fn handshake() {
        let mut l = Latch::default();
        assert!(!l.waiting());
        l.capture(Some(1.0));
        assert_eq!(l.feedback(), LatchFeedback::default(), "disarmed ignores");
        l.arm(arm(7));
        assert_eq!(l.feedback().id, 7);
        assert!(l.waiting());
        l.capture(None);
        assert!(l.waiting());
        l.capture(Some(2.5));
        l.capture(Some(12.5));
        assert_eq!(
            l.feedback(),
            LatchFeedback {
                id: 7,
                latched: true,
                position: 2.5
            }
        );
        l.arm(arm(7));
        assert!(l.feedback().latched, "same id does not re-arm");
        l.arm(arm(8));
        assert_eq!(l.feedback().id, 8);
        assert!(!l.feedback().latched);
        l.arm(arm(0));
        assert_eq!(l.feedback(), LatchFeedback::default());
    }
}
