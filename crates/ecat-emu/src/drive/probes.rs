//! Touch probes of an emulated drive: probe 1 on the encoder index (zero
//! impulse, source 01), probe 2 on its input, wired to the home switch
//! (source 00); first-event mode, rising or falling edge. Every 0 → 1 of an
//! enable bit re-arms the plant's latch with a fresh internal id, so the
//! latched positions (0x60BA..0x60BD) are the plant's exact ones.

use motion_homing::{Edge, Feedback, LatchArm};

use super::Drive;

#[derive(Clone, Copy, Debug, Default)]
pub(super) struct ProbeUnit {
    enabled: bool,
    id: u8,
}

impl Drive {
    /// The plant's latch arms from 0x60B8 (marker, switch); an enable bit's
    /// 0 → 1 draws a fresh id.
    pub(super) fn probe_arms(&mut self) -> (LatchArm, LatchArm) {
        let f = self.od.get(0x60B8, 0) as u16;
        let mut arms = [LatchArm::default(); 2];
        for (k, (en_bit, shift)) in [(0x0001u16, 0u16), (0x0100, 8)].into_iter().enumerate() {
            let en = f & en_bit != 0;
            let unit = &mut self.probes[k];
            if en && !unit.enabled {
                self.next_probe_id = self.next_probe_id.wrapping_add(1).max(1);
                unit.id = self.next_probe_id;
            }
            if !en {
                unit.id = 0;
            }
            unit.enabled = en;
            let source = (f >> (shift + 2)) & 0b11;
            let rising = f & (0x0010 << shift) != 0;
            let falling = f & (0x0020 << shift) != 0;
            // probe 1: index (01); probe 2: its input (00)
            let source_ok = if k == 0 {
                source == 0b01
            } else {
                source == 0b00
            };
            if en && source_ok && (rising || falling) {
                arms[k] = LatchArm {
                    id: unit.id,
                    edge: if rising { Edge::Rising } else { Edge::Falling },
                };
            }
        }
        (arms[0], arms[1])
    }

    /// 0x60B9 and the latched positions 0x60BA..0x60BD from the plant's
    /// latches of this arming.
    pub(super) fn update_probe_status(&mut self, fb: &Feedback) {
        let f = self.od.get(0x60B8, 0) as u16;
        let mut st = 0u16;
        if self.probes[0].enabled {
            st |= 0x0001;
            let l = fb.marker_latch;
            if l.id != 0 && l.id == self.probes[0].id && l.latched {
                if f & 0x0010 != 0 {
                    st |= 0x0002;
                    self.od
                        .put(0x60BA, 0, self.counts(l.position + self.offset));
                } else {
                    st |= 0x0004;
                    self.od
                        .put(0x60BB, 0, self.counts(l.position + self.offset));
                }
            }
        }
        if self.probes[1].enabled {
            st |= 0x0100;
            let l = fb.switch_latch;
            if l.id != 0 && l.id == self.probes[1].id && l.latched {
                if f & 0x1000 != 0 {
                    st |= 0x0200;
                    self.od
                        .put(0x60BC, 0, self.counts(l.position + self.offset));
                } else {
                    st |= 0x0400;
                    self.od
                        .put(0x60BD, 0, self.counts(l.position + self.offset));
                }
            }
        }
        self.od.put(0x60B9, 0, u64::from(st));
    }
}
