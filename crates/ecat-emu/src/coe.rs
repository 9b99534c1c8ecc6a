//! CoE (CANopen over EtherCAT) SDO server of the mailbox: expedited, normal
//! and segmented upload and download, aborts (ETG.1000.6 §5.6.2).
//!
//! A request is the whole SM0 mailbox buffer (6-byte mailbox header, 2-byte
//! CoE header, SDO); the answer is the bytes to put into SM1.
//!
//! Upload of data that does not fit one mailbox: the initiate response
//! carries the complete size and no data, the data follows in segments of
//! up to mailbox size − 9 bytes (at least 7, padded, with the unused count).

use crate::drive::Drive;
use crate::od::abort;

const TYPE_ERR: u8 = 0x00;
const TYPE_COE: u8 = 0x03;
const SERVICE_SDO_REQUEST: u8 = 0x02;
const SERVICE_SDO_RESPONSE: u8 = 0x03;

#[derive(Clone, Debug)]
struct UploadState {
    data: Vec<u8>,
    offset: usize,
    toggle: bool,
}

#[derive(Clone, Debug)]
struct DownloadState {
    index: u16,
    sub: u8,
    size: usize,
    data: Vec<u8>,
    toggle: bool,
}

/// Statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CoeStats {
    pub requests: u64,
    pub aborts: u64,
    pub segments_up: u64,
    pub segments_down: u64,
}

/// The SDO server of one SubDevice.
#[derive(Clone, Debug, Default)]
pub struct CoeServer {
    upload: Option<UploadState>,
    download: Option<DownloadState>,
    counter: u8,
    pub stats: CoeStats,
}

/// Index and sub-index of an SDO request.
fn header(sdo: &[u8]) -> Option<(u16, u8)> {
    Some((
        u16::from_le_bytes([*sdo.get(1)?, *sdo.get(2)?]),
        *sdo.get(3)?,
    ))
}

fn mbx_header(len: usize, kind: u8, counter: u8) -> Vec<u8> {
    let mut v = Vec::with_capacity(6 + len);
    v.extend_from_slice(&(len as u16).to_le_bytes());
    v.extend_from_slice(&[0, 0, 0, kind | (counter << 4)]);
    v
}

impl CoeServer {
    pub fn new() -> CoeServer {
        CoeServer::default()
    }

    fn next_counter(&mut self) -> u8 {
        self.counter = if self.counter >= 7 {
            1
        } else {
            self.counter + 1
        };
        self.counter
    }

    fn sdo_response(&mut self, sdo: &[u8]) -> Vec<u8> {
        let c = self.next_counter();
        let mut v = mbx_header(2 + sdo.len(), TYPE_COE, c);
        v.extend_from_slice(&[0x00, SERVICE_SDO_RESPONSE << 4]);
        v.extend_from_slice(sdo);
        v
    }

    fn abort(&mut self, index: u16, sub: u8, code: u32) -> Vec<u8> {
        self.stats.aborts += 1;
        self.upload = None;
        self.download = None;
        let c = self.next_counter();
        let mut v = mbx_header(10, TYPE_COE, c);
        v.extend_from_slice(&[0x00, SERVICE_SDO_REQUEST << 4, 0x80]);
        v.extend_from_slice(&index.to_le_bytes());
        v.push(sub);
        v.extend_from_slice(&code.to_le_bytes());
        v
    }

    fn mailbox_error(&mut self, detail: u16) -> Vec<u8> {
        let c = self.next_counter();
        let mut v = mbx_header(4, TYPE_ERR, c);
        v.extend_from_slice(&0x0001u16.to_le_bytes());
        v.extend_from_slice(&detail.to_le_bytes());
        v
    }

    /// Handles one mailbox request. `preop`: mapping objects may change;
    /// `mbx_size`: the mailbox buffer size. `None`: nothing to answer (an
    /// abort from the client).
    pub fn handle(
        &mut self,
        req: &[u8],
        drive: &mut Drive,
        preop: bool,
        mbx_size: usize,
    ) -> Option<Vec<u8>> {
        let sdo = match self.sdo_request(req) {
            Ok(sdo) => sdo,
            Err(answer) => return Some(answer),
        };
        match sdo[0] >> 5 {
            1 => Some(self.initiate_download(sdo, drive, preop)),
            0 => Some(self.download_segment(sdo, drive, preop)),
            2 => Some(self.initiate_upload(sdo, drive, mbx_size)),
            3 => Some(self.upload_segment(sdo[0], mbx_size)),
            // abort from the client: drop the transfer, no answer
            4 => {
                self.upload = None;
                self.download = None;
                None
            }
            _ => {
                let (index, sub) = header(sdo).unwrap_or((0, 0));
                Some(self.abort(index, sub, abort::INVALID_COMMAND))
            }
        }
    }

    /// The SDO of a CoE SDO request (at least the command byte); `Err`: the
    /// mailbox error or abort to answer instead.
    fn sdo_request<'r>(&mut self, req: &'r [u8]) -> Result<&'r [u8], Vec<u8>> {
        if req.len() < 6 {
            return Err(self.mailbox_error(0x0002));
        }
        let len = usize::from(u16::from_le_bytes([req[0], req[1]]));
        let kind = req[5] & 0x0F;
        if kind != TYPE_COE {
            // unsupported protocol
            return Err(self.mailbox_error(0x0002));
        }
        if len < 2 || 6 + len > req.len() {
            return Err(self.mailbox_error(0x0005)); // invalid size
        }
        let body = &req[6..6 + len];
        let service = body[1] >> 4;
        if service != SERVICE_SDO_REQUEST {
            return Err(self.mailbox_error(0x0002));
        }
        self.stats.requests += 1;
        if body.len() < 3 {
            return Err(self.abort(0, 0, abort::INVALID_COMMAND));
        }
        Ok(&body[2..])
    }

    /// Index and sub-index of an initiate request (no complete access); a
    /// new transfer ends a running one. `Err`: the abort to answer.
    fn initiate(&mut self, sdo: &[u8]) -> Result<(u16, u8), Vec<u8>> {
        let Some((index, sub)) = header(sdo) else {
            return Err(self.abort(0, 0, abort::INVALID_COMMAND));
        };
        if sdo[0] & 0x10 != 0 {
            return Err(self.abort(index, sub, abort::NO_COMPLETE_ACCESS));
        }
        self.upload = None;
        self.download = None;
        Ok((index, sub))
    }

    /// Initiate download: expedited, normal (all data in the request), or
    /// the first bytes of a segmented one.
    fn initiate_download(&mut self, sdo: &[u8], drive: &mut Drive, preop: bool) -> Vec<u8> {
        let (index, sub) = match self.initiate(sdo) {
            Ok(x) => x,
            Err(answer) => return answer,
        };
        if sdo.len() < 8 {
            return self.abort(index, sub, abort::INVALID_COMMAND);
        }
        let cmd = sdo[0];
        if cmd & 0x02 != 0 {
            // expedited
            let n = if cmd & 0x01 != 0 {
                4 - usize::from((cmd >> 2) & 0x03)
            } else {
                usize::from(drive.od.bits(index, sub) / 8).clamp(1, 4)
            };
            return self.download(drive, index, sub, &sdo[4..4 + n], preop);
        }
        let size = u32::from_le_bytes([sdo[4], sdo[5], sdo[6], sdo[7]]) as usize;
        let data = &sdo[8..];
        if data.len() >= size {
            return self.download(drive, index, sub, &data[..size], preop);
        }
        // the rest follows in segments; check the target now
        if let Err(code) = drive.od.entry(index, sub).map(|_| ()) {
            return self.abort(index, sub, code);
        }
        self.download = Some(DownloadState {
            index,
            sub,
            size,
            data: data.to_vec(),
            toggle: false,
        });
        self.download_ok(index, sub)
    }

    /// The drive takes `data`: the download response, or the abort.
    fn download(
        &mut self,
        drive: &mut Drive,
        index: u16,
        sub: u8,
        data: &[u8],
        preop: bool,
    ) -> Vec<u8> {
        match drive.sdo_download(index, sub, data, preop) {
            Ok(()) => self.download_ok(index, sub),
            Err(code) => self.abort(index, sub, code),
        }
    }

    /// Download segment: appended; the last one is handed to the drive.
    fn download_segment(&mut self, sdo: &[u8], drive: &mut Drive, preop: bool) -> Vec<u8> {
        let Some(mut st) = self.download.take() else {
            return self.abort(0, 0, abort::INVALID_COMMAND);
        };
        let cmd = sdo[0];
        let toggle = cmd & 0x10 != 0;
        if toggle != st.toggle {
            return self.abort(st.index, st.sub, abort::TOGGLE_BIT);
        }
        let last = cmd & 0x01 != 0;
        let mut seg = &sdo[1..];
        if seg.len() == 7 {
            let unused = usize::from((cmd >> 1) & 0x07);
            seg = &seg[..7 - unused];
        }
        st.data.extend_from_slice(seg);
        self.stats.segments_down += 1;
        let resp = [0x20 | (u8::from(toggle) << 4), 0, 0, 0, 0, 0, 0, 0];
        if last {
            if st.data.len() != st.size {
                return self.abort(st.index, st.sub, abort::LENGTH_MISMATCH);
            }
            if let Err(code) = drive.sdo_download(st.index, st.sub, &st.data, preop) {
                return self.abort(st.index, st.sub, code);
            }
        } else {
            st.toggle = !st.toggle;
            self.download = Some(st);
        }
        self.sdo_response(&resp)
    }

    /// Initiate upload: expedited (≤ 4 bytes), normal (fits the mailbox),
    /// or the size now and the data in segments.
    fn initiate_upload(&mut self, sdo: &[u8], drive: &Drive, mbx_size: usize) -> Vec<u8> {
        let (index, sub) = match self.initiate(sdo) {
            Ok(x) => x,
            Err(answer) => return answer,
        };
        let data = match drive.od.upload(index, sub) {
            Ok(d) => d,
            Err(code) => return self.abort(index, sub, code),
        };
        let mut r = vec![0u8; 8];
        r[1..3].copy_from_slice(&index.to_le_bytes());
        r[3] = sub;
        if data.len() <= 4 && !data.is_empty() {
            r[0] = 0x40 | 0x02 | 0x01 | (((4 - data.len()) as u8) << 2);
            r[4..4 + data.len()].copy_from_slice(&data);
            return self.sdo_response(&r);
        }
        r[0] = 0x41;
        r[4..8].copy_from_slice(&(data.len() as u32).to_le_bytes());
        // header 6 + CoE 2 + SDO 8 = 16 bytes before the data
        if data.len() <= mbx_size.saturating_sub(16) {
            r.extend_from_slice(&data);
        } else {
            self.upload = Some(UploadState {
                data,
                offset: 0,
                toggle: false,
            });
        }
        self.sdo_response(&r)
    }

    /// Upload segment: the next piece of the running upload.
    fn upload_segment(&mut self, cmd: u8, mbx_size: usize) -> Vec<u8> {
        let Some(mut st) = self.upload.take() else {
            return self.abort(0, 0, abort::INVALID_COMMAND);
        };
        let toggle = cmd & 0x10 != 0;
        if toggle != st.toggle {
            return self.abort(0, 0, abort::TOGGLE_BIT);
        }
        // header 6 + CoE 2 + command 1
        let room = mbx_size.saturating_sub(9).max(7);
        let rest = st.data.len() - st.offset;
        let n = rest.min(room);
        let last = n == rest;
        let unused = 7usize.saturating_sub(n);
        let mut r = vec![(u8::from(toggle) << 4) | ((unused as u8) << 1) | u8::from(last)];
        r.extend_from_slice(&st.data[st.offset..st.offset + n]);
        r.resize(1 + n.max(7), 0);
        st.offset += n;
        st.toggle = !st.toggle;
        self.stats.segments_up += 1;
        if !last {
            self.upload = Some(st);
        }
        self.sdo_response(&r)
    }

    fn download_ok(&mut self, index: u16, sub: u8) -> Vec<u8> {
        let mut r = vec![0x60, 0, 0, sub, 0, 0, 0, 0];
        r[1..3].copy_from_slice(&index.to_le_bytes());
        self.sdo_response(&r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::DriveConfig;
    use crate::od::{Access, Mappable};

    fn req(sdo: &[u8]) -> Vec<u8> {
        let mut v = mbx_header(2 + sdo.len(), TYPE_COE, 1);
        v.extend_from_slice(&[0x00, SERVICE_SDO_REQUEST << 4]);
        v.extend_from_slice(sdo);
        v.resize(128, 0);
        v
    }

    fn drive() -> Drive {
        let mut d = Drive::new(DriveConfig::new("EMU-402 servo"));
        let long: String = (0..300)
            .map(|i| char::from(b'a' + (i % 26) as u8))
            .collect();
        d.od.string(0x2000, "long text", &long);
        d.od.var(0x2001, "scratch", 32, Access::Rw, Mappable::No, 0);
        // a writable string to receive segmented downloads
        d.od.string_with(0x2002, "writable text", &"x".repeat(200), Access::Rw);
        d
    }

    fn sdo(resp: &[u8]) -> &[u8] {
        let len = usize::from(u16::from_le_bytes([resp[0], resp[1]]));
        &resp[8..6 + len]
    }

    #[test]
    fn expedited_upload_and_download() {
        let mut s = CoeServer::new();
        let mut d = drive();
        let r = s
            .handle(&req(&[0x40, 0x18, 0x10, 1, 0, 0, 0, 0]), &mut d, true, 128)
            .unwrap();
        assert_eq!(r[5] & 0x0F, TYPE_COE);
        assert_eq!(r[7] >> 4, SERVICE_SDO_RESPONSE);
        assert_eq!(sdo(&r), [0x43, 0x18, 0x10, 1, 0xC7, 0x0E, 0, 0]);
        // u16 object: n = 2 unused bytes
        let r = s
            .handle(&req(&[0x40, 0x41, 0x60, 0, 0, 0, 0, 0]), &mut d, true, 128)
            .unwrap();
        assert_eq!(sdo(&r)[0], 0x4B);
        // expedited download of a u32
        let r = s
            .handle(
                &req(&[0x23, 0x01, 0x20, 0, 0x78, 0x56, 0x34, 0x12]),
                &mut d,
                true,
                128,
            )
            .unwrap();
        assert_eq!(sdo(&r), [0x60, 0x01, 0x20, 0, 0, 0, 0, 0]);
        assert_eq!(d.od.get(0x2001, 0), 0x1234_5678);
    }

    #[test]
    fn aborts_name_the_object() {
        let mut s = CoeServer::new();
        let mut cfg = DriveConfig::new("NOTP");
        cfg.touch_probe = false;
        let mut d = Drive::new(cfg);
        let r = s
            .handle(&req(&[0x40, 0xB8, 0x60, 0, 0, 0, 0, 0]), &mut d, true, 128)
            .unwrap();
        assert_eq!(r[7] >> 4, SERVICE_SDO_REQUEST);
        assert_eq!(sdo(&r), [0x80, 0xB8, 0x60, 0, 0x00, 0x00, 0x02, 0x06]);
        // write to a read-only object
        let r = s
            .handle(&req(&[0x2B, 0x41, 0x60, 0, 1, 0, 0, 0]), &mut d, true, 128)
            .unwrap();
        assert_eq!(&sdo(&r)[4..], 0x0601_0002u32.to_le_bytes());
        // complete access is not supported
        let r = s
            .handle(&req(&[0x50, 0x00, 0x1C, 0, 0, 0, 0, 0]), &mut d, true, 128)
            .unwrap();
        assert_eq!(&sdo(&r)[4..], 0x0601_0004u32.to_le_bytes());
        assert_eq!(s.stats.aborts, 3);
        // non-CoE mailbox: mailbox error
        let mut other = req(&[0x40, 0, 0x10, 0, 0, 0, 0, 0]);
        other[5] = 0x04;
        let r = s.handle(&other, &mut d, true, 128).unwrap();
        assert_eq!(r[5] & 0x0F, TYPE_ERR);
    }

    #[test]
    fn normal_and_segmented_upload() {
        let mut s = CoeServer::new();
        let mut d = drive();
        // 0x1008 fits: normal upload, data in the response
        let r = s
            .handle(&req(&[0x40, 0x08, 0x10, 0, 0, 0, 0, 0]), &mut d, true, 128)
            .unwrap();
        let b = sdo(&r);
        assert_eq!(b[0], 0x41);
        assert_eq!(u32::from_le_bytes(b[4..8].try_into().unwrap()), 13);
        assert_eq!(&b[8..], b"EMU-402 servo");
        assert_eq!(u16::from_le_bytes([r[0], r[1]]), 23);

        // 300 bytes: segmented
        let r = s
            .handle(&req(&[0x40, 0x00, 0x20, 0, 0, 0, 0, 0]), &mut d, true, 128)
            .unwrap();
        let b = sdo(&r);
        assert_eq!(b[0], 0x41);
        assert_eq!(u32::from_le_bytes(b[4..8].try_into().unwrap()), 300);
        assert_eq!(b.len(), 8, "no data in the initiate response");
        let mut got = Vec::new();
        let mut toggle = false;
        loop {
            let r = s
                .handle(
                    &req(&[0x60 | (u8::from(toggle) << 4), 0, 0, 0, 0, 0, 0, 0]),
                    &mut d,
                    true,
                    128,
                )
                .unwrap();
            let len = usize::from(u16::from_le_bytes([r[0], r[1]]));
            let cmd = r[8];
            assert_eq!(cmd >> 5, 0, "upload segment response");
            assert_eq!(cmd & 0x10 != 0, toggle);
            let mut n = len - 3;
            if n == 7 {
                n -= usize::from((cmd >> 1) & 7);
            }
            got.extend_from_slice(&r[9..9 + n]);
            if cmd & 1 != 0 {
                break;
            }
            toggle = !toggle;
        }
        assert_eq!(got, d.od.upload(0x2000, 0).unwrap());
        assert!(s.stats.segments_up >= 3);
        // a wrong toggle aborts
        s.handle(&req(&[0x40, 0x00, 0x20, 0, 0, 0, 0, 0]), &mut d, true, 128);
        let r = s
            .handle(&req(&[0x70, 0, 0, 0, 0, 0, 0, 0]), &mut d, true, 128)
            .unwrap();
        assert_eq!(&sdo(&r)[4..], 0x0503_0000u32.to_le_bytes());
    }

    #[test]
    fn normal_and_segmented_download() {
        let mut s = CoeServer::new();
        let mut d = drive();
        let text: Vec<u8> = (0..150u8).map(|i| b'A' + i % 26).collect();
        // initiate with the first 20 bytes, the rest in segments of 7 + ...
        let mut init = vec![0x21, 0x02, 0x20, 0];
        init.extend_from_slice(&(text.len() as u32).to_le_bytes());
        init.extend_from_slice(&text[..20]);
        let r = s.handle(&req(&init), &mut d, true, 128).unwrap();
        assert_eq!(sdo(&r)[0], 0x60);
        let mut at = 20;
        let mut toggle = false;
        while at < text.len() {
            let n = (text.len() - at).min(50);
            let last = at + n == text.len();
            let mut seg = vec![(u8::from(toggle) << 4) | u8::from(last)];
            seg.extend_from_slice(&text[at..at + n]);
            if n < 7 {
                seg[0] |= ((7 - n) as u8) << 1;
                seg.resize(8, 0);
            }
            let r = s.handle(&req(&seg), &mut d, true, 128).unwrap();
            assert_eq!(sdo(&r)[0], 0x20 | (u8::from(toggle) << 4));
            at += n;
            toggle = !toggle;
        }
        assert_eq!(d.od.upload(0x2002, 0).unwrap(), text);
        assert!(s.stats.segments_down >= 3);
        // a segment without a transfer aborts
        let r = s
            .handle(&req(&[0x01, 1, 2, 3, 4, 5, 6, 7]), &mut d, true, 128)
            .unwrap();
        assert_eq!(&sdo(&r)[4..], 0x0504_0001u32.to_le_bytes());
        // whole data in the initiate request (normal download)
        let mut init = vec![0x21, 0x02, 0x20, 0];
        init.extend_from_slice(&5u32.to_le_bytes());
        init.extend_from_slice(b"hello");
        s.handle(&req(&init), &mut d, true, 128).unwrap();
        assert_eq!(d.od.upload(0x2002, 0).unwrap(), b"hello");
        // abort from the client: no answer
        assert!(s
            .handle(&req(&[0x80, 0, 0x20, 0, 0, 0, 0, 0]), &mut d, true, 128)
            .is_none());
    }
}
