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
//! An operation with parameters carries its spec (`JogSpec`, `MoveSpec`,
//! written with [`op_spec!`](crate::op_spec)): declared here once, with
//! how every layer outside the engine carries and offers each parameter
//! ([`params`](crate::params)); the control request, the core, OPC UA,
//! Python and motionctl carry it unchanged, and the engine fills what was
//! left out from the axis's configuration as it arrives
//! ([`Operation::resolve`]).
//!
//! Positions here are in **axis** coordinates (the reference HomedStatus
//! stands for; before the first homing, the raw position), speeds in
//! units/s, accelerations in units/s², times in ns.

use crate::config::AxisConfig;
use crate::params::{AxisRef, Carried, Fallback, Form, Param, Refused, Spec, Unit, Why};

/// Declares [`Operation`], its verbs [`OpKind`] (one row each: the
/// number a status frame carries, the spelling, the OPC UA method's name,
/// and what the layers around the engine need to know of it), their
/// spellings, and the dispatch from a kind to its spec. A new operation is
/// a row here and its spec type; everything else derives from both.
macro_rules! operations {
    ($(
        $(#[doc = $doc:literal])*
        $variant:ident $( ( $spec:ident ) )? = $num:literal {
            name: $name:literal,
            title: $title:literal,
            client: $client:literal,
            moves: $moves:literal,
            held: $held:literal,
            all: $all:literal,
            summary: $summary:literal $(,)?
        }
    )*) => {
        /// One operation, applied in the step it arrives and answered in
        /// `Status::op` of that step (accepted with a new id, or refused
        /// with an ERR / EXERR and no effect at all). One with parameters
        /// carries its spec, unchanged from the client that asked.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub enum Operation {
            $( $(#[doc = $doc])* $variant $( ($spec) )?, )*
        }

        /// Which operation: the verbs. The numbers are what a status frame
        /// and a control request carry; the spellings are JSON's.
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
        #[repr(u8)]
        pub enum OpKind {
            /// No operation was asked for since the engine started.
            #[default]
            None = 0,
            $( $variant = $num, )*
        }

        crate::spellings!(OpKind {
            None => "none",
            $( $variant => $name, )*
        });

        impl OpKind {
            /// Every operation, in the table's order.
            pub const ALL: &'static [OpKind] = &[$( OpKind::$variant ),*];

            /// Its row of the table.
            pub const fn traits(self) -> OpTraits {
                match self {
                    OpKind::None => OpTraits::NONE,
                    $( OpKind::$variant => OpTraits {
                        title: $title,
                        client: $client,
                        moves: $moves,
                        held: $held,
                        all_by_default: $all,
                        summary: $summary,
                    }, )*
                }
            }

            /// Its parameters (none for most).
            pub fn params(self) -> &'static [Param] {
                match self {
                    OpKind::None => &[],
                    $( OpKind::$variant => spec_params!($($spec)?), )*
                }
            }
        }

        impl Operation {
            /// The kind, as `Status::op` shows it.
            pub fn kind(&self) -> OpKind {
                match self {
                    $( Operation::$variant $( (wild!($spec)) )? => OpKind::$variant, )*
                }
            }

            /// The operation of `kind` with the carried parameters `c`
            /// (what a client sent).
            pub fn take(kind: OpKind, c: &Carried) -> Result<Operation, Refused> {
                match kind {
                    OpKind::None => Err(Refused { param: "kind", why: Why::NotAnOperation }),
                    $( OpKind::$variant => take_op!(c, $variant $(, $spec)?), )*
                }
            }

            fn spec(&self) -> Option<&dyn Carrier> {
                match self {
                    $( Operation::$variant $( (bind!(s, $spec)) )? => some_spec!(s $(, $spec)?), )*
                }
            }

            fn spec_mut(&mut self) -> Option<&mut dyn Carrier> {
                match self {
                    $( Operation::$variant $( (bind!(s, $spec)) )? => some_spec!(s $(, $spec)?), )*
                }
            }
        }
    };
}

/// What the layers around the engine need to know of an operation: its
/// row of the [`operations!`] table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OpTraits {
    /// Its OPC UA method's name.
    pub title: &'static str,
    /// A client may ask for it (the control service, OPC UA, Python,
    /// motionctl): the others are the daemon's own (the stream's start and
    /// end go with its acquire and release; a client stops with the
    /// control service's stop).
    pub client: bool,
    /// It moves the axis (or takes it over to be moved, or redefines where
    /// it is): the cycle refuses it on an axis a program owns, that a home sequence will start or
    /// whose I/O process is not attached, and a gantry takes it on every
    /// side or on none.
    pub moves: bool,
    /// Hold to run: it runs while its client renews it (a token names it),
    /// on one axis or one gantry.
    pub held: bool,
    /// Asked for without naming an axis, it applies to every axis (else it
    /// needs one).
    pub all_by_default: bool,
    /// What it does, in a line (OPC UA's method description).
    pub summary: &'static str,
}

impl OpTraits {
    /// [`OpKind::None`]'s: nothing.
    const NONE: OpTraits = OpTraits {
        title: "",
        client: false,
        moves: false,
        held: false,
        all_by_default: false,
        summary: "",
    };
}

impl OpKind {
    /// See [`OpTraits::title`].
    pub const fn title(self) -> &'static str {
        self.traits().title
    }
    /// See [`OpTraits::client`].
    pub const fn client(self) -> bool {
        self.traits().client
    }
    /// See [`OpTraits::moves`].
    pub const fn moves(self) -> bool {
        self.traits().moves
    }
    /// See [`OpTraits::held`].
    pub const fn held(self) -> bool {
        self.traits().held
    }
    /// See [`OpTraits::all_by_default`].
    pub const fn all_by_default(self) -> bool {
        self.traits().all_by_default
    }
    /// See [`OpTraits::summary`].
    pub const fn summary(self) -> &'static str {
        self.traits().summary
    }
}

/// `_` for a variant's spec in a pattern.
macro_rules! wild {
    ($spec:ident) => {
        _
    };
}

/// The binding `$s` for a variant's spec in a pattern.
macro_rules! bind {
    ($s:ident, $spec:ident) => {
        $s
    };
}

/// The spec bound as `$s`, if the variant has one.
macro_rules! some_spec {
    ($s:ident) => {
        None
    };
    ($s:ident, $spec:ident) => {
        Some($s)
    };
}

macro_rules! spec_params {
    () => {
        &[]
    };
    ($spec:ident) => {
        <$spec as Spec>::PARAMS
    };
}

macro_rules! take_op {
    ($c:ident, $variant:ident) => {
        Ok(Operation::$variant)
    };
    ($c:ident, $variant:ident, $spec:ident) => {
        <$spec as Spec>::take($c).map(Operation::$variant)
    };
}

/// What [`Operation`] needs of a spec without knowing its type.
trait Carrier {
    fn carry_dyn(&self, c: &mut Carried);
    fn resolve_dyn(&mut self, cfg: &AxisConfig);
    fn resolve_axes_dyn(
        &mut self,
        lookup: &mut dyn FnMut(&str) -> Option<u16>,
    ) -> Result<(), Refused>;
}

impl<T: Spec> Carrier for T {
    fn carry_dyn(&self, c: &mut Carried) {
        self.carry(c);
    }
    fn resolve_dyn(&mut self, cfg: &AxisConfig) {
        self.resolve(cfg);
    }
    fn resolve_axes_dyn(
        &mut self,
        lookup: &mut dyn FnMut(&str) -> Option<u16>,
    ) -> Result<(), Refused> {
        self.resolve_axes(lookup)
    }
}

impl Operation {
    /// Its parameters as a client carries them ([`Carried::EMPTY`] for
    /// none).
    pub fn carried(&self) -> Carried {
        let mut c = Carried::EMPTY;
        if let Some(s) = self.spec() {
            s.carry_dyn(&mut c);
        }
        c
    }

    /// Its parameters left out, from the axis's configuration: the one
    /// place defaults are resolved (the engine does it as the operation
    /// arrives, `Axis::operation`).
    pub fn resolve(&mut self, cfg: &AxisConfig) {
        if let Some(s) = self.spec_mut() {
            s.resolve_dyn(cfg);
        }
    }

    /// Its axis parameters named by a client: their indices by `lookup`
    /// (the control thread, which has the machine's names).
    pub fn resolve_axes(
        &mut self,
        lookup: &mut dyn FnMut(&str) -> Option<u16>,
    ) -> Result<(), Refused> {
        match self.spec_mut() {
            Some(s) => s.resolve_axes_dyn(lookup),
            None => Ok(()),
        }
    }
}

operations! {
    /// MSO / MC_Power on: request the power stage on, holding the actual
    /// position (the command follows the actual position while disabled,
    /// so enabling never jumps). IP until the drive reports enabled; an
    /// enable timeout is an axis fault (ER 12 / 42).
    Enable = 1 {
        name: "enable",
        title: "Enable",
        client: true,
        moves: false,
        held: false,
        all: true,
        summary: "MSO: enable the drive, holding position",
    }
    /// MSF / MC_Power off: a moving axis is stopped first (with the
    /// deceleration of the running motion), then the power stage is
    /// switched off; homing in process aborts with ERR 12 / EXERR 1. Always
    /// accepted.
    Disable = 2 {
        name: "disable",
        title: "Disable",
        client: true,
        moves: false,
        held: false,
        all: true,
        summary: "MSF: disable the drive (a moving axis is stopped first)",
    }
    /// MAFR / MC_Reset: clears the axis's ER / ERR / EXERR and `faulted`,
    /// and asks the drive for a fault reset (`Command::fault_reset`). Never
    /// enables, never moves.
    Reset = 3 {
        name: "reset",
        title: "Reset",
        client: true,
        moves: false,
        held: false,
        all: true,
        summary: "MAFR: clear the axis's error and ask the drive for a fault reset",
    }
    /// MAJ / MC_Jog, hold to run ([`JogSpec`]).
    Jog(JogSpec) = 4 {
        name: "jog",
        title: "Jog",
        client: true,
        moves: true,
        held: true,
        all: false,
        summary: "MAJ, hold to run: jog this axis while called again within Duration",
    }
    /// MAM / MC_MoveAbsolute, MC_MoveRelative ([`MoveSpec`]).
    Move(MoveSpec) = 5 {
        name: "move",
        title: "Move",
        client: true,
        moves: true,
        held: false,
        all: false,
        summary: "MAM: a move to Target (or by it), S-curve with a Jerk; done when MoveStatus drops",
    }
    /// The supervised stream starts: from now on the axis follows the
    /// setpoints of `Request::setpoint`, interpolated to the cycle, each one
    /// checked (ERR 1019 when refused).
    StreamStart = 6 {
        name: "stream_start",
        title: "StreamStart",
        client: false,
        moves: true,
        held: false,
        all: false,
        summary: "the supervised setpoint stream starts",
    }
    /// The stream ends (released by its owner, or the owner is gone): the
    /// axis stops at once from where its command is (a program that
    /// releases at rest on its last setpoint finds it there). Always
    /// accepted.
    StreamEnd = 7 {
        name: "stream_end",
        title: "StreamEnd",
        client: false,
        moves: false,
        held: false,
        all: false,
        summary: "the supervised setpoint stream ends",
    }
    /// MAS / MC_Stop: ends a jog, move or stream normally (no error,
    /// HomedStatus kept, the drive stays enabled) with the deceleration of
    /// the running motion; homing in process ends with ERR 12 / EXERR 1 as a
    /// `Request::stop` does. Always accepted.
    Stop = 8 {
        name: "stop",
        title: "Stop",
        client: false,
        moves: false,
        held: false,
        all: true,
        summary: "MAS: stop the axis",
    }
    /// MCD: new dynamics for the jog or move that runs now ([`ChangeSpec`]),
    /// re-planned from its exact state. Answered in place: accepted, the
    /// motion keeps its operation's id (its client follows it on); refused,
    /// `Status::op.refused` holds why and the motion runs on unchanged.
    Change(ChangeSpec) = 9 {
        name: "change",
        title: "Change",
        client: true,
        moves: true,
        held: false,
        all: false,
        summary: "MCD: new speed, acceleration, deceleration or jerk for the running jog or move",
    }
    /// MRP / MC_SetPosition ([`RedefineSpec`]): homed and at rest, the
    /// axis's position becomes P (or moves by D) without motion. Only the
    /// raw → axis offset changes: the frames, the drive and the soft limits
    /// on the machine see no step (the limits' numbers shift with it).
    Redefine(RedefineSpec) = 10 {
        name: "redefine",
        title: "Redefine",
        client: true,
        moves: true,
        held: false,
        all: false,
        summary: "MRP: the axis's position becomes Position (or moves by it) without motion",
    }
    /// MAR / MC_TouchProbe ([`ArmSpec`]): latch the axis's position at the
    /// next edge of an input, during whatever motion (or none); the
    /// position is `Status::registration_position`. Never moves the axis
    /// and answered in place: a running jog, move or stream keeps its id.
    Arm(ArmSpec) = 11 {
        name: "arm",
        title: "Arm",
        client: true,
        moves: false,
        held: false,
        all: false,
        summary: "MAR: latch the axis's position at the next edge of Input (inside Window)",
    }
    /// MDR / MC_AbortTrigger: the armed registration is disarmed (its last
    /// latched position stays). Always accepted; answered in place; asked
    /// for without an axis, every axis's.
    Disarm = 12 {
        name: "disarm",
        title: "Disarm",
        client: true,
        moves: false,
        held: false,
        all: true,
        summary: "MDR: disarm the axis's registration",
    }
    /// MAG / MC_GearIn ([`GearSpec`]): from now on the axis follows its
    /// master's position change times a ratio (`axis::ops::gear`).
    Gear(GearSpec) = 13 {
        name: "gear",
        title: "Gear",
        client: true,
        moves: true,
        held: false,
        all: false,
        summary: "MAG: this axis follows Master's position change times Ratio until stopped",
    }
}

impl OpKind {
    /// Answered in place: an accepted one leaves `Status::op.id` as it was
    /// (a running motion keeps its id, so its client follows it on); only
    /// `Status::op.refused` tells (cleared when accepted, set when refused).
    pub const fn in_place(self) -> bool {
        matches!(self, OpKind::Change | OpKind::Arm | OpKind::Disarm)
    }
}

/// A motion's acceleration (a jog's, a move's): one parameter, whichever
/// operation carries it.
const ACCEL: Param = Param::new("Accel", Unit::Acceleration)
    .or(Fallback::HomeAcceleration)
    .flag("accel", "A");
/// A motion's deceleration.
const DECEL: Param = Param::new("Decel", Unit::Acceleration)
    .or(Fallback::HomeDeceleration)
    .flag("decel", "D");
/// A motion's jerk: an S-curve when above 0.
const JERK: Param = Param::new("Jerk", Unit::Jerk)
    .or(Fallback::Jerk)
    .flag("jerk", "J");

crate::op_spec! {
    /// MAJ / MC_Jog, hold to run: runs in the sign of `speed` until stopped
    /// (a stop, a limit, a fault, or the lease running out): the jog stops
    /// normally unless `Request::jog_renew` renews it within its lease (an
    /// HMI or program that dies never leaves an axis running).
    pub struct JogSpec {
        /// Signed speed, units/s: the sign is the direction.
        speed: f64 = Param::new("Speed", Unit::Speed).flag("speed", "V"),
        /// The lease, s (0.05 ..= 5): the jog stops when no renewal came for
        /// this long. Left out: 0.5 s.
        lease: Option<f64> = Param::new("Duration", Unit::Seconds)
            .or(Fallback::JogLease)
            .form(Form::Lease),
        /// Acceleration, units/s²; left out: the axis's `home_acceleration`.
        accel: Option<f64> = ACCEL,
        /// Deceleration, units/s²; left out: the axis's `home_deceleration`.
        decel: Option<f64> = DECEL,
        /// Jerk, units/s³ (> 0: an S-curve; 0: a trapezoid); left out: the
        /// axis's `jerk`.
        jerk: Option<f64> = JERK,
    }
}

crate::op_spec! {
    /// MAM / MC_MoveAbsolute (`relative` off: `target` is an axis position)
    /// or MC_MoveRelative (`relative`: `target` is a distance from the
    /// current command position): a trapezoid ending at rest on the target
    /// (PC). On a cyclic axis an absolute target is reached the shortest
    /// way.
    pub struct MoveSpec {
        /// The target position, axis coordinates (units); with `relative`
        /// the distance from where the move starts.
        target: f64 = Param::new("Target", Unit::Position).form(Form::Either {
            off: ("to", "P"),
            on: ("by", "D"),
            switch: "relative",
        }),
        /// `target` is a distance from where the move starts.
        relative: bool = Param::new("Relative", Unit::None),
        /// Speed (magnitude), units/s; left out: the axis's `home_speed`.
        speed: Option<f64> = Param::new("Speed", Unit::Speed)
            .or(Fallback::HomeSpeed)
            .flag("speed", "V"),
        /// Acceleration, units/s²; left out: the axis's `home_acceleration`.
        accel: Option<f64> = ACCEL,
        /// Deceleration, units/s²; left out: the axis's `home_deceleration`.
        decel: Option<f64> = DECEL,
        /// Replace a jog or move in progress (without it such an axis
        /// refuses with ERR 3).
        supersede: bool = Param::new("Supersede", Unit::None).flag("supersede", ""),
        /// Jerk, units/s³ (> 0: an S-curve; 0: a trapezoid); left out: the
        /// axis's `jerk`.
        jerk: Option<f64> = JERK,
    }
}

crate::op_spec! {
    /// MCD: new dynamics for the jog or move that runs now, re-planned
    /// from its exact state (position, velocity, acceleration); each
    /// number left out keeps the running motion's.
    pub struct ChangeSpec {
        /// Speed (magnitude), units/s; a jog keeps its direction. Left out:
        /// the running motion's.
        speed: Option<f64> = Param::new("Speed", Unit::Speed).flag("speed", "V"),
        /// Acceleration, units/s²; left out: the running motion's.
        accel: Option<f64> = Param::new("Accel", Unit::Acceleration).flag("accel", "A"),
        /// Deceleration, units/s²; left out: the running motion's.
        decel: Option<f64> = Param::new("Decel", Unit::Acceleration).flag("decel", "D"),
        /// Jerk, units/s³ (> 0: an S-curve; 0: a trapezoid); left out: the
        /// running motion's.
        jerk: Option<f64> = Param::new("Jerk", Unit::Jerk).flag("jerk", "J"),
    }
}

crate::op_spec! {
    /// MRP / MC_SetPosition: the axis's position becomes `value`
    /// (`relative` off) or moves by `value` (`relative`), without
    /// motion; homed, at rest and not coupled only. The position that
    /// becomes P is the **command** position (exact at rest; the actual
    /// keeps its following error). On a cyclic axis P reads wrapped into
    /// `[0, unwind)`.
    pub struct RedefineSpec {
        /// The new axis position (units); with `relative` the shift.
        value: f64 = Param::new("Position", Unit::Position).form(Form::Either {
            off: ("position", "P"),
            on: ("by", "D"),
            switch: "relative",
        }),
        /// `value` is a shift of the axis's positions.
        relative: bool = Param::new("Relative", Unit::None),
    }
}

impl RedefineSpec {
    /// The command position becomes `p`.
    pub fn to(p: f64) -> Self {
        RedefineSpec {
            value: p,
            relative: false,
        }
    }

    /// Every position moves by `d`.
    pub fn by(d: f64) -> Self {
        RedefineSpec {
            value: d,
            relative: true,
        }
    }
}

/// The input a registration watches.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LatchInput {
    /// The home switch input (actuated whatever its wiring).
    #[default]
    Switch = 0,
    /// The feedback device's marker (index pulse).
    Marker = 1,
}

crate::spellings!(LatchInput {
    Switch => "switch",
    Marker => "marker",
});

/// The edge of the input a registration takes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LatchEdge {
    /// The input becomes actuated (a normally closed switch: opens).
    #[default]
    Rising = 0,
    /// The input stops being actuated.
    Falling = 1,
}

crate::spellings!(LatchEdge {
    Rising => "rising",
    Falling => "falling",
});

crate::op_spec! {
    /// MAR / MC_TouchProbe: latch the axis's position at the next `edge`
    /// of `input`, optionally only inside `window`. Where the drive latches
    /// the input (`registration` for the home switch, `marker_latch` for
    /// the marker) the position is the drive's, exact to the count; else
    /// the engine samples the input each cycle and places the edge midway
    /// between the samples around it (within half the travel of a cycle,
    /// speed × cycle / 2).
    pub struct ArmSpec {
        /// The input: `switch` (the home switch, the default) or `marker`.
        input: LatchInput = Param::new("Input", Unit::None).flag("input", "switch|marker"),
        /// The edge: `rising` (becoming actuated, the default) or
        /// `falling`. A marker is a pulse: both of its edges lie at the
        /// marker.
        edge: LatchEdge = Param::new("Edge", Unit::None).flag("edge", "rising|falling"),
        /// Only an edge at an axis position in [LO, HI] counts (units);
        /// left out: any.
        window: Option<(f64, f64)> = Param::new("Window", Unit::Position).flag("window", "LO HI"),
    }
}

impl ArmSpec {
    /// The next `edge` of `input`, anywhere.
    pub fn on(input: LatchInput, edge: LatchEdge) -> Self {
        ArmSpec {
            input,
            edge,
            window: None,
        }
    }
}

crate::op_spec! {
    /// MAG / MC_GearIn: from now on the axis (the slave) follows its
    /// master's commanded (or, with `actual`, actual) position change times
    /// `ratio`, from where both stand (no jump). With `clutch` the slave's
    /// velocity ramps in to the geared velocity at that acceleration and
    /// then locks; the distance lost while ramping is not made up (as
    /// Logix MAG's clutch and PLCopen MC_GearIn do). It runs until a stop,
    /// a disable or a fault on either axis ends it.
    pub struct GearSpec {
        /// The master axis (by name; the engine sees its index).
        master: AxisRef = Param::new("Master", Unit::None).flag("master", "MASTER"),
        /// Slave units per master unit, finite and not 0 (negative: the
        /// slave runs the opposite way).
        ratio: f64 = Param::new("Ratio", Unit::None).flag("ratio", "R"),
        /// Follow the master's actual position instead of its command.
        actual: bool = Param::new("Actual", Unit::None).flag("actual", ""),
        /// Clutch: ramp the slave's velocity in at this acceleration,
        /// units/s²; left out: the slave locks on at once.
        clutch: Option<f64> = Param::new("Clutch", Unit::Acceleration).flag("clutch", "A"),
    }
}

impl GearSpec {
    /// Gearing to the axis of index `master` at `ratio`, on its command,
    /// without a clutch.
    pub fn to(master: u16, ratio: f64) -> Self {
        GearSpec {
            master: AxisRef::Index(master),
            ratio,
            actual: false,
            clutch: None,
        }
    }

    /// The master's index, once the control thread resolved its name.
    pub fn master_index(&self) -> Option<u16> {
        match self.master {
            AxisRef::Index(i) => Some(i),
            AxisRef::Name(_) => None,
        }
    }
}

/// What a geared slave's engine is given of its master each cycle
/// (`Request::master`): the cycle reads it from the master's engine after
/// the master stepped in the same cycle, so the slave follows without a
/// cycle's lag. Nothing else crosses between the two engines.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MasterFeed {
    /// The master's command position after its step, raw (never wrapped).
    pub commanded: f64,
    /// The master's newest valid actual position, raw (`None`: none).
    pub actual: Option<f64>,
    /// The hardest the master's motion may change its speed, units/s²
    /// ([`Axis::acceleration_bound`](crate::Axis::acceleration_bound)).
    pub accel: f64,
    /// The master was stopped (MAS), disabled, or began homing in this
    /// cycle: the gearing ends, the slave stops normally.
    pub stopped: bool,
    /// The master is faulted: the gearing ends, the slave stops with
    /// ER 1025 / 3.
    pub faulted: bool,
}

/// A jog's or move's speed, acceleration and deceleration as the engine
/// plans with them, after [`Operation::resolve`]: a number still left out
/// (no default configured) is NaN, which the operand checks refuse (13).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dynamics {
    pub speed: f64,
    pub accel: f64,
    pub decel: f64,
    /// units/s³: 0 plans trapezoids, above 0 S-curves.
    pub jerk: f64,
}

impl Dynamics {
    fn of(speed: Option<f64>, accel: Option<f64>, decel: Option<f64>, jerk: Option<f64>) -> Self {
        let n = |x: Option<f64>| x.unwrap_or(f64::NAN);
        Dynamics {
            speed: n(speed),
            accel: n(accel),
            decel: n(decel),
            // No default configured (an engine without the `jerk` key): a
            // trapezoid, as before jerk existed.
            jerk: jerk.unwrap_or(0.0),
        }
    }
}

impl JogSpec {
    /// A jog at `speed` with every other parameter left out.
    pub fn at(speed: f64) -> Self {
        JogSpec {
            speed,
            lease: None,
            accel: None,
            decel: None,
            jerk: None,
        }
    }

    /// The signed speed and the acceleration, deceleration, jerk.
    pub fn dynamics(&self) -> Dynamics {
        Dynamics::of(Some(self.speed), self.accel, self.decel, self.jerk)
    }

    /// The lease to the nearest ns (0 when left out or not a positive
    /// number of seconds: refused 13 / 6).
    pub fn lease_ns(&self) -> u64 {
        match self.lease {
            Some(s) if s.is_finite() && s > 0.0 => (s * 1e9).round().min(u64::MAX as f64) as u64,
            _ => 0,
        }
    }
}

impl MoveSpec {
    /// A move to axis position `target` with every other parameter left
    /// out.
    pub fn to(target: f64) -> Self {
        MoveSpec {
            target,
            relative: false,
            speed: None,
            accel: None,
            decel: None,
            supersede: false,
            jerk: None,
        }
    }

    /// The speed, acceleration, deceleration and jerk.
    pub fn dynamics(&self) -> Dynamics {
        Dynamics::of(self.speed, self.accel, self.decel, self.jerk)
    }
}

impl ChangeSpec {
    /// A change of nothing (every number left out): add what changes.
    pub fn none() -> Self {
        ChangeSpec {
            speed: None,
            accel: None,
            decel: None,
            jerk: None,
        }
    }

    /// The running motion's dynamics `d` with what this change gives.
    pub fn applied_to(&self, d: Dynamics) -> Dynamics {
        Dynamics {
            speed: self.speed.unwrap_or(d.speed),
            accel: self.accel.unwrap_or(d.accel),
            decel: self.decel.unwrap_or(d.decel),
            jerk: self.jerk.unwrap_or(d.jerk),
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

/// The answer to the operations: the last accepted one and its progress,
/// and the refusal of the last one asked for if it was refused.
///
/// A caller that passed an operation in a step reads this after the step:
/// `id` changed → accepted (it is then the operation described); `id`
/// unchanged → refused, `refused` holds the ERR / EXERR. An operation
/// answered in place ([`OpKind::in_place`]: a change) keeps `id`: accepted
/// when `refused` is `None` after the step. A refusal is the
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
    /// Gearing stopped the slave with an error (ER 1025: a travel limit
    /// ahead, a master it cannot follow, the master's fault).
    Gearing = 12,
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
    Gearing => "gearing",
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
