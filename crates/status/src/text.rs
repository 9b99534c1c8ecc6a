//! Text in the wire structs: UTF-8, NUL-padded, of fixed length.

/// Bytes of a name (axis, I/O process, owner).
pub const NAME_LEN: usize = 32;
/// Bytes of a phase name.
pub const PHASE_LEN: usize = 16;

/// Writes `s` NUL-padded into `buf`, cut at a character boundary.
pub fn put_str(buf: &mut [u8], s: &str) {
    buf.fill(0);
    let mut n = s.len().min(buf.len());
    while !s.is_char_boundary(n) {
        n -= 1;
    }
    buf[..n].copy_from_slice(&s.as_bytes()[..n]);
}

/// The text of a NUL-padded field (invalid UTF-8 replaced, never a panic).
pub fn get_str(buf: &[u8]) -> String {
    let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    String::from_utf8_lossy(&buf[..end]).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strings_are_bounded_and_never_panic() {
        let mut b = [0u8; 4];
        put_str(&mut b, "Xä€");
        assert_eq!(get_str(&b), "Xä"); // cut at a character boundary
        assert_eq!(get_str(&[0xff, 0xfe, 0]), "\u{fffd}\u{fffd}");
    }
}
