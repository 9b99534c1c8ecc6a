//! Sans-I/O CIP Motion homing engine.
//!
//! Config + feedback + time in, command + status out: [`Axis::step`] is
//! called once per controller cycle per axis. No threads, clocks, heap
//! allocation or I/O happen inside a step, so the engine is deterministic and
//! is tested cycle by cycle against the plant model in `motion-plant`.
//!
//! * [`config`]: the homing attributes (spec §2) and axis facts.
//! * [`validate`](mod@validate): every configuration problem at once, with CIP codes.
//! * [`plan`]: every sequence as one ordered list of legs.
//! * [`axis`]: the state machine that runs a plan, for every active and
//!   passive sequence; feedback trust (loss in time, plausibility); the
//!   stored reference of absolute axes.
//! * [`profile`]: jog / stop / trapezoid profiles that never exceed their limits.
//! * [`codes`]: the ERR / EXERR table.
//! * [`io`]: the per-cycle feedback, command and request types (with the
//!   coordination hooks a machine coordinator uses for gantries and home
//!   order: barrier, timed final move, stop code).
//! * [`status`]: the instruction's and the axis's status after a cycle.
//! * [`operation`]: the operations around homing (enable, disable, reset,
//!   jog, move, stop, the supervised stream) as they cross the boundary;
//!   [`op_limits`]: the bounds they run within; [`params`]: an operation's
//!   parameters declared once with its spec, and carried by every layer.
//! * [`names`]: every enum's spellings, written once next to the enum.
//! * [`time`]: ns ↔ s conversions, exact and cheap.
//! * [`equivalent`]: the CiA 402 homing method and PLCopen function blocks
//!   of the limit-switch sequences and of a search that reverses at a limit.

pub mod axis;
pub mod code_table;
pub mod codes;
pub mod config;
pub mod equivalent;
pub mod io;
pub mod names;
pub mod op_limits;
pub mod operation;
pub mod params;
pub mod plan;
pub mod position;
pub mod profile;
pub mod status;
pub mod time;
pub mod validate;

pub use axis::loss::FeedbackLoss;
pub use axis::{Axis, RestoreRefusal};
pub use config::*;
pub use io::*;
pub use op_limits::{
    effective_max_deceleration, effective_stream_acceleration, effective_stream_timeout_ns,
    effective_unhomed_speed, OpLimits, MAX_JERK,
};
// Every operation, its verbs and its spec types, whatever the table adds.
pub use operation::*;
pub use params::{AxisRef, Carried, Param, Spec};
pub use status::{Implausible, Phase, Status};
pub use validate::{
    advisories, effective_max_speed, effective_search_limit, validate, ConfigError,
};
