//! What a trip reports: the invariant broken (its EXERR under ERR 1021,
//! `motion_homing::codes`), the value against its bound, the stop category.
//! Plain data, `Copy`: the cycle hands it over as it is; whoever logs it
//! formats it, off the real-time thread.

use motion_homing::codes::*;

/// The invariants, numbered as their EXERR under [`ERR_MONITOR`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u16)]
pub enum Invariant {
    /// The command's velocity above the speed bound.
    Velocity = EX_MONITOR_VELOCITY,
    /// The commanded acceleration above its bound.
    Acceleration = EX_MONITOR_ACCELERATION,
    /// A set-point step larger than the speed bound allows.
    Step = EX_MONITOR_STEP,
    /// Outside the soft limits while homed (or further out).
    SoftLimit = EX_MONITOR_SOFT_LIMIT,
    /// The power stage asked on without a request since it had to go off.
    Enable = EX_MONITOR_ENABLE,
    /// A gantry's sides apart.
    Gantry = EX_MONITOR_GANTRY,
    /// A command that is not a number.
    NotFinite = EX_MONITOR_NOT_FINITE,
}

motion_homing::spellings!(Invariant {
    Velocity => "velocity",
    Acceleration => "acceleration",
    Step => "step",
    SoftLimit => "soft_limit",
    Enable => "enable",
    Gantry => "gantry",
    NotFinite => "not_finite",
});

impl Invariant {
    /// The unit of its value and bound.
    pub fn unit(self) -> &'static str {
        match self {
            Self::Velocity | Self::Step => "units/s",
            Self::Acceleration => "units/s²",
            Self::SoftLimit | Self::Gantry => "units",
            Self::Enable | Self::NotFinite => "",
        }
    }
}

/// Why the power stage was no longer allowed on (an `Enable` trip): what
/// took the permission away last.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum Withdrawn {
    /// Nobody asked for it since the monitor started.
    #[default]
    NeverAsked = 0,
    DriveFault = 1,
    /// The drive switched its power stage off by itself (STO, a power
    /// return).
    PowerDropped = 2,
    /// Its I/O process reports the drive lost.
    DriveLost = 3,
    /// A new I/O process took over.
    IoRestarted = 4,
    Shutdown = 5,
    /// A disable, once its stop had had the time it needs.
    Disabled = 6,
}

motion_homing::spellings!(Withdrawn {
    NeverAsked => "never_asked",
    DriveFault => "drive_fault",
    PowerDropped => "power_stage_dropped",
    DriveLost => "drive_lost",
    IoRestarted => "io_restarted",
    Shutdown => "shutdown",
    Disabled => "disabled",
});

/// How the monitor stopped the axis (EN 60204-1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Category {
    /// Power stage off at once: it was off already (a fault, a dropped or
    /// lost drive), or there was nothing to stop.
    Stop0 = 0,
    /// A controlled stop, then the power stage off.
    Stop1 = 1,
}

/// One trip, as the log and the status show it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trip {
    pub invariant: Invariant,
    /// What the command did (for `Enable`: 1; for `NotFinite`: the value).
    pub value: f64,
    /// What it was allowed (for `SoftLimit`: the limit it passed).
    pub bound: f64,
    /// The cycle that produced the command, ns.
    pub at_ns: u64,
    pub category: Category,
    /// The last command the monitor passed (raw), where its stop starts.
    pub from: f64,
    /// An `Enable` trip: what had taken the permission away.
    pub withdrawn: Option<Withdrawn>,
}

impl Trip {
    /// ERR / EXERR the axis reports.
    pub fn code(&self) -> (u16, u16) {
        (ERR_MONITOR, self.invariant as u16)
    }
}

/// A broken invariant: which, and the value against its bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Broken {
    pub invariant: Invariant,
    pub value: f64,
    pub bound: f64,
    pub withdrawn: Option<Withdrawn>,
}

/// `Err` with `invariant` when `value` is above `bound` by more than
/// `slack` (the tolerance; the trip reports the bound itself).
pub(crate) fn within(
    invariant: Invariant,
    value: f64,
    bound: f64,
    slack: f64,
) -> Result<(), Broken> {
    if value <= bound + slack {
        Ok(())
    } else {
        Err(Broken {
            invariant,
            value,
            bound,
            withdrawn: None,
        })
    }
}
