//! The methods: what each takes and answers, the decoding of a call's
//! arguments into a request for the control service, and the control
//! service's answer as output arguments and a status code.
//!
//! Pure functions (no server, no daemon), so they are fuzzed directly
//! (`tests` below, proptest).
//!
//! Home, Stop, Unhome (per axis) and HomeAll, StopAll (on `Machine`) are
//! the control service's own requests, declared here. The operations of
//! the engine are not: every operation a client may ask for
//! (`motion_homing::OpKind::client`) is a method on every axis, named by
//! its kind's title, with one input argument per parameter of its spec in
//! the spec's order — named by the parameter's title, typed by its kind
//! (a number: Double; a switch: Boolean; a choice or an axis: String; a
//! pair: Double[2]) and described by its doc — decoded into the spec the
//! engine declared ([`Call::Operate`]). A new operation is a method here
//! without a line of this file changing.
//!
//! Arguments after the last one that must be given may be left out, and an
//! optional number, a switch or a pair may be given as null: left out, the
//! engine applies the axis's default (Move's Speed: the axis's
//! `home_speed`). Jog is hold to run: its Duration is its lease, which the
//! caller must state, at most [`MAX_JOG_S`], renewed by calling Jog again
//! (`jogs.rs`, `bridge.rs`).

use motion_control::params::{Carried, Form, Kind, Param, Place};
use motion_control::*;
use opcua::types::{DataTypeId, StatusCode, Variant};
use std::borrow::Cow;
use std::sync::OnceLock;

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
    pub doc: Cow<'static, str>,
}

/// What a method asks of the control service.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verb {
    Home,
    Stop,
    Unhome,
    /// An operation of the engine.
    Op(OpKind),
}

/// One method.
pub struct MethodSpec {
    pub name: &'static str,
    pub scope: Scope,
    pub verb: Verb,
    pub inputs: Vec<ArgSpec>,
    pub doc: &'static str,
}

const fn arg(name: &'static str, data_type: DataTypeId, array: bool, doc: &'static str) -> ArgSpec {
    ArgSpec {
        name,
        data_type,
        array,
        doc: Cow::Borrowed(doc),
    }
}

const TIMEOUT: ArgSpec = arg(
    "Timeout",
    DataTypeId::Double,
    false,
    "seconds after which the supervisor stops what still homes (0: the axes' own home_timeout only)",
);

/// The argument of an operation's parameter.
fn param_arg(p: &Param) -> ArgSpec {
    let (data_type, array) = match p.kind {
        Kind::Number | Kind::Optional => (DataTypeId::Double, false),
        Kind::Switch => (DataTypeId::Boolean, false),
        Kind::Choice(_) | Kind::Axis => (DataTypeId::String, false),
        Kind::Pair => (DataTypeId::Double, true),
    };
    let doc: Vec<&str> = p.doc.lines().map(str::trim).collect();
    let mut doc = doc.join(" ").replace('`', "");
    if let Kind::Choice(c) = p.kind {
        doc += &format!(" One of: {}.", c.join(", "));
    }
    if p.form == Form::Lease {
        doc +=
            &format!(" At most {MAX_JOG_S} s here: call again within it to go on (hold to run).");
    }
    if !given(p) {
        doc += " Null or left out: not given.";
    }
    ArgSpec {
        name: p.title,
        data_type,
        array,
        doc: Cow::Owned(doc),
    }
}

/// Every method we offer: the control service's own, then one per
/// operation a client may ask for.
pub fn methods() -> &'static [MethodSpec] {
    static ALL: OnceLock<Vec<MethodSpec>> = OnceLock::new();
    ALL.get_or_init(|| {
        let own = |name, scope, verb, inputs, doc| MethodSpec {
            name,
            scope,
            verb,
            inputs,
            doc,
        };
        let mut all = vec![
            own(
                "Home",
                Scope::Axis,
                Verb::Home,
                vec![TIMEOUT],
                "MAH: home this axis (a gantry side: home the gantry with HomeAll)",
            ),
            own(
                "Stop",
                Scope::Axis,
                Verb::Stop,
                vec![],
                "MAS: stop this axis (a homing ends with ERR 12 / EXERR 1)",
            ),
            own(
                "Unhome",
                Scope::Axis,
                Verb::Unhome,
                vec![],
                "clear HomedStatus (and invalidate a stored absolute reference)",
            ),
            own(
                "HomeAll",
                Scope::Machine,
                Verb::Home,
                vec![
                    arg(
                        "Axes",
                        DataTypeId::String,
                        true,
                        "axis or gantry names; empty: every axis, in home order",
                    ),
                    arg(
                        "Parallel",
                        DataTypeId::Boolean,
                        false,
                        "start every named axis at once, ignoring the home order",
                    ),
                    TIMEOUT,
                ],
                "home the named axes (all by default), like `motionctl home`",
            ),
            own(
                "StopAll",
                Scope::Machine,
                Verb::Stop,
                vec![],
                "MAS on every axis",
            ),
        ];
        for k in OpKind::ALL.iter().copied().filter(|k| k.client()) {
            all.push(MethodSpec {
                name: k.title(),
                scope: Scope::Axis,
                verb: Verb::Op(k),
                inputs: k.params().iter().map(param_arg).collect(),
                doc: k.summary(),
            });
        }
        all
    })
}

pub fn spec(name: &str, scope: Scope) -> Option<&'static MethodSpec> {
    methods()
        .iter()
        .find(|m| m.name == name && m.scope == scope)
}

/// Longest Timeout accepted (the range of `home_timeout`).
pub const MAX_TIMEOUT_S: f64 = 86_400.0;
/// Longest lease of a hold-to-run call (Jog's Duration): an HMI that holds
/// longer calls again within it; one that hangs, or whose link is cut,
/// stops the axis within this bound — whatever its session's timeout.
pub const MAX_JOG_S: f64 = 1.0;
/// Largest |number| taken (the daemon applies the axis's own limits; this
/// only keeps absurd numbers off the wire).
pub const MAX_ABS: f64 = 1e12;

/// What the control service is asked.
#[derive(Clone, Debug, PartialEq)]
pub enum Call {
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
    /// An operation of the engine on one axis, as its spec declares it.
    Operate {
        axis: String,
        op: Operation,
    },
}

impl Call {
    /// The typed control request.
    pub fn typed(&self) -> Request {
        let named = |a: &Vec<String>| Axes::from_names(a);
        match self {
            Call::Home {
                axes,
                parallel,
                timeout_s,
            } => Request::Home {
                axes: named(axes),
                parallel: *parallel,
                timeout_s: (*timeout_s > 0.0).then_some(*timeout_s),
            },
            Call::Stop { axes } => Request::Stop { axes: named(axes) },
            Call::Unhome { axes } => Request::Unhome { axes: named(axes) },
            Call::Operate { axis, op } => Request::Operate {
                axes: Axes::Named(vec![axis.clone()]),
                op: *op,
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
pub fn decode(spec: &MethodSpec, axis: Option<&str>, args: &[Variant]) -> Result<Call, CallError> {
    if args.len() > spec.inputs.len() {
        return Err(CallError::Status(StatusCode::BadTooManyArguments));
    }
    let axes = match (spec.scope, axis) {
        (Scope::Axis, Some(a)) => vec![a.to_string()],
        (Scope::Axis, None) => return Err(CallError::Status(StatusCode::BadMethodInvalid)),
        (Scope::Machine, _) => Vec::new(),
    };
    match spec.verb {
        Verb::Op(kind) => decode_op(kind, axes.concat(), args),
        verb => decode_own(spec, verb, axes, args),
    }
}

/// Home, Stop, Unhome and their machine-wide forms: every argument given.
fn decode_own(
    spec: &MethodSpec,
    verb: Verb,
    mut axes: Vec<String>,
    args: &[Variant],
) -> Result<Call, CallError> {
    if args.len() < spec.inputs.len() {
        return Err(CallError::Status(StatusCode::BadArgumentsMissing));
    }
    let mut results = vec![StatusCode::Good; args.len()];
    let (mut timeout_s, mut parallel) = (0.0, false);
    for (i, (a, s)) in args.iter().zip(&spec.inputs).enumerate() {
        let r = match s.name {
            "Timeout" => timeout(a).map(|t| timeout_s = t),
            "Parallel" => boolean(a).map(|b| parallel = b),
            "Axes" => names(a).map(|n| axes = n),
            _ => Err(StatusCode::BadInvalidArgument),
        };
        if let Err(e) = r {
            results[i] = e;
        }
    }
    if results.iter().any(|r| r.is_bad()) {
        return Err(CallError::Args(results));
    }
    Ok(match verb {
        Verb::Home => Call::Home {
            axes,
            parallel,
            timeout_s,
        },
        Verb::Stop => Call::Stop { axes },
        Verb::Unhome | Verb::Op(_) => Call::Unhome { axes },
    })
}

/// An operation of the engine: each argument by its parameter.
fn decode_op(kind: OpKind, axis: String, args: &[Variant]) -> Result<Call, CallError> {
    let params = kind.params();
    let needed = params.iter().rposition(given).map_or(0, |i| i + 1);
    if args.len() < needed {
        return Err(CallError::Status(StatusCode::BadArgumentsMissing));
    }
    let mut c = Carried::EMPTY;
    let results: Vec<StatusCode> = (args.iter().zip(params))
        .map(|(a, p)| param(p, a, &mut c).err().unwrap_or(StatusCode::Good))
        .collect();
    if results.iter().any(|r| r.is_bad()) {
        return Err(CallError::Args(results));
    }
    // Every argument was checked against its parameter: what remains is
    // a parameter the call left out that must be given.
    let op = Operation::take(kind, &c)
        .map_err(|_| CallError::Status(StatusCode::BadArgumentsMissing))?;
    Ok(Call::Operate { axis, op })
}

/// A parameter a call must give: a number, choice or axis that has no
/// default — and the lease of a hold-to-run call, which its caller states
/// (it is the one that renews it).
fn given(p: &Param) -> bool {
    matches!(p.kind, Kind::Number | Kind::Choice(_) | Kind::Axis) || p.form == Form::Lease
}

/// One argument of an operation into `c`, where its parameter is carried.
fn param(p: &Param, v: &Variant, c: &mut Carried) -> Result<(), StatusCode> {
    let slot = match p.place {
        Place::Slot(s) => s,
        _ => 0,
    };
    let empty = matches!(v, Variant::Empty);
    match p.kind {
        _ if empty && given(p) => Err(StatusCode::BadTypeMismatch),
        Kind::Optional | Kind::Switch | Kind::Pair if empty => Ok(()),
        Kind::Number | Kind::Optional => {
            let lease = p.form == Form::Lease;
            let x = bounded(v, |x| {
                x.abs() <= MAX_ABS && (!lease || (x > 0.0 && x <= MAX_JOG_S))
            })?;
            c.values[slot] = x;
            Ok(())
        }
        Kind::Switch => {
            if let (true, Place::Bit(b)) = (boolean(v)?, p.place) {
                c.switches |= 1 << b;
            }
            Ok(())
        }
        Kind::Choice(choices) => {
            let Variant::String(s) = v else {
                return Err(StatusCode::BadTypeMismatch);
            };
            let i = choices.iter().position(|x| *x == s.as_ref());
            c.values[slot] = i.ok_or(StatusCode::BadOutOfRange)? as f64;
            Ok(())
        }
        Kind::Axis => {
            let Variant::String(s) = v else {
                return Err(StatusCode::BadTypeMismatch);
            };
            match params::AxisRef::named(s.as_ref()) {
                Some(params::AxisRef::Name(n)) => {
                    c.name = n;
                    Ok(())
                }
                _ => Err(StatusCode::BadOutOfRange),
            }
        }
        Kind::Pair => {
            let Variant::Array(a) = v else {
                return Err(StatusCode::BadTypeMismatch);
            };
            let [lo, hi] = a.values.as_slice() else {
                return Err(StatusCode::BadOutOfRange);
            };
            c.values[slot] = bounded(lo, |x| x.abs() <= MAX_ABS)?;
            c.values[slot + 1] = bounded(hi, |x| x.abs() <= MAX_ABS)?;
            Ok(())
        }
    }
}

fn boolean(v: &Variant) -> Result<bool, StatusCode> {
    match v {
        Variant::Boolean(b) => Ok(*b),
        _ => Err(StatusCode::BadTypeMismatch),
    }
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
            doc: Cow::Borrowed("the control service accepted the request"),
        },
        ArgSpec {
            name: "Reason",
            data_type: DataTypeId::String,
            array: false,
            doc: Cow::Borrowed("\"accepted\", or why it was refused (the control service's words)"),
        },
        ArgSpec {
            name: "ERR",
            data_type: DataTypeId::UInt16,
            array: false,
            doc: Cow::Borrowed("the instruction's ERR where it has one, else 0"),
        },
        ArgSpec {
            name: "EXERR",
            data_type: DataTypeId::UInt16,
            array: false,
            doc: Cow::Borrowed("the instruction's EXERR where it has one, else 0"),
        },
    ];
    const MACHINE: &[ArgSpec] = &[
        ArgSpec {
            name: "Axes",
            data_type: DataTypeId::String,
            array: true,
            doc: Cow::Borrowed("the axes the request addressed"),
        },
        ArgSpec {
            name: "Accepted",
            data_type: DataTypeId::Boolean,
            array: true,
            doc: Cow::Borrowed("per axis"),
        },
        ArgSpec {
            name: "Reasons",
            data_type: DataTypeId::String,
            array: true,
            doc: Cow::Borrowed("per axis: \"accepted\" or why refused"),
        },
        ArgSpec {
            name: "ERR",
            data_type: DataTypeId::UInt16,
            array: true,
            doc: Cow::Borrowed("per axis"),
        },
        ArgSpec {
            name: "EXERR",
            data_type: DataTypeId::UInt16,
            array: true,
            doc: Cow::Borrowed("per axis"),
        },
        ArgSpec {
            name: "Message",
            data_type: DataTypeId::String,
            array: false,
            doc: Cow::Borrowed("the control service's message (empty when accepted)"),
        },
    ];
    match scope {
        Scope::Axis => AXIS,
        Scope::Machine => MACHINE,
    }
}

#[cfg(test)]
mod tests;
