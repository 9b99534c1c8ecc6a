//! Homing attributes of one axis (spec §2) and the axis facts homing depends on.
//!
//! Plain data, `Copy`, no heap: a validated [`AxisConfig`] is moved into the
//! engine once and never changes while the cycle runs. Each enum's
//! spellings (fixed: docs/configuration.md) are its [`spellings!`](crate::spellings) table
//! right below it, in the order a config error lists them.

/// Axis configuration (CIP "Axis Configuration").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisConfiguration {
    /// A controlled axis: the drive closes the loop on our command.
    Servo,
    /// Only a feedback device: position is read, never commanded.
    FeedbackOnly,
    /// No hardware: the command is the position.
    Virtual,
}

crate::spellings!(AxisConfiguration {
    Servo => "servo",
    FeedbackOnly => "feedback_only",
    Virtual => "virtual",
});

/// Drive control mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ControlMode {
    Position,
    Velocity,
    Torque,
}

crate::spellings!(ControlMode {
    Position => "position",
    Velocity => "velocity",
    Torque => "torque",
});

/// Travel mode. A cyclic axis wraps its *axis* position into `[0, unwind)`;
/// the raw (drive) position never wraps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TravelMode {
    Linear,
    Cyclic,
}

crate::spellings!(TravelMode {
    Linear => "linear",
    Cyclic => "cyclic",
});

/// Home Mode attribute: 0 Passive, 1 Active; and the MAH instruction's
/// Absolute mode. The numbers are what the status frame carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HomeMode {
    Passive = 0,
    Active = 1,
    /// An absolute feedback device: sequence Immediate only, no motion; the
    /// reference (the raw → axis offset) is stored by the supervisor and
    /// restored at start-up with [`Axis::restore_reference`](crate::Axis::restore_reference).
    Absolute = 2,
}

// Active first: the default, as the config lists the choices.
crate::spellings!(HomeMode {
    Active => "active",
    Passive => "passive",
    Absolute => "absolute",
});

/// Home Direction attribute (0..=3 in CIP order).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HomeDirection {
    UnidirectionalForward = 0,
    BidirectionalForward = 1,
    UnidirectionalReverse = 2,
    BidirectionalReverse = 3,
}

crate::spellings!(HomeDirection {
    UnidirectionalForward => "unidirectional_forward",
    BidirectionalForward => "bidirectional_forward",
    UnidirectionalReverse => "unidirectional_reverse",
    BidirectionalReverse => "bidirectional_reverse",
});

impl HomeDirection {
    /// +1.0 for the forward forms, -1.0 for the reverse forms.
    pub fn sign(self) -> f64 {
        match self {
            Self::UnidirectionalForward | Self::BidirectionalForward => 1.0,
            Self::UnidirectionalReverse | Self::BidirectionalReverse => -1.0,
        }
    }

    pub fn is_unidirectional(self) -> bool {
        matches!(
            self,
            Self::UnidirectionalForward | Self::UnidirectionalReverse
        )
    }
}

/// Home Sequence attribute (0..=5 in CIP order).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HomeSequence {
    Immediate = 0,
    Switch = 1,
    Marker = 2,
    SwitchThenMarker = 3,
    Torque = 4,
    TorqueThenMarker = 5,
    /// *Ours* (CIP reserves 6..=255): the limit switch in Home Direction is
    /// the reference (CiA 402 methods 17 / 18; PLCopen MC_StepLimitSwitch).
    /// Seek it at Home Speed, stop on it, return off it at Home Return
    /// Speed: the event is where it clears.
    LimitSwitch = 6,
    /// *Ours*: as [`LimitSwitch`](Self::LimitSwitch), then on at Home Return
    /// Speed to the first marker after the clear point, which is the event
    /// (CiA 402 methods 1 / 2).
    LimitSwitchThenMarker = 7,
}

crate::spellings!(HomeSequence {
    Immediate => "immediate",
    Switch => "switch",
    Marker => "marker",
    SwitchThenMarker => "switch_then_marker",
    Torque => "torque",
    TorqueThenMarker => "torque_then_marker",
    LimitSwitch => "limit_switch",
    LimitSwitchThenMarker => "limit_switch_then_marker",
});

impl HomeSequence {
    /// The sequence finds a switch edge: the home switch, or for the
    /// limit-switch sequences the limit switch in Home Direction, which then
    /// plays the home switch's part in every leg (see `plan`).
    pub fn uses_switch(self) -> bool {
        matches!(
            self,
            Self::Switch | Self::SwitchThenMarker | Self::LimitSwitch | Self::LimitSwitchThenMarker
        )
    }
    pub fn uses_marker(self) -> bool {
        matches!(
            self,
            Self::Marker
                | Self::SwitchThenMarker
                | Self::TorqueThenMarker
                | Self::LimitSwitchThenMarker
        )
    }
    /// The reference is the limit switch in Home Direction (the home switch
    /// is not used).
    pub fn uses_limit_switch(self) -> bool {
        matches!(self, Self::LimitSwitch | Self::LimitSwitchThenMarker)
    }
    pub fn uses_torque(self) -> bool {
        matches!(self, Self::Torque | Self::TorqueThenMarker)
    }
}

/// Everything the engine needs to home one axis.
///
/// Units: positions in position units, speeds in units/s, accelerations in
/// units/s², torques in % of rated, times in seconds. `0.0` means "not set"
/// where the field says so.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisConfig {
    // --- axis facts -------------------------------------------------------
    pub configuration: AxisConfiguration,
    pub control_mode: ControlMode,
    pub travel: TravelMode,
    /// Cyclic only: position units per revolution.
    pub unwind: f64,
    /// Conversion constant: feedback counts per position unit.
    pub counts_per_unit: f64,
    /// The feedback device has a marker and the drive latches its position.
    pub marker: bool,
    /// The drive latches the marker position (touch probe). Without a latch
    /// the drive only reports that an index pulse passed in the last cycle,
    /// and the marker is known to one cycle of travel.
    pub marker_latch: bool,
    /// The drive latches its position on the home switch edge (registration).
    pub registration: bool,
    /// The feedback device keeps its position over power cycles (an absolute
    /// encoder): a stored reference stays valid, and Absolute home mode is
    /// possible.
    pub absolute: bool,
    /// Maximum negative / positive travel in axis coordinates, if known.
    pub travel_limits: Option<(f64, f64)>,

    // --- homing attributes (spec §2) ------------------------------------
    pub home_mode: HomeMode,
    pub home_direction: HomeDirection,
    pub home_sequence: HomeSequence,
    /// Home Configuration Bits, bit 1.
    pub home_switch_normally_closed: bool,
    pub home_position: f64,
    pub home_offset: f64,
    pub home_speed: f64,
    pub home_return_speed: f64,
    pub home_acceleration: f64,
    pub home_deceleration: f64,
    pub home_torque_level: f64,
    pub home_torque_threshold: f64,
    pub home_torque_time: f64,
    /// From the Home operation wrapper: `0.0` = no timeout.
    pub home_timeout: f64,

    // --- our additions (documented in the README's config table) ---------
    /// Creep speed (units/s) of the seek / back-off / creep scheme, for drives
    /// without a marker latch: after a marker found at speed, stop and creep
    /// back over it at this speed, so its uncertainty is creep × cycle / 2.
    /// `0.0` = no creep leg. Bidirectional active sequences only.
    pub home_creep_speed: f64,
    /// Longest distance one search leg may travel. `0.0` = derive from the
    /// travel limits (or two revolutions on a cyclic axis); with neither
    /// known the search is unbounded (and `check` warns).
    pub search_limit: f64,
    /// Torque limit the drive runs with normally (both directions, % rated).
    /// Saved and restored around a torque sequence.
    pub torque_limit: f64,
    /// Following-error tolerance the drive runs with normally (units, 0 = off).
    pub position_error_tolerance: f64,
    /// Velocity-error tolerance the drive runs with normally (units/s, 0 = off).
    pub velocity_error_tolerance: f64,
    /// Time the drive gets to report "enabled" after an active start (s).
    pub enable_timeout: f64,
    /// Feedback-loss rule, stated in time so it means the same at any cycle
    /// rate: a leaky bucket of missing-feedback time. Every step without a
    /// fresh valid sample adds the time since the previous step; every step
    /// with one drains `feedback_loss_drain` x that time. The rule trips when
    /// the bucket holds more than this (ns): a dead peer trips within this
    /// plus one cycle, an isolated gap shorter than this never trips.
    pub feedback_timeout_ns: u64,
    /// Drain rate of the feedback-loss bucket per unit of time with fresh
    /// feedback. With `d`, sustained loss of more than `d / (1 + d)` of the
    /// cycles trips eventually (0.25: above 20 %).
    pub feedback_loss_drain: f64,
    /// The nominal time between steps (the controller cycle), ns; 0 = none.
    /// A step that comes later counts one cycle toward the feedback-loss
    /// bucket: a stall of the controller is not the peer's silence.
    pub cycle_ns: u64,
    /// Raw positions beyond ±this (units) are treated as absurd feedback.
    pub max_position: f64,
    /// The fastest the axis can physically move, units/s: feedback that
    /// implies more is implausible (a forged or corrupt frame), never an
    /// event. `0.0` = derive 2 × the fastest homing speed the configured
    /// sequence commands; a sequence that commands none (passive, immediate)
    /// then gets no plausibility check. Also the speed bound of jog, move
    /// and stream: without one they are refused (13 / 7). See
    /// `validate::effective_max_speed`.
    pub max_speed: f64,
    /// Switch-then-marker: a marker closer than this (units) to the switch
    /// edge is ambiguous — with the edge's sampling error (and switch
    /// repeatability) it may be the marker before or after the one intended,
    /// which moves the reference by a whole marker spacing from one homing to
    /// the next. `0.0` = no check. See `refuse_ambiguous_marker`.
    pub marker_min_distance: f64,
    /// An ambiguous marker fails homing (ERR 1018) instead of completing with
    /// the `Status::ambiguous_marker` warning.
    pub refuse_ambiguous_marker: bool,

    // --- the operations around homing (their limits) ----------------------
    /// Speed cap (units/s) of jogs and moves while the axis is not homed
    /// (LinuxCNC jogs unhomed joints, slowly: without a reference no soft
    /// limit protects the machine). `0.0` = `home_speed`. See
    /// `validate::effective_unhomed_speed`.
    pub unhomed_speed: f64,
    /// The axis has overtravel limit switches: motion towards a tripped one
    /// stops (ER 12 / 43) and is refused (ERR 9). `false`: the inputs are
    /// ignored, also by homing (an EtherCAT drive then need not map them).
    pub limit_switches: bool,
    /// Logix "Maximum Deceleration", units/s²: the deceleration of a stop
    /// at a limit switch or after a fault (a stream's stops: at least
    /// `stream_acceleration`), and the most an operation may ask for. `0.0` = the largest deceleration configured
    /// (`home_deceleration`). See `validate::effective_max_deceleration`.
    pub max_deceleration: f64,
    /// Largest change of velocity of the supervised stream, units/s²: of
    /// its segments on the program's timeline (ERR 1019 / 4 above it), and
    /// of the command between two cycles, whatever the timestamps say.
    /// `0.0` = 10 × `home_acceleration`.
    pub stream_acceleration: f64,
    /// The stream stops the axis (ERR 1019 / 5) after this long without a
    /// new setpoint since the last one arrived, ns. `0` = 50 ms.
    pub stream_timeout_ns: u64,
    /// The stream may drive an axis that is not homed (no soft limits then).
    pub stream_unhomed: bool,
    /// `home_reverse_at_limit` (CiA 402 methods 7–14 / 23–30): a bidirectional
    /// switch or switch-then-marker search that reaches the limit switch in
    /// Home Direction before the home switch stops, runs back past the home
    /// switch, stops and searches again, so the event is the same switch
    /// edge approached the same way as from the near side. Validation
    /// refuses it for every other sequence and direction (ERR 41 / EXERR 37).
    pub home_reverse_at_limit: bool,
    /// The drive homes the axis itself (EtherCAT: CiA 402 homing mode 6,
    /// the `[[axis]]` key `drive_homing`): an active sequence's plan is then
    /// one leg "the drive homes" and the move to Home Position (see
    /// `axis::drive_homing`). The drive's homing method and speeds are the
    /// I/O process's to set; the engine only asks and watches.
    pub drive_homing: bool,
}

impl Default for AxisConfig {
    /// CIP defaults where CIP has one (Active, bidirectional forward,
    /// Immediate); zero speeds, which validation rejects for motion sequences.
    fn default() -> Self {
        Self {
            configuration: AxisConfiguration::Servo,
            control_mode: ControlMode::Position,
            travel: TravelMode::Linear,
            unwind: 0.0,
            counts_per_unit: 1.0,
            marker: false,
            marker_latch: true,
            registration: false,
            absolute: false,
            travel_limits: None,
            home_mode: HomeMode::Active,
            home_direction: HomeDirection::BidirectionalForward,
            home_sequence: HomeSequence::Immediate,
            home_switch_normally_closed: false,
            home_position: 0.0,
            home_offset: 0.0,
            home_speed: 0.0,
            home_return_speed: 0.0,
            home_acceleration: 0.0,
            home_deceleration: 0.0,
            home_torque_level: 0.0,
            home_torque_threshold: 0.0,
            home_torque_time: 0.0,
            home_timeout: 0.0,
            home_creep_speed: 0.0,
            search_limit: 0.0,
            torque_limit: 100.0,
            position_error_tolerance: 0.0,
            velocity_error_tolerance: 0.0,
            enable_timeout: 1.0,
            feedback_timeout_ns: 10_000_000,
            feedback_loss_drain: 0.25,
            cycle_ns: 0,
            max_position: 1.0e9,
            max_speed: 0.0,
            marker_min_distance: 0.0,
            refuse_ambiguous_marker: false,
            unhomed_speed: 0.0,
            limit_switches: true,
            max_deceleration: 0.0,
            stream_acceleration: 0.0,
            stream_timeout_ns: 0,
            stream_unhomed: false,
            home_reverse_at_limit: false,
            drive_homing: false,
        }
    }
}
