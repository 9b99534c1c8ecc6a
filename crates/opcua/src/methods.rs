//! The methods: what each takes and answers, the decoding of a call's
//! arguments into an [`Operation`] for the control service, and the
//! control service's answer as output arguments and a status code.
//!
//! Pure functions (no server, no daemon), so they are fuzzed directly
//! (`tests` below, proptest).
//!
//! A new operation is a row of [`METHODS`], a variant of [`Operation`]
//! with its control request in [`Operation::typed`], and an arm in
//! [`decode`]. Enable, Disable and Reset take no input (like Stop); Move
//! takes Target (Double), Relative (Boolean) and Speed (Double, 0: the
//! axis's default); Jog is hold to run: Speed and a Duration (at most
//! [`MAX_JOG_S`]) that the client extends by calling Jog again with the
//! same speed (the keep-alive), and the jog stops when the duration runs
//! out or the calling session is gone (the bridge renews the control
//! service's lease only while both hold: `bridge.rs`, `jogs.rs`).

use motion_control::*;
use opcua::types::{DataTypeId, StatusCode, Variant};

/// Where a method sits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scope {
    /// On every `Machine.Axes.<axis>` object: acts on that axis.
    Axis,
    /// On `Machine`: acts on named axes, or all.
    Machine,
}

/// One input argument.
pub struct ArgSpec {
    pub name: &'static str,
    pub data_type: DataTypeId,
    pub array: bool,
    pub doc: &'static str,
}

/// One method.
pub struct MethodSpec {
    pub name: &'static str,
    pub scope: Scope,
    pub inputs: &'static [ArgSpec],
    pub doc: &'static str,
}

const TIMEOUT: ArgSpec = ArgSpec {
    name: "Timeout",
    data_type: DataTypeId::Double,
    array: false,
    doc: "seconds after which the supervisor stops what still homes (0: the axes' own home_timeout only)",
};

/// Every method we offer.
pub const METHODS: &[MethodSpec] = &[
    MethodSpec {
        name: "Home",
        scope: Scope::Axis,
        inputs: &[TIMEOUT],
        doc: "MAH: home this axis (a gantry side: home the gantry with HomeAll)",
    },
    MethodSpec {
        name: "Stop",
        scope: Scope::Axis,
        inputs: &[],
        doc: "MAS: stop this axis (a homing ends with ERR 12 / EXERR 1)",
    },
    MethodSpec {
        name: "Unhome",
        scope: Scope::Axis,
        inputs: &[],
        doc: "clear HomedStatus (and invalidate a stored absolute reference)",
    },
    MethodSpec {
        name: "Enable",
        scope: Scope::Axis,
        inputs: &[],
        doc: "MSO: enable the drive, holding position",
    },
    MethodSpec {
        name: "Disable",
        scope: Scope::Axis,
        inputs: &[],
        doc: "MSF: disable the drive (a moving axis is stopped first)",
    },
    MethodSpec {
        name: "Reset",
        scope: Scope::Axis,
        inputs: &[],
        doc: "MAFR: clear the axis's error and ask the drive for a fault reset",
    },
    MethodSpec {
        name: "Jog",
        scope: Scope::Axis,
        inputs: &[
            ArgSpec {
                name: "Speed",
                data_type: DataTypeId::Double,
                array: false,
                doc: "signed speed (units/s): the sign is the direction",
            },
            ArgSpec {
                name: "Duration",
                data_type: DataTypeId::Double,
                array: false,
                doc: "seconds the jog runs (0 < Duration <= 10) unless called again with the same speed, which extends it (hold to run); it stops at once when the session closes",
            },
        ],
        doc: "MAJ, hold to run: jog this axis for Duration seconds, or while called again",
    },
    MethodSpec {
        name: "Move",
        scope: Scope::Axis,
        inputs: &[
            ArgSpec {
                name: "Target",
                data_type: DataTypeId::Double,
                array: false,
                doc: "the target position (units), or the distance with Relative",
            },
            ArgSpec {
                name: "Relative",
                data_type: DataTypeId::Boolean,
                array: false,
                doc: "Target is a distance from where the axis is",
            },
            ArgSpec {
                name: "Speed",
                data_type: DataTypeId::Double,
                array: false,
                doc: "units/s (> 0), or 0: the axis's home_speed",
            },
        ],
        doc: "MAM: a trapezoidal move to Target (or by it); done when MoveStatus drops",
    },
    MethodSpec {
        name: "HomeAll",
        scope: Scope::Machine,
        inputs: &[
            ArgSpec {
                name: "Axes",
                data_type: DataTypeId::String,
                array: true,
                doc: "axis or gantry names; empty: every axis, in home order",
            },
            ArgSpec {
                name: "Parallel",
                data_type: DataTypeId::Boolean,
                array: false,
                doc: "start every named axis at once, ignoring the home order",
            },
            TIMEOUT,
        ],
        doc: "home the named axes (all by default), like `motionctl home`",
    },
    MethodSpec {
        name: "StopAll",
        scope: Scope::Machine,
        inputs: &[],
        doc: "MAS on every axis",
    },
];

pub fn spec(name: &str, scope: Scope) -> Option<&'static MethodSpec> {
    METHODS.iter().find(|m| m.name == name && m.scope == scope)
}

/// Longest Timeout accepted (the range of `home_timeout`).
pub const MAX_TIMEOUT_S: f64 = 86_400.0;
/// Longest Duration of one Jog call: an HMI that holds longer calls Jog
/// again; one that vanished without closing its session stops jogging
/// within this bound.
pub const MAX_JOG_S: f64 = 10.0;
/// Largest |Speed| or |Target| taken (the daemon applies the axis's own
/// limits; this only keeps absurd numbers off the wire).
pub const MAX_ABS: f64 = 1e12;

/// What the control service is asked.
#[derive(Clone, Debug, PartialEq)]
pub enum Operation {
    /// `axes` empty: every axis in home order.
    Home {
        axes: Vec<String>,
        parallel: bool,
        timeout_s: f64,
    },
    Stop {
        axes: Vec<String>,
    },
    Unhome {
        axes: Vec<String>,
    },
    Enable {
        axes: Vec<String>,
    },
    Disable {
        axes: Vec<String>,
    },
    Reset {
        axes: Vec<String>,
    },
    /// Hold to run on one axis: the bridge starts it and renews it while
    /// `duration_s` lasts and the session lives.
    Jog {
        axis: String,
        speed: f64,
        duration_s: f64,
    },
    Move {
        axis: String,
        position: f64,
        relative: bool,
        /// `None`: the axis's default.
        speed: Option<f64>,
    },
}

/// The control service's lease of a jog started here, renewed by the
/// bridge every [`JOG_RENEW_MS`] while the jog may run.
pub const JOG_LEASE_MS: u32 = 500;
pub const JOG_RENEW_MS: u64 = 100;

impl Operation {
    /// The typed control request.
    pub fn typed(&self) -> Request {
        let named = |a: &Vec<String>| Axes::from_names(a);
        match self {
            Operation::Home {
                axes,
                parallel,
                timeout_s,
            } => Request::Home {
                axes: named(axes),
                parallel: *parallel,
                timeout_s: (*timeout_s > 0.0).then_some(*timeout_s),
            },
            Operation::Stop { axes } => Request::Stop { axes: named(axes) },
            Operation::Unhome { axes } => Request::Unhome { axes: named(axes) },
            Operation::Enable { axes } => Request::Enable { axes: named(axes) },
            Operation::Disable { axes } => Request::Disable { axes: named(axes) },
            Operation::Reset { axes } => Request::Reset { axes: named(axes) },
            Operation::Jog { axis, speed, .. } => Request::Jog {
                axes: Axes::Named(vec![axis.clone()]),
                speed: *speed,
                accel: None,
                decel: None,
                lease_ms: JOG_LEASE_MS,
            },
            Operation::Move {
                axis,
                position,
                relative,
                speed,
            } => Request::Move {
                axes: Axes::Named(vec![axis.clone()]),
                position: *position,
                relative: *relative,
                speed: *speed,
                accel: None,
                decel: None,
                supersede: false,
            },
        }
    }

    /// The control request (the client adds layout, key and id). `decode`
    /// bounded the names, so it always encodes; were it not, the request
    /// is of no kind and the daemon refuses it.
    pub fn request(&self) -> Box<ControlRequest> {
        self.typed().encode().unwrap_or_else(ControlRequest::zeroed)
    }
}

/// Why a call is refused before it reaches the daemon.
#[derive(Clone, Debug, PartialEq)]
pub enum CallError {
    /// The whole call (e.g. missing arguments).
    Status(StatusCode),
    /// Per input argument (`BadInvalidArgument` overall).
    Args(Vec<StatusCode>),
}

/// Decodes the input arguments of `spec` called on `axis` (the axis object,
/// for [`Scope::Axis`]).
pub fn decode(
    spec: &MethodSpec,
    axis: Option<&str>,
    args: &[Variant],
) -> Result<Operation, CallError> {
    if args.len() < spec.inputs.len() {
        return Err(CallError::Status(StatusCode::BadArgumentsMissing));
    }
    if args.len() > spec.inputs.len() {
        return Err(CallError::Status(StatusCode::BadTooManyArguments));
    }
    let mut results = vec![StatusCode::Good; args.len()];
    let mut timeout_s = 0.0;
    let mut parallel = false;
    let mut named = Vec::new();
    let (mut speed, mut duration_s, mut target, mut relative) = (0.0, 0.0, 0.0, false);
    for (i, (a, s)) in args.iter().zip(spec.inputs).enumerate() {
        let r = match (spec.name, s.name) {
            (_, "Timeout") => timeout(a).map(|t| timeout_s = t),
            ("Jog", "Speed") => bounded(a, |x| x.abs() <= MAX_ABS).map(|x| speed = x),
            ("Move", "Speed") => bounded(a, |x| (0.0..=MAX_ABS).contains(&x)).map(|x| speed = x),
            (_, "Duration") => bounded(a, |x| x > 0.0 && x <= MAX_JOG_S).map(|x| duration_s = x),
            (_, "Target") => bounded(a, |x| x.abs() <= MAX_ABS).map(|x| target = x),
            (_, "Relative") => match a {
                Variant::Boolean(b) => {
                    relative = *b;
                    Ok(())
                }
                _ => Err(StatusCode::BadTypeMismatch),
            },
            (_, "Parallel") => match a {
                Variant::Boolean(b) => {
                    parallel = *b;
                    Ok(())
                }
                _ => Err(StatusCode::BadTypeMismatch),
            },
            (_, "Axes") => names(a).map(|n| named = n),
            _ => Err(StatusCode::BadInvalidArgument),
        };
        if let Err(e) = r {
            results[i] = e;
        }
    }
    if results.iter().any(|r| r.is_bad()) {
        return Err(CallError::Args(results));
    }
    let axes = match (spec.scope, axis) {
        (Scope::Axis, Some(a)) => vec![a.to_string()],
        (Scope::Axis, None) => return Err(CallError::Status(StatusCode::BadMethodInvalid)),
        (Scope::Machine, _) => named,
    };
    Ok(match spec.name {
        "Home" | "HomeAll" => Operation::Home {
            axes,
            parallel,
            timeout_s,
        },
        "Stop" | "StopAll" => Operation::Stop { axes },
        "Unhome" => Operation::Unhome { axes },
        "Enable" => Operation::Enable { axes },
        "Disable" => Operation::Disable { axes },
        "Reset" => Operation::Reset { axes },
        "Jog" => Operation::Jog {
            axis: axes.concat(),
            speed,
            duration_s,
        },
        "Move" => Operation::Move {
            axis: axes.concat(),
            position: target,
            relative,
            speed: (speed > 0.0).then_some(speed),
        },
        _ => return Err(CallError::Status(StatusCode::BadMethodInvalid)),
    })
}

fn timeout(v: &Variant) -> Result<f64, StatusCode> {
    let t = match v {
        Variant::Double(x) => *x,
        Variant::Float(x) => f64::from(*x),
        _ => return Err(StatusCode::BadTypeMismatch),
    };
    if t.is_finite() && (0.0..=MAX_TIMEOUT_S).contains(&t) {
        Ok(t)
    } else {
        Err(StatusCode::BadOutOfRange)
    }
}

/// A finite Double (or Float) that `ok` accepts.
fn bounded(v: &Variant, ok: impl Fn(f64) -> bool) -> Result<f64, StatusCode> {
    let x = match v {
        Variant::Double(x) => *x,
        Variant::Float(x) => f64::from(*x),
        _ => return Err(StatusCode::BadTypeMismatch),
    };
    if x.is_finite() && ok(x) {
        Ok(x)
    } else {
        Err(StatusCode::BadOutOfRange)
    }
}

/// An array of names (a null or empty array: none), each a name the
/// control service can carry.
fn names(v: &Variant) -> Result<Vec<String>, StatusCode> {
    let list = match v {
        Variant::Empty => return Ok(Vec::new()),
        Variant::Array(a) => &a.values,
        _ => return Err(StatusCode::BadTypeMismatch),
    };
    if list.len() > MAX_AXES {
        return Err(StatusCode::BadOutOfRange);
    }
    let mut out = Vec::with_capacity(list.len());
    for v in list {
        let Variant::String(s) = v else {
            return Err(StatusCode::BadTypeMismatch);
        };
        let s = s.as_ref();
        if s.is_empty() || s.len() > NAME_LEN || s.contains('\0') {
            return Err(StatusCode::BadOutOfRange);
        }
        out.push(s.to_string());
    }
    Ok(out)
}

/// The status of a call the daemon answered: Good when accepted; a
/// refusal is `BadInvalidState` (the machine's state does not allow it:
/// already homing, I/O not attached, the Home instruction's ERR/EXERR, …)
/// or `BadInvalidArgument` (an unknown axis name); the reasons are in the
/// output arguments either way.
pub fn status_of(resp: &ControlResponse) -> StatusCode {
    match resp.result {
        RESULT_ACCEPTED => StatusCode::Good,
        RESULT_REFUSED
            if resp
                .answers()
                .iter()
                .any(|a| a.accepted == 0 && a.reason == REASON_UNKNOWN_AXIS) =>
        {
            StatusCode::BadInvalidArgument
        }
        RESULT_REFUSED | RESULT_NOT_READY => StatusCode::BadInvalidState,
        RESULT_BAD_REQUEST => StatusCode::BadInvalidArgument,
        _ => StatusCode::BadInternalError,
    }
}

/// The reason of one axis's answer, in words.
fn reason(resp: &ControlResponse, a: &AxisAnswer) -> String {
    if a.accepted != 0 {
        return "accepted".into();
    }
    let msg = resp.message_text();
    if a.reason == REASON_NONE && !msg.is_empty() {
        msg
    } else {
        reason_text(a.reason).to_string()
    }
}

/// The output arguments (see [`output_args`]).
pub fn outputs(scope: Scope, resp: &ControlResponse) -> Vec<Variant> {
    let answers = resp.answers();
    match scope {
        Scope::Axis => {
            let (ok, why, err, exerr) = match answers.first() {
                Some(a) => (a.accepted != 0, reason(resp, a), a.err, a.exerr),
                None => (
                    resp.result == RESULT_ACCEPTED,
                    if resp.result == RESULT_ACCEPTED {
                        "accepted".into()
                    } else {
                        resp.message_text()
                    },
                    0,
                    0,
                ),
            };
            vec![ok.into(), why.into(), err.into(), exerr.into()]
        }
        Scope::Machine => {
            let names: Vec<String> = answers.iter().map(|a| get_str(&a.name)).collect();
            let ok: Vec<bool> = answers.iter().map(|a| a.accepted != 0).collect();
            let why: Vec<String> = answers.iter().map(|a| reason(resp, a)).collect();
            let err: Vec<u16> = answers.iter().map(|a| a.err).collect();
            let exerr: Vec<u16> = answers.iter().map(|a| a.exerr).collect();
            vec![
                names.into(),
                ok.into(),
                why.into(),
                err.into(),
                exerr.into(),
                resp.message_text().into(),
            ]
        }
    }
}

/// Names, types and descriptions of the output arguments per scope.
pub fn output_args(scope: Scope) -> &'static [ArgSpec] {
    const AXIS: &[ArgSpec] = &[
        ArgSpec {
            name: "Accepted",
            data_type: DataTypeId::Boolean,
            array: false,
            doc: "the control service accepted the request",
        },
        ArgSpec {
            name: "Reason",
            data_type: DataTypeId::String,
            array: false,
            doc: "\"accepted\", or why it was refused (the control service's words)",
        },
        ArgSpec {
            name: "ERR",
            data_type: DataTypeId::UInt16,
            array: false,
            doc: "the instruction's ERR where it has one, else 0",
        },
        ArgSpec {
            name: "EXERR",
            data_type: DataTypeId::UInt16,
            array: false,
            doc: "the instruction's EXERR where it has one, else 0",
        },
    ];
    const MACHINE: &[ArgSpec] = &[
        ArgSpec {
            name: "Axes",
            data_type: DataTypeId::String,
            array: true,
            doc: "the axes the request addressed",
        },
        ArgSpec {
            name: "Accepted",
            data_type: DataTypeId::Boolean,
            array: true,
            doc: "per axis",
        },
        ArgSpec {
            name: "Reasons",
            data_type: DataTypeId::String,
            array: true,
            doc: "per axis: \"accepted\" or why refused",
        },
        ArgSpec {
            name: "ERR",
            data_type: DataTypeId::UInt16,
            array: true,
            doc: "per axis",
        },
        ArgSpec {
            name: "EXERR",
            data_type: DataTypeId::UInt16,
            array: true,
            doc: "per axis",
        },
        ArgSpec {
            name: "Message",
            data_type: DataTypeId::String,
            array: false,
            doc: "the control service's message (empty when accepted)",
        },
    ];
    match scope {
        Scope::Axis => AXIS,
        Scope::Machine => MACHINE,
    }
}

#[cfg(test)]
mod tests;
