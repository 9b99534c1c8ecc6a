//! The drive backend: what sits behind the frames of a drive-I/O process.
//! `motion-io`'s `sim` backend simulates the axes; `motion-ethercat`'s
//! `EthercatBackend` drives CiA 402 drives on an EtherCAT bus; another
//! fieldbus master (CANopen, ...) would implement the same trait.
//!
//! The trait lives here, beside the frames it takes and returns, so that the
//! `motion-io` binary and the backend crates share one definition of it and
//! of [`ExchangeError`] (a backend crate cannot depend on a binary).

use std::fmt;

use crate::{CommandFrame, FeedbackFrame};

/// Why [`Backend::exchange`] did not apply a command frame. The feedback is
/// still filled (the backend's own axes), so the supervisor sees the state.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ExchangeError {
    /// The frame carries another number of axes than the backend drives: the
    /// two processes use different configs; applying it could drive the wrong
    /// axis.
    AxisCountMismatch { frame: usize, ours: usize },
}

impl fmt::Display for ExchangeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ExchangeError::AxisCountMismatch { frame, ours } => write!(
                f,
                "command frame has {frame} axes, config has {ours}: ignoring commands \
                 (are both processes using the same config?)"
            ),
        }
    }
}

/// Upper bound of [`Backend::watchdog_stop`] calls [`Backend::shutdown`]
/// makes before it falls back to [`Backend::emergency_stop`]. At 1 kHz that
/// is 100 s of deceleration, far beyond any sane configuration.
pub const MAX_STOP_CYCLES: u32 = 100_000;

/// One set of drives, exchanged with once per cycle.
///
/// Axis `i` of a frame is axis `i` of the backend (config order); the
/// backend fills `fb.header.axis_count` and `fb.axes[..axis_count]`. The
/// caller owns the rest of the frame (`answers_sequence`, `io_received_ns`;
/// `layout_version`, `sequence` and `timestamp_ns` are stamped when it is
/// published). `fb` is the shared-memory sample itself, already zeroed.
///
/// # What an implementation must guarantee
///
/// * **Bounded time, never block.** [`exchange`](Self::exchange),
///   [`watchdog_stop`](Self::watchdog_stop) and [`status`](Self::status) run
///   once per cycle between receiving a command and answering it; the
///   supervisor measures that round trip against its cycle. A fieldbus
///   backend hands the frame to its bus cycle (e.g. the process image of an
///   EtherCAT master running in its own real-time thread, through a lock-free
///   double buffer) and returns the newest inputs it has; it never waits for
///   a bus round trip, a mutex held by a non-real-time thread, a file or a
///   socket, and does not allocate on the heap in steady state.
/// * **Never panic on data.** Frames come from another process: NaN or huge
///   set-points, odd control bits and out-of-range latch ids must be handled
///   (a real drive rejects a bad set-point by faulting). The frame header was
///   checked already ([`crate::FrameHeader::check`]); the axis count
///   is the backend's to compare.
/// * **Units on the wire are counts** (positions), counts/s (velocities),
///   % rated (torque); [`crate::convert`] maps them to position units
///   with the axis' `counts_per_unit` where the backend needs units.
/// * **Honest feedback.** Every field reflects the drive: the enabled and
///   fault bits, latch ids echoed exactly as the drive reports them, a latch
///   position exactly as latched. Feedback of a drive that did not answer this
///   cycle is the last known one, never an invented value.
/// * **Controlled stop on loss of commands.** When the supervisor falls
///   silent the caller calls [`watchdog_stop`](Self::watchdog_stop) every
///   cycle until it returns `true`: every enabled axis decelerates to rest
///   (a real drive: quick-stop / the fieldbus watchdog's stop reaction), is
///   then disabled and reports a fault, so the supervisor sees why it dropped
///   out. The fault is reset by the usual enable false → true handshake of a
///   later command.
pub trait Backend {
    /// Short name for messages ("sim").
    fn name(&self) -> &str;

    /// Number of axes this backend drives (≤ [`crate::MAX_AXES`]).
    fn axis_count(&self) -> usize;

    /// Axis names in frame order, for messages.
    fn axis_names(&self) -> Vec<String>;

    /// One cycle: apply `cmd` to the drives and fill `fb` with their feedback.
    /// A command that cannot be applied (the axis count does not match: the
    /// two processes use different configs) is not applied at all; `fb` is
    /// still filled and the reason returned. The check is made here, once,
    /// for every backend; [`apply`](Self::apply) does the rest.
    fn exchange(
        &mut self,
        cmd: &CommandFrame,
        fb: &mut FeedbackFrame,
    ) -> Result<(), ExchangeError> {
        let (theirs, ours) = (cmd.header.axis_count as usize, self.axis_count());
        if theirs != ours {
            self.status(fb);
            return Err(ExchangeError::AxisCountMismatch {
                frame: theirs,
                ours,
            });
        }
        self.apply(cmd, fb)
    }

    /// [`exchange`](Self::exchange) once the frame is known to carry this
    /// backend's axis count.
    fn apply(&mut self, cmd: &CommandFrame, fb: &mut FeedbackFrame) -> Result<(), ExchangeError>;

    /// Commands have stopped: one cycle (`dt_s` seconds) of bringing every
    /// axis to a controlled stop, then disabling it with a communication
    /// fault. Fills `fb`. Returns `true` once every axis is at rest (then
    /// further calls change nothing and just report the state). A later
    /// [`exchange`](Self::exchange) ends the stop.
    fn watchdog_stop(&mut self, dt_s: f64, fb: &mut FeedbackFrame) -> bool;

    /// Fills `fb` with the current state without changing anything.
    fn status(&self, fb: &mut FeedbackFrame);

    /// Immediate stop: disable every axis now (power stage off, a fault
    /// reported), without a deceleration ramp. Last resort.
    fn emergency_stop(&mut self, fb: &mut FeedbackFrame);

    /// A summary for the log when the process ends (bus counters and the
    /// like); `None`: nothing to say.
    fn summary(&self) -> Option<String> {
        None
    }

    /// The process is shutting down: a controlled stop of every axis now,
    /// bounded in time. The default runs [`watchdog_stop`](Self::watchdog_stop)
    /// for at most [`MAX_STOP_CYCLES`] cycles of `dt_s` and falls back to
    /// [`emergency_stop`](Self::emergency_stop). A simulated backend can do
    /// that instantly; a real one would pace the calls with its bus cycle.
    /// Returns `true` if the controlled stop completed.
    fn shutdown(&mut self, dt_s: f64, fb: &mut FeedbackFrame) -> bool {
        for _ in 0..MAX_STOP_CYCLES {
            if self.watchdog_stop(dt_s, fb) {
                return true;
            }
        }
        self.emergency_stop(fb);
        false
    }
}
