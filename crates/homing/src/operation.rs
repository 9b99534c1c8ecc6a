//! The operations around homing, as they cross the engine's boundary: what
//! a caller asks for ([`Operation`], in `Request::op`), a program's
//! setpoint ([`Setpoint`], in `Request::setpoint`), and the answer
//! ([`OpStatus`] in `Status::op`, [`StopCause`] in `Status::last_stop`).
//!
//! The anchors are the Logix motion instructions (MSO, MSF, MAFR, MAJ, MAM,
//! MAS) and PLCopen's MC_Power, MC_Reset, MC_Jog, MC_MoveAbsolute /
//! MC_MoveRelative and MC_Stop; the supervised stream is ros2_control's
//! position command interface with the checks a controller owes it. The
//! behaviour lives in `axis::ops`; the ERR / EXERR of a refusal are in
//! [`codes`](crate::codes).
//!
//! Positions here are in **axis** coordinates (the reference HomedStatus
//! stands for; before the first homing, the raw position), speeds in
//! units/s, accelerations in units/s², times in ns.

/// One operation, applied in the step it arrives and answered in
/// `Status::op` of that step (accepted with a new id, or refused with an
/// ERR / EXERR and no effect at all).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Operation {
    /// MSO / MC_Power on: request the power stage on, holding the actual
    /// position (the command follows the actual position while disabled,
    /// so enabling never jumps). IP until the drive reports enabled; an
    /// enable timeout is an axis fault (ER 12 / 42).
    Enable,
    /// MSF / MC_Power off: a moving axis is stopped first (with the
    /// deceleration of the running motion), then the power stage is
    /// switched off; homing in process aborts with ERR 12 / EXERR 1. Always
    /// accepted.
    Disable,
    /// MAFR / MC_Reset: clears the axis's ER / ERR / EXERR and `faulted`,
    /// and asks the drive for a fault reset (`Command::fault_reset`). Never
    /// enables, never moves.
    Reset,
    /// MAJ / MC_Jog, hold to run: runs in the sign of `speed` until stopped
    /// (a stop, a limit, a fault, or the lease running out). `lease_ns`: the
    /// jog stops normally unless `Request::jog_renew` renews it within this
    /// time (an HMI or program that dies never leaves an axis running).
    Jog {
        speed: f64,
        accel: f64,
        decel: f64,
        lease_ns: u64,
    },
    /// MAM / MC_MoveAbsolute (`relative = false`: `target` is an axis
    /// position) or MC_MoveRelative (`relative`: `target` is a distance from
    /// the current command position): a trapezoid ending at rest on the
    /// target (PC). `supersede`: replaces a jog or move in progress (without
    /// it, such an axis refuses with ERR 3). On a cyclic axis an absolute
    /// target is reached the shortest way.
    Move {
        target: f64,
        relative: bool,
        speed: f64,
        accel: f64,
        decel: f64,
        supersede: bool,
    },
    /// The supervised stream starts: from now on the axis follows the
    /// setpoints of `Request::setpoint`, interpolated to the cycle, each one
    /// checked (ERR 1019 when refused).
    StreamStart,
    /// The stream ends (released by its owner, or the owner is gone): the
    /// axis comes to rest, landing on the last setpoint when the
    /// deceleration allows. Always accepted.
    StreamEnd,
    /// MAS / MC_Stop: ends a jog, move or stream normally (no error,
    /// HomedStatus kept, the drive stays enabled) with the deceleration of
    /// the running motion; homing in process ends with ERR 12 / EXERR 1 as a
    /// `Request::stop` does. Always accepted.
    Stop,
}

impl Operation {
    /// The kind, as `Status::op` shows it.
    pub fn kind(&self) -> OpKind {
        match self {
            Operation::Enable => OpKind::Enable,
            Operation::Disable => OpKind::Disable,
            Operation::Reset => OpKind::Reset,
            Operation::Jog { .. } => OpKind::Jog,
            Operation::Move { .. } => OpKind::Move,
            Operation::StreamStart => OpKind::StreamStart,
            Operation::StreamEnd => OpKind::StreamEnd,
            Operation::Stop => OpKind::Stop,
        }
    }
}

/// A NEW setpoint of the supervised stream, handed to the engine in the
/// step it arrived (at most one per step: the newest).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Setpoint {
    /// When the program meant it, ns on the program's own timeline (only
    /// differences count: the interpolation runs from one to the next).
    pub t_ns: u64,
    /// Axis position, units.
    pub position: f64,
    /// Velocity feed-forward, units/s; `None`: the interpolated segment's
    /// velocity is commanded.
    pub velocity: Option<f64>,
}

/// Which operation `Status::op` describes. The numbers are what a status
/// frame carries; the spellings are JSON's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum OpKind {
    /// No operation was asked for since the engine started.
    #[default]
    None = 0,
    Enable = 1,
    Disable = 2,
    Reset = 3,
    Jog = 4,
    Move = 5,
    StreamStart = 6,
    StreamEnd = 7,
    Stop = 8,
}

crate::spellings!(OpKind {
    None => "none",
    Enable => "enable",
    Disable => "disable",
    Reset => "reset",
    Jog => "jog",
    Move => "move",
    StreamStart => "stream_start",
    StreamEnd => "stream_end",
    Stop => "stop",
});

/// The answer to the operations: the last accepted one and its progress,
/// and the refusal of the last one asked for if it was refused.
///
/// A caller that passed an operation in a step reads this after the step:
/// `id` changed → accepted (it is then the operation described); `id`
/// unchanged → refused, `refused` holds the ERR / EXERR. A refusal is the
/// instruction's error, not an axis fault: it sets nothing else and leaves
/// the running operation (and the axis's ER) as they were.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpStatus {
    /// Incremented by the engine for every accepted operation (0: none yet).
    pub id: u32,
    /// Kind of the operation `id`.
    pub kind: OpKind,
    /// In process: the operation is running (enabling, jogging, moving,
    /// streaming, stopping, disabling, resetting).
    pub ip: bool,
    /// Process complete: it ended as meant — enabled; disabled; reset (the
    /// drive reports no fault); a move at its target; a jog ended normally
    /// (stop, lease, soft limit) and at rest; a stream released and at
    /// rest; a stop at rest. Both IP and PC false after an end by a fault.
    pub pc: bool,
    /// ERR / EXERR of the last operation asked for, when it was refused
    /// (`None` once one is accepted).
    pub refused: Option<(u16, u16)>,
}

/// Why the last jog, move or stream ended (or the axis was last brought to
/// rest by an operation). The numbers are what a status frame carries; the
/// spellings are JSON's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum StopCause {
    /// Nothing was stopped since the engine started.
    #[default]
    None = 0,
    /// A stop (MAS): `Operation::Stop` or `Request::stop`. Normal.
    Operator = 1,
    /// The jog's lease ran out (hold to run). Normal; the code 1020 / 0 is
    /// only logged.
    LeaseExpired = 2,
    /// A jog came to rest at a software travel limit. Normal.
    SoftLimit = 3,
    /// A hardware limit switch was hit while moving towards it: ER 12 / 43.
    LimitSwitch = 4,
    /// The drive faulted or dropped its power stage, or did not enable in
    /// time: ER 12 / 16 (12 / 42).
    DriveFault = 5,
    /// Feedback lost, invalid or implausible while moving: ER 12 / 40
    /// (41, 44).
    FeedbackLost = 6,
    /// The stream stopped the axis: a setpoint refused, the stream silent,
    /// or the axis no longer homed: ER 1019 / x.
    SetpointRefused = 7,
    /// `Operation::Disable` stopped the axis before switching it off. Normal.
    Disable = 8,
    /// The stream's owner released it (or is gone). Normal.
    Released = 9,
    /// `Request::shutdown`: the power stage was switched off at once.
    Shutdown = 10,
    /// The cycle monitor stopped the axis (ER 1021 / x): a command broke
    /// one of its invariants.
    Monitor = 11,
}

crate::spellings!(StopCause {
    None => "none",
    Operator => "operator",
    LeaseExpired => "lease_expired",
    SoftLimit => "soft_limit",
    LimitSwitch => "limit_switch",
    DriveFault => "drive_fault",
    FeedbackLost => "feedback_lost",
    SetpointRefused => "setpoint_refused",
    Disable => "disable",
    Released => "released",
    Shutdown => "shutdown",
    Monitor => "monitor",
});

impl StopCause {
    /// A normal end (no axis fault): stop, lease, soft limit, disable,
    /// release.
    pub fn is_normal(self) -> bool {
        matches!(
            self,
            Self::Operator | Self::LeaseExpired | Self::SoftLimit | Self::Disable | Self::Released
        )
    }
}
