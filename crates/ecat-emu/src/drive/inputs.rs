//! The input objects of an emulated drive, from the plant: statusword
//! (state bits, remote, CSP following / following error), position,
//! velocity and torque in the objects' units, digital inputs (0x60FD: limit
//! switches, home switch, an index-pulse bit), touch probes.

use super::state::State;
use super::{Drive, ERR_FOLLOWING};

impl Drive {
    /// The input objects from the plant: statusword, position, velocity,
    /// torque, digital inputs, touch probes.
    pub(super) fn update_inputs(&mut self) {
        let fb = self.plant.feedback();
        let cpu = self.cfg.counts_per_unit;
        let mut sw = self.state.bits() | 0x0200;
        if self.mode() == 6 {
            sw |= self.homing_statusword();
        } else if self.state == State::OperationEnabled {
            // CSP: following the target
            sw |= 0x1000;
        }
        if self.od.get(0x603F, 0) as u16 == ERR_FOLLOWING && self.state == State::Fault {
            sw |= 0x2000;
        }
        self.od.put(0x6041, 0, u64::from(sw));
        self.od
            .put(0x6064, 0, self.counts(fb.position + self.offset));
        let v = (fb.velocity * cpu)
            .round()
            .clamp(i32::MIN as f64, i32::MAX as f64) as i32;
        self.od.put(0x606C, 0, v as u32 as u64);
        let t = (fb.torque * 10.0).round().clamp(-32768.0, 32767.0) as i16;
        self.od.put(0x6077, 0, t as u16 as u64);
        let mut di = 0u32;
        if fb.overtravel_negative && self.cfg.limit_switches {
            di |= 1 << 0;
        }
        if fb.overtravel_positive && self.cfg.limit_switches {
            di |= 1 << 1;
        }
        if fb.home_switch {
            di |= 1 << 2;
        }
        if let (true, Some(bit)) = (fb.marker_pulse, self.cfg.index_pulse_bit) {
            di |= 1 << (bit & 31);
        }
        self.od.put(0x60FD, 0, u64::from(di));
        if self.cfg.touch_probe {
            self.update_probe_status(&fb);
        }
    }

    /// Position units → counts as the 32-bit objects hold them.
    pub(super) fn counts(&self, units: f64) -> u64 {
        ((units * self.cfg.counts_per_unit).round() as i64) as u32 as u64
    }
}
