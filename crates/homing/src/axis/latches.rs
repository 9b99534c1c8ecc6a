//! The arm side of the drive's position latches (touch-probe handshake).
//!
//! Every arming gets a new non-zero id; the drive echoes it with its capture,
//! so a capture from an earlier arming can never be taken for a new one,
//! whatever the frame delay. Id 0 disarms.

use crate::io::Edge;

#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Latches {
    /// Id of the current marker arming (0 = disarmed).
    pub marker_id: u8,
    /// Id of the current switch (registration) arming (0 = disarmed).
    pub switch_id: u8,
    /// Electrical edge the switch latch is armed for.
    pub switch_edge: Edge,
    last_id: u8,
}

impl Latches {
    pub fn arm_marker(&mut self) {
        self.marker_id = self.next_id();
    }

    /// Arms the switch latch for a rising (`true`) or falling electrical edge.
    pub fn arm_switch(&mut self, rising: bool) {
        self.switch_edge = if rising { Edge::Rising } else { Edge::Falling };
        self.switch_id = self.next_id();
    }

    pub fn disarm(&mut self) {
        self.marker_id = 0;
        self.switch_id = 0;
    }

    /// Ids run 1..=255 and wrap past 0, which means "disarmed".
    fn next_id(&mut self) -> u8 {
        self.last_id = if self.last_id == u8::MAX {
            1
        } else {
            self.last_id + 1
        };
        self.last_id
    }
}
