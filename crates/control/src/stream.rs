//! The supervised setpoint stream as a Rust program uses it: take axes over
//! ([`Client::stream`]: the control service's stream-acquire, which hands
//! out an owner token), publish setpoints ([`Stream::publish`], on
//! `{prefix}/setpoints`), give them back ([`Stream::release`], or drop).
//!
//! The acquire answer's `data` is one line of JSON, [`StreamMap`]: for
//! every name of the request, in request order, the axis index its
//! setpoints address (`index`: for a gantry its first side) and the sides
//! that index moves:
//!
//! ```json
//! {"axes":[{"name":"Y","index":2,"sides":[2,3]},{"name":"X","index":0,"sides":[0]}]}
//! ```
//!
//! The handle publishes from its own iceoryx2 node, whose id the acquire
//! request names: when that node is gone (the program died), the
//! supervisor releases the axes and stops them.

use serde::{Deserialize, Serialize};

use crate::client::{Client, ClientError};
use crate::message::*;
use crate::ops::OpError;
use crate::request::{Axes, Request};
use motion_frames::{SetpointAxis, SP_VELOCITY};
use motion_ipc::{IpcError, SetpointPublisher};

/// One requested name of a stream and where its setpoints go.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct StreamAxis {
    pub name: String,
    /// The axis index setpoints for this name carry (a gantry: its first
    /// side's).
    pub index: u32,
    /// The axes that index moves (a gantry: every side).
    pub sides: Vec<u32>,
}

/// The acquire answer's `data`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct StreamMap {
    pub axes: Vec<StreamAxis>,
}

/// What can go wrong taking axes over.
#[derive(Debug, thiserror::Error)]
pub enum StreamError {
    #[error(transparent)]
    Op(#[from] OpError),
    #[error("setpoint service: {0}")]
    Ipc(#[from] IpcError),
    #[error("the stream-acquire answer has no usable axis map: {0}")]
    Map(String),
}

impl From<ClientError> for StreamError {
    fn from(e: ClientError) -> Self {
        StreamError::Op(OpError::Client(e))
    }
}

/// Axes owned by this program for the setpoint stream.
pub struct Stream<'c> {
    // The publisher before its node: dropped first.
    publisher: SetpointPublisher,
    _node: iceoryx2::node::Node<iceoryx2::prelude::ipc::Service>,
    client: &'c mut Client,
    token: u64,
    map: StreamMap,
    answer: Box<ControlResponse>,
    released: bool,
}

impl Client {
    /// Takes `axes` (names of axes or gantries) over for the setpoint
    /// stream of program `owner`. Refused (with each axis's reason) when an
    /// axis is owned, homing, moving, not enabled, faulted or — unless
    /// `stream_unhomed` — not homed.
    pub fn stream<'c>(
        &'c mut self,
        owner: &str,
        axes: &[String],
    ) -> Result<Stream<'c>, StreamError> {
        let domain = self.domain().clone();
        let node = domain.create_node("motion-stream")?;
        let publisher = SetpointPublisher::open(&node, &domain)?;
        let r = Request::StreamAcquire {
            axes: Axes::Named(axes.to_vec()),
            owner: owner.to_string(),
            node_id: node.id().value(),
        };
        let answer = self.send(&r, std::time::Duration::from_secs(3))?;
        if answer.result != RESULT_ACCEPTED {
            return Err(OpError::Refused(answer).into());
        }
        let map: StreamMap = serde_json::from_slice(answer.data_bytes())
            .map_err(|e| StreamError::Map(e.to_string()))?;
        Ok(Stream {
            publisher,
            _node: node,
            client: self,
            token: answer.token,
            map,
            answer,
            released: false,
        })
    }
}

impl Stream<'_> {
    /// The owner token.
    pub fn token(&self) -> u64 {
        self.token
    }

    /// For each requested name, in request order, where its setpoints go.
    pub fn map(&self) -> &StreamMap {
        &self.map
    }

    /// The acquire answer (per-axis answers with their operation ids).
    pub fn answer(&self) -> &ControlResponse {
        &self.answer
    }

    /// The control client (status, stop, ...), while the stream runs.
    pub fn client(&mut self) -> &mut Client {
        self.client
    }

    /// Publishes one setpoint per requested name (in request order) at the
    /// program's time `t_ns`; `velocity`, when given, is a feed-forward per
    /// name. Returns the frame's sequence number.
    pub fn publish(
        &mut self,
        t_ns: u64,
        positions: &[f64],
        velocity: Option<&[f64]>,
    ) -> Result<u64, StreamError> {
        let map = &self.map;
        Ok(self.publisher.publish(self.token, t_ns, |axes| {
            let n = positions.len().min(map.axes.len()).min(axes.len());
            for k in 0..n {
                let v = velocity.and_then(|v| v.get(k).copied());
                axes[k] = SetpointAxis {
                    axis: map.axes[k].index,
                    flags: if v.is_some() { SP_VELOCITY } else { 0 },
                    position: positions[k],
                    velocity: v.unwrap_or(0.0),
                };
            }
            n
        })?)
    }

    /// Gives the axes back: the stream ends normally and the axes stop.
    pub fn release(mut self) -> Result<Box<ControlResponse>, OpError> {
        self.released = true;
        let r = Request::StreamRelease { token: self.token };
        let resp = self.client.send(&r, std::time::Duration::from_secs(3))?;
        if resp.result == RESULT_ACCEPTED {
            Ok(resp)
        } else {
            Err(OpError::Refused(resp))
        }
    }
}

impl Drop for Stream<'_> {
    /// A stream dropped without `release` is released here (best effort:
    /// without an answer the supervisor still ends it, when this node is
    /// gone or the setpoints stop).
    fn drop(&mut self) {
        if !self.released {
            let r = Request::StreamRelease { token: self.token };
            let _ = self.client.send(&r, std::time::Duration::from_secs(1));
        }
    }
}
