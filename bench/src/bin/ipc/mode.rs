//! The four ways the round trip is measured: motion-io or a bare iceoryx2
//! echo as the peer, each waiting on the event or spinning. The bare echo
//! is the floor: what iceoryx2 itself costs with the same payloads, so that
//! motion-io / bare shows what motion-io adds.

/// One peer set-up ([`Mode::ALL`], in the order they run by default).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    IoEvent,
    BareEvent,
    IoSpin,
    BareSpin,
}

impl Mode {
    pub const ALL: [Mode; 4] = [Mode::IoEvent, Mode::BareEvent, Mode::IoSpin, Mode::BareSpin];

    /// Its name in `--modes`.
    pub fn key(self) -> &'static str {
        ["io-event", "bare-event", "io-spin", "bare-spin"][self as usize]
    }

    /// Its row in the table.
    pub fn label(self) -> &'static str {
        [
            "(a) motion-io, event",
            "(c) bare echo, event",
            "(b) motion-io --spin",
            "(c) bare echo, spin",
        ][self as usize]
    }

    /// The peer busy-polls (SCHED_OTHER) instead of waiting on the event.
    pub fn spin(self) -> bool {
        matches!(self, Mode::IoSpin | Mode::BareSpin)
    }

    /// The peer is this binary's bare echo, not motion-io.
    pub fn bare(self) -> bool {
        matches!(self, Mode::BareEvent | Mode::BareSpin)
    }
}

/// `--modes` item: a mode's key, blanks around it ignored.
pub fn parse(s: &str) -> Result<Mode, String> {
    let known = Mode::ALL.map(Mode::key).join(", ");
    let mode = Mode::ALL.into_iter().find(|x| x.key() == s.trim());
    mode.ok_or_else(|| format!("unknown mode {s:?} (one of {known})"))
}
