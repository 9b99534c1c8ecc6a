//! Touch probes (0x60B8 function, 0x60B9 status, 0x60BA..0x60BD positions)
//! behind the frames' latch ids.
//!
//! * Probe 1 latches the encoder index (zero impulse): the **marker latch**
//!   (`marker_arm_id` → `marker_latch_*`, rising edge, 0x60BA).
//! * Probe 2 latches its digital input, wired to the home switch: the
//!   **switch (registration) latch** (`switch_arm_id`/`switch_arm_edge` →
//!   `switch_latch_*`; rising edge 0x60BC, falling edge 0x60BD).
//!
//! Both run in "trigger on first event" mode. The frames' id handshake
//! (crates/homing/src/io.rs, `LatchFeedback`) is kept exactly: the id of a
//! request is reported only once the drive has confirmed *that* arming, and a
//! stored edge is reported only if it belongs to it. Arming = the enable bit
//! goes 0 → 1 (the drive clears its stored edges on that edge). Before a new
//! arming the enable bit is held at 0 for at least [`SETTLE_CYCLES`] cycles
//! *and* until the drive reports the probe disabled, so every status seen
//! with "enabled" afterwards stems from the new arming, whatever the drive's
//! process-data latency (up to `SETTLE_CYCLES` cycles). While re-arming the
//! id reads 0 (disarmed); an edge passed in that window is not latched.
//!
//! Positions are 32-bit on the wire; they are extended to the 64-bit axis
//! position with the drive's position at the cycle they are first seen
//! (`position64 + (latch32 − position32)` in wrapping arithmetic) and then
//! held unchanged.

/// Touch probe function (0x60B8) bits.
pub mod function {
    pub const PROBE1_ENABLE: u16 = 1 << 0;
    /// 0 = trigger on the first event, 1 = continuous.
    pub const PROBE1_CONTINUOUS: u16 = 1 << 1;
    /// Source bits 2–3 = 01: the encoder's zero impulse.
    pub const PROBE1_SOURCE_INDEX: u16 = 0b01 << 2;
    pub const PROBE1_RISING: u16 = 1 << 4;
    pub const PROBE1_FALLING: u16 = 1 << 5;
    pub const PROBE2_ENABLE: u16 = 1 << 8;
    pub const PROBE2_CONTINUOUS: u16 = 1 << 9;
    /// Source bits 10–11 = 00: the touch probe 2 input.
    pub const PROBE2_SOURCE_INPUT: u16 = 0b00 << 10;
    pub const PROBE2_RISING: u16 = 1 << 12;
    pub const PROBE2_FALLING: u16 = 1 << 13;
}

/// Touch probe status (0x60B9) bits.
pub mod status {
    pub const PROBE1_ENABLED: u16 = 1 << 0;
    pub const PROBE1_RISING_STORED: u16 = 1 << 1;
    pub const PROBE1_FALLING_STORED: u16 = 1 << 2;
    pub const PROBE2_ENABLED: u16 = 1 << 8;
    pub const PROBE2_RISING_STORED: u16 = 1 << 9;
    pub const PROBE2_FALLING_STORED: u16 = 1 << 10;
}

/// Cycles the enable bit stays 0 before a new arming (bound on the drive's
/// process-data latency, in cycles).
pub const SETTLE_CYCLES: u32 = 3;

/// Edge a latch takes (the frames' `EDGE_RISING` / `EDGE_FALLING`): the
/// engine's own type.
pub use motion_homing::Edge;

/// A latch as reported in the feedback frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Latch {
    pub id: u8,
    pub latched: bool,
    pub position: i64,
}

/// This cycle's touch-probe inputs of one drive.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ProbeInputs {
    pub status: u16,
    pub probe1_positive: i32,
    pub probe1_negative: i32,
    pub probe2_positive: i32,
    pub probe2_negative: i32,
    /// The drive's position this cycle, as on the wire…
    pub position32: i32,
    /// …and extended to 64 bits.
    pub position64: i64,
}

impl ProbeInputs {
    fn extend(&self, latch32: i32) -> i64 {
        self.position64
            .wrapping_add(i64::from(latch32.wrapping_sub(self.position32)))
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Phase {
    #[default]
    Off,
    /// Enable bit held at 0 until the drive shows the probe disabled.
    Disabling,
    /// Enable bit 1, waiting for the drive to confirm.
    Enabling,
    /// Confirmed: the id is reported.
    Armed,
}

/// Bits of one probe channel.
#[derive(Clone, Copy, Debug)]
struct Bits {
    enable: u16,
    source: u16,
    rising: u16,
    falling: u16,
    enabled: u16,
    rising_stored: u16,
    falling_stored: u16,
}

const PROBE1: Bits = Bits {
    enable: function::PROBE1_ENABLE,
    source: function::PROBE1_SOURCE_INDEX,
    rising: function::PROBE1_RISING,
    falling: function::PROBE1_FALLING,
    enabled: status::PROBE1_ENABLED,
    rising_stored: status::PROBE1_RISING_STORED,
    falling_stored: status::PROBE1_FALLING_STORED,
};

const PROBE2: Bits = Bits {
    enable: function::PROBE2_ENABLE,
    source: function::PROBE2_SOURCE_INPUT,
    rising: function::PROBE2_RISING,
    falling: function::PROBE2_FALLING,
    enabled: status::PROBE2_ENABLED,
    rising_stored: status::PROBE2_RISING_STORED,
    falling_stored: status::PROBE2_FALLING_STORED,
};

#[derive(Clone, Copy, Debug)]
struct Channel {
    bits: Bits,
    id: u8,
    edge: Edge,
    phase: Phase,
    /// Consecutive cycles the enable bit was sent as 0 (saturating).
    zero_cycles: u32,
    latched: Option<i64>,
    rearms: u32,
}

impl Channel {
    const fn new(bits: Bits) -> Channel {
        Channel {
            bits,
            id: 0,
            edge: Edge::Rising,
            phase: Phase::Off,
            zero_cycles: SETTLE_CYCLES,
            latched: None,
            rearms: 0,
        }
    }

    fn on_word(&self) -> u16 {
        let b = &self.bits;
        b.enable
            | b.source
            | match self.edge {
                Edge::Rising => b.rising,
                Edge::Falling => b.falling,
            }
    }

    /// One cycle; returns this channel's function bits.
    fn step(&mut self, id: u8, edge: Edge, inp: &ProbeInputs) -> u16 {
        let enabled = inp.status & self.bits.enabled != 0;
        if id == 0 {
            self.id = 0;
            self.phase = Phase::Off;
            self.latched = None;
        } else if id != self.id {
            // a new request (its edge is taken now; a changed edge with the
            // same id is ignored, as a probe takes its setup on arming)
            self.id = id;
            self.edge = edge;
            self.phase = Phase::Disabling;
            self.latched = None;
        } else if self.phase == Phase::Armed && !enabled {
            // the drive dropped the arming (fault, re-init): arm again
            self.phase = Phase::Disabling;
            self.latched = None;
            self.rearms = self.rearms.saturating_add(1);
        }
        if self.phase == Phase::Disabling && self.zero_cycles >= SETTLE_CYCLES && !enabled {
            self.phase = Phase::Enabling;
        }
        if self.phase == Phase::Enabling && enabled && self.zero_cycles == 0 {
            self.phase = Phase::Armed;
        }
        if self.phase == Phase::Armed && self.latched.is_none() {
            let (stored, pos) = match (self.edge, self.bits.enable == PROBE1.enable) {
                (Edge::Rising, true) => (self.bits.rising_stored, inp.probe1_positive),
                (Edge::Falling, true) => (self.bits.falling_stored, inp.probe1_negative),
                (Edge::Rising, false) => (self.bits.rising_stored, inp.probe2_positive),
                (Edge::Falling, false) => (self.bits.falling_stored, inp.probe2_negative),
            };
            if inp.status & stored != 0 {
                self.latched = Some(inp.extend(pos));
            }
        }
        let word = match self.phase {
            Phase::Enabling | Phase::Armed => self.on_word(),
            Phase::Off | Phase::Disabling => 0,
        };
        if word == 0 {
            self.zero_cycles = self.zero_cycles.saturating_add(1);
        } else {
            self.zero_cycles = 0;
        }
        word
    }

    fn latch(&self) -> Latch {
        if self.phase == Phase::Armed {
            Latch {
                id: self.id,
                latched: self.latched.is_some(),
                position: self.latched.unwrap_or(0),
            }
        } else {
            Latch::default()
        }
    }
}

/// Both probes of one drive.
#[derive(Clone, Copy, Debug)]
pub struct TouchProbes {
    marker: Channel,
    switch: Channel,
}

impl Default for TouchProbes {
    fn default() -> Self {
        Self::new()
    }
}

impl TouchProbes {
    pub const fn new() -> Self {
        Self {
            marker: Channel::new(PROBE1),
            switch: Channel::new(PROBE2),
        }
    }

    /// One cycle: the arm requests of the command frame and this cycle's
    /// inputs in, the touch probe function word (0x60B8) out.
    pub fn step(
        &mut self,
        marker_arm_id: u8,
        switch_arm_id: u8,
        switch_edge: Edge,
        inputs: &ProbeInputs,
    ) -> u16 {
        self.marker.step(marker_arm_id, Edge::Rising, inputs)
            | self.switch.step(switch_arm_id, switch_edge, inputs)
    }

    /// The marker latch for the feedback frame.
    pub fn marker(&self) -> Latch {
        self.marker.latch()
    }

    /// The switch latch for the feedback frame.
    pub fn switch(&self) -> Latch {
        self.switch.latch()
    }

    /// Armings the drive dropped and that were redone.
    pub fn rearms(&self) -> u32 {
        self.marker.rearms + self.switch.rearms
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A drive's touch probe unit with `lag` cycles of process-data latency:
    /// the word sent in cycle k takes effect before the status of cycle
    /// k + lag is sampled.
    struct Drive {
        pipe: Vec<u16>,
        function: u16,
        status: u16,
        pos: [i32; 4],
    }

    impl Drive {
        fn new(lag: usize) -> Drive {
            Drive {
                pipe: vec![0; lag],
                function: 0,
                status: 0,
                pos: [0; 4],
            }
        }

        /// Applies the word that arrives now; `index` / `input` edges at
        /// `at` happen during this drive cycle.
        fn cycle(&mut self, word: u16, index_at: Option<i32>, input: Option<(Edge, i32)>) {
            self.pipe.push(word);
            let w = self.pipe.remove(0);
            let old = self.function;
            self.function = w;
            for (en, en_st, stored) in [(0x0001u16, 0x0001u16, 0x0006u16), (0x0100, 0x0100, 0x0600)]
            {
                if w & en != 0 && old & en == 0 {
                    self.status = (self.status | en_st) & !stored;
                } else if w & en == 0 {
                    self.status &= !(en_st | stored);
                }
            }
            if let Some(p) = index_at {
                if self.function & 0x0011 == 0x0011 && self.status & 0x0002 == 0 {
                    self.status |= 0x0002;
                    self.pos[0] = p;
                }
            }
            if let Some((e, p)) = input {
                let (bit, st, slot) = match e {
                    Edge::Rising => (0x1000, 0x0200, 2),
                    Edge::Falling => (0x2000, 0x0400, 3),
                };
                if self.function & (0x0100 | bit) == 0x0100 | bit && self.status & st == 0 {
                    self.status |= st;
                    self.pos[slot] = p;
                }
            }
        }

        fn inputs(&self, pos: i32) -> ProbeInputs {
            ProbeInputs {
                status: self.status,
                probe1_positive: self.pos[0],
                probe1_negative: self.pos[1],
                probe2_positive: self.pos[2],
                probe2_negative: self.pos[3],
                position32: pos,
                position64: i64::from(pos),
            }
        }
    }

    #[test]
    fn marker_arms_reports_id_then_exact_latch() {
        for lag in 1..=3 {
            let mut p = TouchProbes::new();
            let mut d = Drive::new(lag);
            let mut armed_at = None;
            for k in 0..20 {
                let w = p.step(7, 0, Edge::Rising, &d.inputs(100));
                let m = p.marker();
                if m.id == 7 && armed_at.is_none() {
                    armed_at = Some(k);
                }
                assert!(m.id == 0 || m.id == 7);
                assert!(!m.latched);
                d.cycle(w, None, None);
            }
            assert!(armed_at.is_some(), "lag {lag}");
            // the word carries probe 1, index source, rising
            assert_eq!(p.step(7, 0, Edge::Rising, &d.inputs(100)), 0x0015);
            d.cycle(0x0015, Some(1234), None);
            for _ in 0..lag + 1 {
                let w = p.step(7, 0, Edge::Rising, &d.inputs(2000));
                d.cycle(w, Some(9999), None); // later index pulses are not stored
            }
            assert_eq!(
                p.marker(),
                Latch {
                    id: 7,
                    latched: true,
                    position: 1234
                },
                "lag {lag}"
            );
            // held, same id does not re-arm
            for _ in 0..5 {
                let w = p.step(7, 0, Edge::Rising, &d.inputs(5000));
                d.cycle(w, Some(7777), None);
            }
            assert_eq!(p.marker().position, 1234);
        }
    }

    #[test]
    fn a_stale_latch_is_never_reported_under_a_new_id() {
        for lag in 1..=3 {
            let mut p = TouchProbes::new();
            let mut d = Drive::new(lag);
            // arm id 1 and latch at 500
            for _ in 0..10 {
                let w = p.step(1, 0, Edge::Rising, &d.inputs(0));
                d.cycle(w, Some(500), None);
            }
            assert!(p.marker().latched && p.marker().position == 500);
            // re-arm with id 2: from now on no report may carry id 2 with
            // position 500 (the old latch)
            let mut saw_two = false;
            for k in 0..30 {
                let w = p.step(2, 0, Edge::Rising, &d.inputs(0));
                let m = p.marker();
                if m.id == 2 {
                    saw_two = true;
                    assert!(!(m.latched && m.position == 500), "lag {lag} k {k}");
                }
                assert_ne!(m.id, 1, "old id gone at once");
                // index pulses keep coming at 500 until cycle 20, then at 800
                let at = if k < 20 { None } else { Some(800) };
                d.cycle(w, at, None);
            }
            assert!(saw_two);
            assert_eq!(
                p.marker(),
                Latch {
                    id: 2,
                    latched: true,
                    position: 800
                }
            );
        }
    }

    #[test]
    fn rapid_re_requests_while_enabling() {
        let mut p = TouchProbes::new();
        let mut d = Drive::new(2);
        let mut last = 0;
        for k in 0..40u8 {
            let id = if k < 10 { k / 2 + 1 } else { 9 };
            let w = p.step(id, 0, Edge::Rising, &d.inputs(0));
            let m = p.marker();
            assert!(m.id == 0 || m.id == id, "k {k}: {m:?} for {id}");
            last = m.id;
            d.cycle(w, None, None);
        }
        assert_eq!(last, 9);
    }

    #[test]
    fn switch_latch_on_either_edge_and_disarm() {
        let mut p = TouchProbes::new();
        let mut d = Drive::new(1);
        for _ in 0..6 {
            let w = p.step(0, 3, Edge::Falling, &d.inputs(0));
            assert!(w == 0 || w == 0x2100, "{w:#06x}");
            d.cycle(w, None, Some((Edge::Rising, 111))); // wrong edge
        }
        assert_eq!(p.switch().id, 3);
        assert!(!p.switch().latched);
        let w = p.step(0, 3, Edge::Falling, &d.inputs(0));
        d.cycle(w, None, Some((Edge::Falling, -42)));
        p.step(0, 3, Edge::Rising, &d.inputs(0)); // edge change, same id: ignored
        assert_eq!(
            p.switch(),
            Latch {
                id: 3,
                latched: true,
                position: -42
            }
        );
        // disarm
        assert_eq!(p.step(0, 0, Edge::Rising, &d.inputs(0)), 0);
        assert_eq!(p.switch(), Latch::default());
        assert_eq!(p.marker(), Latch::default());
    }

    #[test]
    fn positions_extend_across_the_32_bit_wrap() {
        let inp = ProbeInputs {
            status: 0,
            position32: i32::MIN + 10,
            position64: i64::from(i32::MAX) + 11,
            ..ProbeInputs::default()
        };
        // a latch 20 counts before the current position, on the other side
        // of the wrap
        assert_eq!(inp.extend(i32::MAX - 9), i64::from(i32::MAX) + 11 - 20);
    }

    #[test]
    fn dropped_arming_is_redone() {
        let mut p = TouchProbes::new();
        let mut d = Drive::new(1);
        for _ in 0..6 {
            let w = p.step(4, 0, Edge::Rising, &d.inputs(0));
            d.cycle(w, None, None);
        }
        assert_eq!(p.marker().id, 4);
        // the drive drops the probe (e.g. fault)
        d.status = 0;
        d.function = 0;
        let w = p.step(4, 0, Edge::Rising, &d.inputs(0));
        assert_eq!(p.marker().id, 0);
        assert_eq!(p.rearms(), 1);
        d.cycle(w, None, None);
        for _ in 0..8 {
            let w = p.step(4, 0, Edge::Rising, &d.inputs(0));
            d.cycle(w, None, None);
        }
        assert_eq!(p.marker().id, 4);
    }
}
