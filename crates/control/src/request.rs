//! A control request as typed values: decoded from the wire once, at the
//! edge ([`Request::decode`]), so the daemon applies its rules to an enum
//! and never to kinds and flags; encoded the same way by Rust clients
//! ([`Request::encode`]). The bytes stay those of [`ControlRequest`]
//! (the Python package in `python/` speaks them): an unknown kind is a
//! decode error, never some other request.

use crate::message::*;

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
    /// MSO: enable the drives of `axes`, holding position.
    Enable { axes: Axes },
    /// MSF: disable the drives of `axes` (a moving axis is stopped first).
    Disable { axes: Axes },
    /// MAFR: clear the axis faults of `axes`, ask their drives for a fault
    /// reset.
    Reset { axes: Axes },
    /// MAJ, hold to run: jog `axes` (one axis or one gantry) at `speed`
    /// (signed) while the lease is renewed; `accel`/`decel` `None`: the
    /// axis's homing ones. (A jog replaces a running jog; on a moving axis
    /// it is refused, ERR 3: nothing supersedes a move but another move.)
    Jog {
        axes: Axes,
        speed: f64,
        accel: Option<f64>,
        decel: Option<f64>,
        lease_ms: u32,
    },
    /// Renew the lease of jog `token` (on `axes`; none: wherever it runs);
    /// `end`: end that jog now instead.
    JogRenew { axes: Axes, token: u64, end: bool },
    /// MAM: move `axes` to `position` (`relative`: by it); `None`: the
    /// axis's homing speed, acceleration, deceleration.
    Move {
        axes: Axes,
        position: f64,
        relative: bool,
        speed: Option<f64>,
        accel: Option<f64>,
        decel: Option<f64>,
        supersede: bool,
    },
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
}

/// Longest `timeout_s` taken (a day); longer ones are cut to it.
const TIMEOUT_MAX_S: f64 = 86_400.0;

/// NaN on the wire: "the axis's default".
fn param(x: f64) -> Option<f64> {
    (!x.is_nan()).then_some(x)
}

/// A parameter for the wire: `None` is NaN.
fn wire(x: Option<f64>) -> f64 {
    x.unwrap_or(f64::NAN)
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
            REQ_ENABLE => Request::Enable { axes: axes() },
            REQ_DISABLE => Request::Disable { axes: axes() },
            REQ_RESET => Request::Reset { axes: axes() },
            REQ_JOG => Request::Jog {
                axes: axes(),
                speed: m.speed,
                accel: param(m.accel),
                decel: param(m.decel),
                lease_ms: m.lease_ms,
            },
            REQ_JOG_RENEW => Request::JogRenew {
                axes: axes(),
                token: m.token,
                end: m.flags & FLAG_END != 0,
            },
            REQ_MOVE => Request::Move {
                axes: axes(),
                position: m.position,
                relative: m.flags & FLAG_RELATIVE != 0,
                speed: param(m.speed),
                accel: param(m.accel),
                decel: param(m.decel),
                supersede: m.flags & FLAG_SUPERSEDE != 0,
            },
            REQ_STREAM_ACQUIRE => Request::StreamAcquire {
                axes: axes(),
                owner: get_str(&m.owner),
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
            Request::Enable { axes } => {
                m.kind = REQ_ENABLE;
                axes.names()
            }
            Request::Disable { axes } => {
                m.kind = REQ_DISABLE;
                axes.names()
            }
            Request::Reset { axes } => {
                m.kind = REQ_RESET;
                axes.names()
            }
            Request::Jog { .. } | Request::Move { .. } => return self.encode_motion(m),
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
                put_str(&mut m.owner, owner);
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

    /// `encode` of a jog or a move (the motion parameters; NaN for a
    /// default).
    fn encode_motion(&self, mut m: Box<ControlRequest>) -> Option<Box<ControlRequest>> {
        let supersede = |s: bool| if s { FLAG_SUPERSEDE } else { 0 };
        let names = match self {
            Request::Jog {
                axes,
                speed,
                accel,
                decel,
                lease_ms,
            } => {
                m.kind = REQ_JOG;
                (m.speed, m.accel, m.decel) = (*speed, wire(*accel), wire(*decel));
                m.lease_ms = *lease_ms;
                axes.names()
            }
            Request::Move {
                axes,
                position,
                relative,
                speed,
                accel,
                decel,
                supersede: s,
            } => {
                m.kind = REQ_MOVE;
                m.flags = supersede(*s) | if *relative { FLAG_RELATIVE } else { 0 };
                m.position = *position;
                (m.speed, m.accel, m.decel) = (wire(*speed), wire(*accel), wire(*decel));
                axes.names()
            }
            _ => return None,
        };
        m.set_axes(names).then_some(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
            Request::Enable { axes: Axes::All },
            Request::Disable {
                axes: named(&["X"]),
            },
            Request::Reset {
                axes: named(&["X", "Y"]),
            },
            Request::Jog {
                axes: named(&["X"]),
                speed: -2.5,
                accel: None,
                decel: Some(40.0),
                lease_ms: 500,
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
            Request::Move {
                axes: named(&["Y"]),
                position: 12.5,
                relative: true,
                speed: Some(3.0),
                accel: Some(100.0),
                decel: None,
                supersede: false,
            },
            Request::Move {
                axes: named(&["Y"]),
                position: -1.0,
                relative: false,
                speed: None,
                accel: None,
                decel: None,
                supersede: true,
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
        for k in [0, 17, 99, u32::MAX] {
            let mut m = ControlRequest::zeroed();
            m.kind = k;
            assert_eq!(Request::decode(&m), Err(DecodeError::UnknownKind(k)));
        }
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
