//! The word layout of the two seqlock buffers between `motion-io`'s thread
//! ([`crate::EthercatBackend`]) and the bus thread: a header, then one
//! frame axis entry (`AxisCommand` / `AxisFeedback`) per axis, as `u64`s.

use motion_frames::{AxisCommand, AxisFeedback};

/// Header words of both buffers.
pub(crate) const HEADER_WORDS: usize = 4;
/// Words per axis (an `AxisCommand` / `AxisFeedback`, 48 bytes).
pub(crate) const AXIS_WORDS: usize = 6;

/// Commands header: `[generation, mode, the command frame's sequence, 0]`.
pub(crate) const MODE_NORMAL: u64 = 0;
pub(crate) const MODE_WATCHDOG_STOP: u64 = 1;
pub(crate) const MODE_EMERGENCY: u64 = 2;

/// Feedback header: `[bus cycle, CLOCK_MONOTONIC ns of the exchange,
/// flags, at-rest mask]`.
pub(crate) const FLAG_RUNNING: u64 = 1;
/// The bus thread's own watchdog stops the drives (no command within its
/// bound).
pub(crate) const FLAG_BUS_WATCHDOG: u64 = 2;

const _: () = {
    assert!(size_of::<AxisCommand>() == AXIS_WORDS * 8);
    assert!(size_of::<AxisFeedback>() == AXIS_WORDS * 8);
};

/// Words of a buffer for `axes` axes.
pub(crate) const fn len(axes: usize) -> usize {
    HEADER_WORDS + axes * AXIS_WORDS
}

fn at(i: usize) -> std::ops::Range<usize> {
    HEADER_WORDS + i * AXIS_WORDS..HEADER_WORDS + (i + 1) * AXIS_WORDS
}

// The frames are `#[repr(C)]`, 48 bytes without padding (pinned in
// motion-frames), made of integers and floats only: every bit pattern is a
// valid value, and a value is exactly its six words.

/// The command of axis `i` in `words`.
pub(crate) fn command(words: &[u64], i: usize) -> AxisCommand {
    let mut a = [0u64; AXIS_WORDS];
    a.copy_from_slice(&words[at(i)]);
    // SAFETY: same size, no padding, every bit pattern is a valid value.
    unsafe { core::mem::transmute::<[u64; AXIS_WORDS], AxisCommand>(a) }
}

/// Stores `c` as the command of axis `i`.
pub(crate) fn put_command(words: &mut [u64], i: usize, c: &AxisCommand) {
    // SAFETY: as above; a fully initialised value of the same size.
    let a = unsafe { core::mem::transmute::<AxisCommand, [u64; AXIS_WORDS]>(*c) };
    words[at(i)].copy_from_slice(&a);
}

/// The feedback of axis `i` in `words`.
pub(crate) fn feedback(words: &[u64], i: usize) -> AxisFeedback {
    let mut a = [0u64; AXIS_WORDS];
    a.copy_from_slice(&words[at(i)]);
    // SAFETY: as for commands.
    unsafe { core::mem::transmute::<[u64; AXIS_WORDS], AxisFeedback>(a) }
}

/// Stores `f` as the feedback of axis `i`.
pub(crate) fn put_feedback(words: &mut [u64], i: usize, f: &AxisFeedback) {
    // SAFETY: as for commands.
    let a = unsafe { core::mem::transmute::<AxisFeedback, [u64; AXIS_WORDS]>(*f) };
    words[at(i)].copy_from_slice(&a);
}
