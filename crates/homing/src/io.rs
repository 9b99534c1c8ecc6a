//! What crosses the engine's boundary each cycle: [`Feedback`] and
//! [`Request`] in, [`Command`] out. Positions are *raw* (the drive's frame,
//! never redefined and never wrapped) in position units; the engine keeps the
//! axis-position offset itself. The operations' types are in
//! [`operation`](crate::operation).

use crate::operation::{MasterFeed, Operation, Setpoint};

/// A position latch as the drive reports it (CiA 402 touch probe style).
///
/// The engine arms a latch by sending a new non-zero `id`; the drive answers
/// with the same `id` once armed, and sets `latched` with the exact position of
/// the first qualifying edge after arming. Matching ids make a latch from an
/// earlier arming impossible to mistake for a new one, whatever the frame delay.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LatchFeedback {
    /// Id of the arm request this state belongs to (0 = disarmed).
    pub id: u8,
    pub latched: bool,
    /// Raw position of the latched edge, units.
    pub position: f64,
}

/// Drive state bits the engine reacts to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DriveState {
    /// Power stage on and following the command.
    pub enabled: bool,
    /// Drive fault (following error, overload, …): it no longer follows.
    pub fault: bool,
}

/// One cycle's feedback for one axis.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Feedback {
    /// Raw actual position, units.
    pub position: f64,
    /// Actual velocity, units/s.
    pub velocity: f64,
    /// Actual torque, % rated, signed (positive pushes forward).
    pub torque: f64,
    /// Electrical level of the home switch input (true = contact closed).
    pub home_switch: bool,
    /// Hardware overtravel inputs (true = tripped).
    pub overtravel_positive: bool,
    pub overtravel_negative: bool,
    pub marker_latch: LatchFeedback,
    pub switch_latch: LatchFeedback,
    /// An index pulse passed during the last cycle. Drives without a marker
    /// position latch report only this (`marker_latch = false` in the
    /// config); the engine then knows the marker to one cycle of travel.
    pub marker_pulse: bool,
    pub drive: DriveState,
    /// The drive's own homing (`drive_homing` axes), as it reports it.
    pub drive_homing: DriveHoming,
}

/// The drive's own homing (CiA 402 homing mode), as the drive reports it
/// while the engine asks for it (`Command::drive_home`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DriveHoming {
    /// The drive runs its homing for this request (or has just finished it,
    /// or is still leaving homing mode): the drive, not the command, moves
    /// the axis, and the command follows the actual position.
    pub active: bool,
    /// Homing attained: the drive found its home and redefined its
    /// position (the home point is its position 0), and is at rest.
    pub attained: bool,
    /// The drive reports a homing error (or did not take homing mode).
    pub error: bool,
}

/// Which electrical edge of the home switch input a registration latch takes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Edge {
    /// Input goes from open to closed.
    #[default]
    Rising,
    /// Input goes from closed to open.
    Falling,
}

/// Arm request for a drive latch.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LatchArm {
    /// 0 = disarmed; any other value arms, a new value re-arms.
    pub id: u8,
    pub edge: Edge,
}

/// One cycle's command for one axis.
///
/// Every field is always finite: the engine never derives a command from
/// unvalidated feedback.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Command {
    /// Request the power stage on.
    pub enable: bool,
    /// Raw position set-point, units.
    pub position: f64,
    /// Velocity set-point / feed-forward, units/s.
    pub velocity: f64,
    /// Torque limits in force, % rated (positive direction, negative direction),
    /// both given as magnitudes.
    pub torque_limit_positive: f64,
    pub torque_limit_negative: f64,
    /// Error tolerances in force (0 = check off).
    pub position_error_tolerance: f64,
    pub velocity_error_tolerance: f64,
    pub marker_arm: LatchArm,
    pub switch_arm: LatchArm,
    /// Ask the drive for a fault reset (MAFR; CiA 402 control word bit 7):
    /// set after `Operation::Reset` for at least three steps and until the
    /// drive reports no fault (at most `enable_timeout`), so the drive sees
    /// a rising edge however the frames are timed.
    pub fault_reset: bool,
    /// Ask the drive to home the axis itself (a `drive_homing` axis in its
    /// drive-homing leg): set for the whole leg, cleared to end it.
    pub drive_home: bool,
}

/// Control inputs for one cycle, as a PLC program would drive the MAH rung.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Request {
    /// Rung condition of the Home instruction: a rising edge starts homing.
    pub home: bool,
    /// Stop (MAS): aborts homing with ERR 12 / EXERR 1 and stops the axis.
    pub stop: bool,
    /// Shutdown (MASD): aborts with ERR 12 / EXERR 12, disables the drive,
    /// clears HomedStatus. Level: the axis stays shut down while set.
    pub shutdown: bool,

    // --- coordination (gantries, home order); the defaults coordinate nothing
    /// Barrier: while set, an axis that has finished a leg waits at rest
    /// before starting its next leg that moves (`Status::waiting`), and
    /// starts it in the first cycle `hold` is clear. A coordinator keeps it
    /// set and clears it for one cycle when every axis it synchronises
    /// waits: their legs then start in the same cycle. Legs that begin in
    /// motion (the stop after an event, a unidirectional continue) never wait.
    pub hold: bool,
    /// If non-zero when the move to Home Position starts from rest, that move
    /// lasts exactly this long (ns): the trapezoid is slowed down, never made
    /// faster than its own minimum (`Status::min_move_ns`). Gantry sides whose
    /// offsets differ thus start and end their final move together.
    pub move_duration_ns: u64,
    /// The ERR / EXERR a stop rising edge reports instead of 12 / 1 (e.g. 12 /
    /// 1 for "home-all aborted because another axis failed", or 1017 / 0 for
    /// gantry skew).
    pub stop_code: Option<(u16, u16)>,
    /// The supervisor woke late for this cycle (its CPU was stalled): a
    /// missing sample is excused, within a bound, by the feedback-loss rule
    /// (see `axis::loss`).
    pub stalled: bool,

    // --- the operations around homing (see `operation`) ----------------
    /// An operation, applied in this step and answered in `Status::op`.
    pub op: Option<Operation>,
    /// A NEW setpoint of the supervised stream that arrived this cycle (the
    /// newest one; `None`: nothing new). Used only while streaming.
    pub setpoint: Option<Setpoint>,
    /// The jog's client renewed its lease this cycle: it runs until
    /// `now + lease_ns` at least.
    pub jog_renew: bool,
    /// The I/O process reports the axis's drive lost (its fieldbus device
    /// stopped answering or left operation) while motion-io itself is
    /// alive: the loss of feedback that follows names the drive (ERR 12 /
    /// EXERR 45) instead of the I/O process, and the status shows it.
    pub drive_lost: bool,
    /// A geared slave's master, this cycle (`None`: not geared, or the
    /// cycle has nothing of it): what the slave follows.
    pub master: Option<MasterFeed>,
}
