//! The Motion Axis Home instruction's status (EN, DN, ER, IP, PC, ERR, EXERR)
//! and the axis status bits homing drives (HomingStatus, HomedStatus);
//! the axis bits and the answer of the operations around homing.

use crate::operation::{OpStatus, StopCause};

/// Where the engine is in a sequence, derived from the state machine's state
/// (the leg of the plan it runs). Names (the spellings table below) are
/// shown to operators and the numbers are kept stable; the EXERR of a
/// search-limit failure has its own explicit mapping in [`codes`](crate::codes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u16)]
pub enum Phase {
    /// Not homing; holding (or tracking the actual position while disabled).
    #[default]
    Idle = 0,
    /// Active start: waiting for the drive to report enabled.
    Enabling = 1,
    /// First leg at Home Speed, searching for the first event.
    Seek = 2,
    /// Decelerating after the first leg's event.
    SeekStop = 3,
    /// Backing the command out of a hard stop before anything else moves.
    Release = 4,
    /// Leg at Home Return Speed (switch clear, marker after switch or torque).
    Return = 5,
    /// Decelerating after the return leg's event.
    ReturnStop = 6,
    /// Trapezoidal move to Home Position.
    MoveHome = 7,
    /// Passive: waiting for an external agent to produce the event.
    Passive = 8,
    /// Aborted: decelerating to rest, then restoring overridden drive values.
    Stopping = 9,
    /// Creeping back over a marker found at speed (drives without a latch).
    Creep = 10,
    /// `home_reverse_at_limit`: a limit switch ended the seek before the home
    /// switch; running back at Home Speed past the home switch, to search
    /// again from its near side.
    Reverse = 11,
    /// The drive runs its own homing (`drive_homing`, CiA 402 mode 6).
    DriveHoming = 12,
}

crate::spellings!(Phase {
    Idle => "idle",
    Enabling => "enabling",
    Seek => "seek",
    SeekStop => "seek_stop",
    Release => "release",
    Return => "return",
    ReturnStop => "return_stop",
    MoveHome => "move_home",
    Passive => "passive",
    Stopping => "stopping",
    Creep => "creep",
    Reverse => "reverse",
    DriveHoming => "drive_homing",
});

/// Feedback refused as implausible, by kind, counted over the axis's life.
/// Each one is a frame that was forged, corrupt, or from a broken encoder;
/// none ever became an event.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Implausible {
    /// Samples whose position moved further since the previous plausible
    /// one than `max_speed` allows (not used; ERR 12 / EXERR 44 while homing).
    pub jumps: u32,
    /// Marker latch positions outside the travel since the latch was armed
    /// (ignored, latch re-armed).
    pub marker_latches: u32,
    /// Registration (switch) latch positions outside the travel since arming
    /// (ignored: the sampled edge is used).
    pub switch_latches: u32,
}

/// Instruction and axis status after a cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Status {
    /// EN: request seen; cleared when the request drops after DN or ER.
    pub en: bool,
    /// DN: the instruction finished (completed, or aborted / errored).
    pub dn: bool,
    /// ER: the instruction detected an error, the codes below say which.
    pub er: bool,
    /// ERR / EXERR of that error ([`codes`](crate::codes)).
    pub err: u16,
    pub exerr: u16,
    /// IP: homing in process.
    pub ip: bool,
    /// PC: process complete — homed *and* at Home Position where the
    /// sequence moves there. A unidirectional sequence that could not reach
    /// Home Position without reversing clears IP without PC.
    pub pc: bool,
    /// Axis HomingStatus.
    pub homing: bool,
    /// Axis HomedStatus: the machine reference is established.
    pub homed: bool,
    /// Axis StoppingStatus: decelerating after an abort.
    pub stopping: bool,
    pub phase: Phase,
    /// Raw position of the home event, once found.
    pub event_raw: Option<f64>,
    /// The raw → axis offset in force when this homing started, if the axis
    /// was homed then: the event in that earlier reference is
    /// `event_raw + prior_offset`, which is what a drift check compares.
    pub prior_offset: Option<f64>,
    /// Command position (raw) in the cycle the event was detected: where the
    /// axis latched in the common command frame of a coordinated machine.
    pub event_command: Option<f64>,
    /// Raw position of the switch edge found by a switch-then-marker
    /// sequence (the marker beyond it is the event).
    pub switch_edge_raw: Option<f64>,
    /// Warning: the marker of a switch-then-marker sequence lay closer than
    /// `marker_min_distance` to the switch edge (homing completed; with
    /// `refuse_ambiguous_marker` it fails with ERR 1018 instead).
    pub ambiguous_marker: bool,
    /// Index of the current leg in the sequence's [plan](crate::plan) (the
    /// last one reached, once homing has ended).
    pub leg: u8,
    /// At rest at a barrier (`Request::hold`), ready to start leg `leg`.
    pub waiting: bool,
    /// While waiting before the move to Home Position: the shortest that move
    /// can take, ns (0 otherwise, and when there is no move to make).
    pub min_move_ns: u64,
    /// Distance travelled in the current (or last) search leg, units: the
    /// command's for a commanded search, checked against the search limit;
    /// the actual position's for a passive watch.
    pub search_travel: f64,
    /// The feedback attribute that was invalid (ERR 12 / EXERR 41).
    pub bad_attribute: Option<&'static str>,
    /// Monotonic time homing started and finished, ns.
    pub started_ns: u64,
    pub finished_ns: Option<u64>,
    /// Feedback is usable: the feedback-loss rule has not tripped since the
    /// last fresh valid sample.
    pub feedback_ok: bool,
    /// Length of the current feedback gap: time since the last step with a
    /// fresh valid sample, ns (0 in a step that had one).
    pub feedback_gap_ns: u64,
    /// Content of the feedback-loss bucket (missing time not yet drained),
    /// ns; the rule trips above `feedback_timeout_ns`. Next to
    /// `feedback_gap_ns` it tells a dead peer (both large) from intermittent
    /// loss (a short gap on a full bucket).
    pub feedback_loss_ns: u64,
    /// When the feedback-loss rule tripped (HomedStatus cleared, ERR 12 /
    /// EXERR 40 while homing): the gap at that moment, ns. Cleared when
    /// homing starts.
    pub lost_after_ns: Option<u64>,
    /// Implausible feedback refused so far.
    pub implausible: Implausible,

    // --- the operations around homing (see `operation`) ----------------
    // `er` / `err` / `exerr` above also carry an axis fault (a drive
    // fault, a limit switch, a refused setpoint, lost feedback while
    // moving), which `Operation::Reset` clears; `stopping` is also set
    // while an operation's motion comes to rest.
    /// ServoActionStatus: the power stage is requested on and the drive
    /// reports it enabled (and not faulted).
    pub servo_action: bool,
    /// JogStatus: a jog runs (until its stop begins).
    pub jogging: bool,
    /// MoveStatus: a move runs (until its stop begins).
    pub moving: bool,
    /// The supervised stream drives the axis.
    pub streaming: bool,
    /// The hardware limit switch inputs (false when `limit_switches` is off).
    pub limit_negative: bool,
    pub limit_positive: bool,
    /// An axis fault is present (the ER of a drive fault, limit switch,
    /// refused setpoint, lost feedback while moving, enable timeout): home,
    /// enable, jog, move and stream are refused (ERR 20) until `Reset`.
    pub faulted: bool,
    /// Why the last jog, move or stream ended.
    pub last_stop: StopCause,
    /// The last accepted operation and its progress, and the refusal of
    /// the last one asked for.
    pub op: OpStatus,
    /// `home_reverse_at_limit`: this homing met the limit switch in Home
    /// Direction before the home switch and reversed its search.
    pub reversed_at_limit: bool,
    /// The I/O process reports the axis's drive lost (`Request::drive_lost`):
    /// not a reading, not enabled, whatever the last feedback said.
    pub drive_lost: bool,
    /// Redefine position accepted over the axis's life (the keeper records
    /// each and stores an absolute axis's reference after it).
    pub redefines: u32,
    /// The shift redefine position applied since the reference was
    /// established (homing, or a stored reference): the soft limits read
    /// `travel_limits` + `shift`, so they stay where they are on the machine.
    pub shift: f64,
    /// The software travel limits in axis coordinates while they are in
    /// force (homed, linear, configured): `travel_limits` + `shift`.
    pub soft_limits: Option<(f64, f64)>,
    /// A registration (MAR, `Operation::Arm`) is armed: the next edge of
    /// its input (inside its window) will be latched. Cleared when it
    /// latched, by `Operation::Disarm`, and when a homing starts.
    pub registration_armed: bool,
    /// Axis position of the edge the last registration latched (`None`
    /// from an arming until it latched).
    pub registration_position: Option<f64>,
    /// GearingStatus: the axis follows its master (MAG), from the accepted
    /// gear (a clutch ramping in included) until its stop begins.
    pub gearing: bool,
}
