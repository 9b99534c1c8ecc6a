//! The process image of an emulated drive, packed and unpacked from the
//! mapping (0x1600 / 0x1A00) and assignment (0x1C12 / 0x1C13) objects as
//! they are: what the master wrote is what goes on the wire.

use super::Drive;

impl Drive {
    /// The mapped entries (index, sub-index, bits) of the PDOs assigned in
    /// `assign` (0x1C12 / 0x1C13), in order.
    fn mapping(&self, assign: u16) -> Vec<(u16, u8, u16)> {
        let mut out = Vec::new();
        let n = self.od.get(assign, 0) as u8;
        for i in 1..=n {
            let pdo = self.od.get(assign, i) as u16;
            let m = self.od.get(pdo, 0) as u8;
            for j in 1..=m {
                let v = self.od.get(pdo, j) as u32;
                out.push(((v >> 16) as u16, (v >> 8) as u8, (v & 0xFF) as u16));
            }
        }
        out
    }

    /// Output (RxPDO) bytes of the current mapping.
    pub fn rx_bytes(&self) -> usize {
        self.mapping(0x1C12)
            .iter()
            .map(|e| usize::from(e.2) / 8)
            .sum()
    }

    /// Input (TxPDO) bytes of the current mapping.
    pub fn tx_bytes(&self) -> usize {
        self.mapping(0x1C13)
            .iter()
            .map(|e| usize::from(e.2) / 8)
            .sum()
    }

    /// Stores the received outputs into the mapped objects.
    pub fn apply_outputs(&mut self, buf: &[u8]) {
        let mut at = 0;
        for (index, sub, bits) in self.mapping(0x1C12) {
            let n = usize::from(bits) / 8;
            if let Some(b) = buf.get(at..at + n) {
                self.od.set_bytes(index, sub, b);
            }
            at += n;
        }
    }

    /// Packs the mapped inputs.
    pub fn fill_inputs(&self, buf: &mut [u8]) {
        let mut at = 0;
        for (index, sub, bits) in self.mapping(0x1C13) {
            let n = usize::from(bits) / 8;
            let v = self.od.get(index, sub).to_le_bytes();
            if let Some(dst) = buf.get_mut(at..at + n) {
                dst.copy_from_slice(&v[..n]);
            }
            at += n;
        }
    }
}
