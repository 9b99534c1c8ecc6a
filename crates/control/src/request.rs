//! A control request as typed values: decoded from the wire once, at the
//! edge ([`Request::decode`]), so the daemon applies its rules to an enum
//! and never to kinds and flags; encoded the same way by Rust clients
//! ([`Request::encode`]). The bytes stay those of [`ControlRequest`]
//! (the Python package in `python/` speaks them): an unknown kind is a
//! decode error, never some other request.
//!
//! An operation of the engine ([`Request::Operate`]) is carried as the
//! engine declares it: its kind's number and its spec's parameters in the
//! slots the spec gives them ([`motion_homing::params`]), so this file
//! names no operation's parameter and a new operation needs nothing here.

use crate::message::*;
use motion_homing::params::{Carried, Refused};
use motion_homing::{OpKind, Operation};

/// The axes a request names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Axes {
    /// No name: every axis (for `home`: the axes "home all" homes, in home
    /// order).
    All,
    /// These names (axes or gantries), as sent.
    Named(Vec<String>),
}

impl Axes {
    /// From names as a client has them: none means every axis.
    pub fn from_names(names: &[String]) -> Self {
        if names.is_empty() {
            Axes::All
        } else {
            Axes::Named(names.to_vec())
        }
    }

    /// The names, empty for every axis.
    pub fn names(&self) -> &[String] {
        match self {
            Axes::All => &[],
            Axes::Named(n) => n,
        }
    }
}

/// Which statistics: since the supervisor started, or since the last reset.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Since {
    #[default]
    Start,
    Reset,
}

/// What a client asks of the supervisor.
#[derive(Clone, Debug, PartialEq)]
pub enum Request {
    /// Home `axes` in home order, or all at once with `parallel`;
    /// `timeout_s` (when set: finite, positive, at most a day) stops what
    /// still homes after that long.
    Home {
        axes: Axes,
        parallel: bool,
        timeout_s: Option<f64>,
    },
    /// Stop (MAS) `axes`.
    Stop { axes: Axes },
    /// Clear HomedStatus of `axes`.
    Unhome { axes: Axes },
    /// The status report (JSON).
    Status,
    /// Latency statistics (JSON), a page from `offset`; `reset` starts the
    /// "since reset" statistics anew after answering.
    Stats {
        since: Since,
        reset: bool,
        offset: u64,
    },
    /// Record every cycle of the next homing of one axis (the rules say
    /// "exactly one": a gantry's name or none is refused).
    Trace { axes: Axes },
    /// The recorded trace (CSV), a page from `offset`; `axis` (when named)
    /// must be the traced one.
    TraceFetch { axis: Option<String>, offset: u64 },
    /// The latency histograms as an HdrHistogram log, a page from `offset`.
    Hlog { since: Since, offset: u64 },
    /// An operation of the engine (enable, disable, reset, jog, move, …)
    /// for `axes`, with its parameters as the client gave them (left out:
    /// the axis's default, filled by the engine). A jog is hold to run on
    /// one axis or gantry; its answer's token names it for `JogRenew`.
    Operate { axes: Axes, op: Operation },
    /// Renew the lease of jog `token` (on `axes`; none: wherever it runs);
    /// `end`: end that jog now instead.
    JogRenew { axes: Axes, token: u64, end: bool },
    /// Take `axes` over for the setpoint stream of program `owner`, whose
    /// publishing iceoryx2 node is `node_id`.
    StreamAcquire {
        axes: Axes,
        owner: String,
        node_id: u128,
    },
    /// End the stream of owner `token`.
    StreamRelease { token: u64 },
}

/// A request the supervisor cannot take as it is.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum DecodeError {
    #[error("unknown request kind {0}")]
    UnknownKind(u32),
    #[error("no operation a client may ask for has the number {0}")]
    UnknownOperation(u32),
    #[error("{op}: {refused}")]
    Param { op: &'static str, refused: Refused },
}

/// Longest `timeout_s` taken (a day); longer ones are cut to it.
const TIMEOUT_MAX_S: f64 = 86_400.0;

/// The operation a message carries (`REQ_OPERATE`): a kind clients may
/// ask for, and its parameters as its spec reads them.
fn operation(m: &ControlRequest) -> Result<Operation, DecodeError> {
    let kind = u8::try_from(m.op)
        .ok()
        .and_then(OpKind::from_number)
        .filter(|k| k.client())
        .ok_or(DecodeError::UnknownOperation(m.op))?;
    let carried = Carried {
        values: m.values,
        switches: m.switches,
        name: m.name,
    };
    Operation::take(kind, &carried).map_err(|refused| DecodeError::Param {
        op: kind.name(),
        refused,
    })
}

impl Request {
    /// The request a message carries (its layout and key were checked by
    /// the server). Names are read as UTF-8 (invalid bytes replaced).
    pub fn decode(m: &ControlRequest) -> Result<Request, DecodeError> {
        let axes = || Axes::from_names(&m.axis_names());
        let since = if m.flags & FLAG_SINCE_RESET != 0 {
            Since::Reset
        } else {
            Since::Start
        };
        Ok(match m.kind {
            REQ_HOME => Request::Home {
                axes: axes(),
                parallel: m.flags & FLAG_PARALLEL != 0,
                timeout_s: (m.timeout_s.is_finite() && m.timeout_s > 0.0)
                    .then(|| m.timeout_s.min(TIMEOUT_MAX_S)),
            },
            REQ_STOP => Request::Stop { axes: axes() },
            REQ_UNHOME => Request::Unhome { axes: axes() },
            REQ_STATUS => Request::Status,
            REQ_STATS => Request::Stats {
                since,
                reset: m.flags & FLAG_RESET != 0,
                offset: m.offset,
            },
            REQ_TRACE => Request::Trace { axes: axes() },
            REQ_TRACE_FETCH => Request::TraceFetch {
                // An empty name names nothing.
                axis: m.axis_names().into_iter().next().filter(|a| !a.is_empty()),
                offset: m.offset,
            },
            REQ_HLOG => Request::Hlog {
                since,
                offset: m.offset,
            },
            REQ_OPERATE => Request::Operate {
                axes: axes(),
                op: operation(m)?,
            },
            REQ_JOG_RENEW => Request::JogRenew {
                axes: axes(),
                token: m.token,
                end: m.flags & FLAG_END != 0,
            },
            REQ_STREAM_ACQUIRE => Request::StreamAcquire {
                axes: axes(),
                owner: get_str(&m.name),
                node_id: u128::from(m.node_id[0]) | u128::from(m.node_id[1]) << 64,
            },
            REQ_STREAM_RELEASE => Request::StreamRelease { token: m.token },
            k => return Err(DecodeError::UnknownKind(k)),
        })
    }

    /// The message for this request (layout, key and request id are the
    /// client's to set); `None` if it names more than [`MAX_AXES`] axes or
    /// a name longer than [`NAME_LEN`] bytes.
    pub fn encode(&self) -> Option<Box<ControlRequest>> {
        let mut m = ControlRequest::zeroed();
        let since = |s: &Since| match s {
            Since::Start => 0,
            Since::Reset => FLAG_SINCE_RESET,
        };
        let names: &[String] = match self {
            Request::Home {
                axes,
                parallel,
                timeout_s,
            } => {
                m.kind = REQ_HOME;
                m.flags = if *parallel { FLAG_PARALLEL } else { 0 };
                m.timeout_s = timeout_s.unwrap_or(0.0);
                axes.names()
            }
            Request::Stop { axes } => {
                m.kind = REQ_STOP;
                axes.names()
            }
            Request::Unhome { axes } => {
                m.kind = REQ_UNHOME;
                axes.names()
            }
            Request::Status => {
                m.kind = REQ_STATUS;
                &[]
            }
            Request::Stats {
                since: s,
                reset,
                offset,
            } => {
                m.kind = REQ_STATS;
                m.flags = since(s) | if *reset { FLAG_RESET } else { 0 };
                m.offset = *offset;
                &[]
            }
            Request::Trace { axes } => {
                m.kind = REQ_TRACE;
                axes.names()
            }
            Request::TraceFetch { axis, offset } => {
                m.kind = REQ_TRACE_FETCH;
                m.offset = *offset;
                axis.as_slice()
            }
            Request::Hlog { since: s, offset } => {
                m.kind = REQ_HLOG;
                m.flags = since(s);
                m.offset = *offset;
                &[]
            }
            Request::Operate { axes, op } => {
                m.kind = REQ_OPERATE;
                m.op = u32::from(op.kind() as u8);
                let c = op.carried();
                (m.values, m.switches, m.name) = (c.values, c.switches, c.name);
                axes.names()
            }
            Request::JogRenew { axes, token, end } => {
                m.kind = REQ_JOG_RENEW;
                m.token = *token;
                m.flags = if *end { FLAG_END } else { 0 };
                axes.names()
            }
            Request::StreamAcquire {
                axes,
                owner,
                node_id,
            } => {
                if owner.len() > NAME_LEN {
                    return None;
                }
                m.kind = REQ_STREAM_ACQUIRE;
                put_str(&mut m.name, owner);
                m.node_id = [*node_id as u64, (*node_id >> 64) as u64];
                axes.names()
            }
            Request::StreamRelease { token } => {
                m.kind = REQ_STREAM_RELEASE;
                m.token = *token;
                &[]
            }
        };
        m.set_axes(names).then_some(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use motion_homing::{JogSpec, MoveSpec};

    fn named(n: &[&str]) -> Axes {
        Axes::Named(n.iter().map(|s| s.to_string()).collect())
    }

    #[test]
    fn every_request_survives_the_wire() {
        for r in [
            Request::Home {
                axes: Axes::All,
                parallel: false,
                timeout_s: None,
            },
            Request::Home {
                axes: named(&["X", "Y"]),
                parallel: true,
                timeout_s: Some(2.5),
            },
            Request::Stop {
                axes: named(&["Z"]),
            },
            Request::Unhome { axes: Axes::All },
            Request::Status,
            Request::Stats {
                since: Since::Reset,
                reset: true,
                offset: 0,
            },
            Request::Stats {
                since: Since::Start,
                reset: false,
                offset: 32768,
            },
            Request::Trace {
                axes: named(&["C"]),
            },
            Request::TraceFetch {
                axis: None,
                offset: 65536,
            },
            Request::TraceFetch {
                axis: Some("C".into()),
                offset: 0,
            },
            Request::Hlog {
                since: Since::Reset,
                offset: 7,
            },
            Request::Operate {
                axes: Axes::All,
                op: Operation::Enable,
            },
            Request::Operate {
                axes: named(&["X"]),
                op: Operation::Disable,
            },
            Request::Operate {
                axes: named(&["X", "Y"]),
                op: Operation::Reset,
            },
            Request::Operate {
                axes: named(&["X"]),
                op: Operation::Jog(JogSpec {
                    speed: -2.5,
                    lease: Some(0.5),
                    accel: None,
                    decel: Some(40.0),
                    jerk: None,
                }),
            },
            Request::JogRenew {
                axes: Axes::All,
                token: 0xdead_beef_0123_4567,
                end: false,
            },
            Request::JogRenew {
                axes: named(&["X"]),
                token: 1,
                end: true,
            },
            Request::Operate {
                axes: named(&["Y"]),
                op: Operation::Move(MoveSpec {
                    relative: true,
                    speed: Some(3.0),
                    accel: Some(100.0),
                    ..MoveSpec::to(12.5)
                }),
            },
            Request::Operate {
                axes: named(&["Y"]),
                op: Operation::Move(MoveSpec::to(-1.0)),
            },
            Request::StreamAcquire {
                axes: named(&["X", "Y"]),
                owner: "cnc".into(),
                node_id: u128::MAX - 12345,
            },
            Request::StreamRelease { token: 77 },
        ] {
            let m = r.encode().expect("encodes");
            assert_eq!(Request::decode(&m), Ok(r));
        }
    }

    #[test]
    fn an_unknown_kind_is_an_error_not_another_request() {
        for k in [0, 10, 14, 17, 99, u32::MAX] {
            let mut m = ControlRequest::zeroed();
            m.kind = k;
            assert_eq!(Request::decode(&m), Err(DecodeError::UnknownKind(k)));
        }
    }

    /// An operation's number must be one a client may ask for; its
    /// parameters are its spec's, each refused by name.
    #[test]
    fn an_operation_is_a_client_s_kind_with_its_spec_s_parameters() {
        let mut m = ControlRequest::zeroed();
        m.kind = REQ_OPERATE;
        for op in [
            0,
            OpKind::StreamStart as u32,
            OpKind::Stop as u32,
            99,
            256 + 1,
        ] {
            m.op = op;
            assert_eq!(
                Request::decode(&m),
                Err(DecodeError::UnknownOperation(op)),
                "{op}"
            );
        }
        // A jog's speed must be given: NaN is left out.
        m.op = OpKind::Jog as u32;
        m.values = [f64::NAN; OP_SLOTS];
        let e = Request::decode(&m).unwrap_err();
        assert_eq!(e.to_string(), "jog: speed must be given");
        m.values[0] = 3.0;
        let Ok(Request::Operate { op, .. }) = Request::decode(&m) else {
            panic!("a jog");
        };
        assert_eq!(op, Operation::Jog(JogSpec::at(3.0)));
    }

    #[test]
    fn hostile_timeouts_and_names_are_bounded() {
        let mut m = ControlRequest::zeroed();
        m.kind = REQ_HOME;
        for (t, want) in [
            (f64::NAN, None),
            (f64::INFINITY, None),
            (-1.0, None),
            (0.0, None),
            (1e12, Some(86_400.0)),
            (0.5, Some(0.5)),
        ] {
            m.timeout_s = t;
            let Ok(Request::Home { timeout_s, .. }) = Request::decode(&m) else {
                panic!("home");
            };
            assert_eq!(timeout_s, want, "{t}");
        }
        m.axis_count = u32::MAX;
        let Ok(Request::Home { axes, .. }) = Request::decode(&m) else {
            panic!("home");
        };
        assert_eq!(axes.names().len(), MAX_AXES);
        let long = Request::Stop {
            axes: Axes::Named(vec!["x".repeat(NAME_LEN + 1)]),
        };
        assert!(long.encode().is_none());
    }
}
