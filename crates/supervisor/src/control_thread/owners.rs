//! The programs that own axes (setpoint stream), as the control thread
//! knows them: token, name, the iceoryx2 node that publishes, the axes.
//! The cycle keeps only the tokens; names are for the status and the log.
//!
//! Liveness: every [`CHECK_EVERY`] the owners' nodes are looked up in the
//! domain's node list (`Node::list`, which reads files and allocates: here,
//! never in the cycle); an owner whose node is not alive — it died, or the
//! id it named was never a node — has its stream released, which stops its
//! axes. (A program that stops publishing is stopped sooner by the engines'
//! own bound, `stream_timeout_ms`; this check ends the ownership of a dead
//! one that was at rest, and of one that named a node it does not have.)

use std::time::{Duration, Instant};

use iceoryx2::node::{Node, NodeState, NodeView};
use iceoryx2::prelude::{ipc, CallbackProgression};

use crate::shared::Snapshot;

/// How often the owners' nodes are checked.
pub const CHECK_EVERY: Duration = Duration::from_millis(100);

/// One owner.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Owner {
    pub token: u64,
    pub name: String,
    pub node_id: u128,
    pub mask: u64,
    /// A snapshot has shown the token (snapshots trail the cycle by up to
    /// 10 ms: one taken before the grant does not know it yet).
    pub seen: bool,
}

/// Every owner, and when their nodes were last checked.
pub struct Owners {
    list: Vec<Owner>,
    next_check: Instant,
    config: Option<iceoryx2::config::Config>,
}

impl Owners {
    /// `config`: the domain's iceoryx2 config (`None`: no liveness check).
    pub fn new(config: Option<iceoryx2::config::Config>) -> Self {
        Self {
            list: Vec::new(),
            next_check: Instant::now(),
            config,
        }
    }

    pub fn add(&mut self, o: Owner) {
        self.list.retain(|x| x.token != o.token);
        self.list.push(o);
    }

    /// Forgets `token`; its owner, if it was one.
    pub fn remove(&mut self, token: u64) -> Option<Owner> {
        let k = self.list.iter().position(|o| o.token == token)?;
        Some(self.list.swap_remove(k))
    }

    /// The name of the program holding `token`.
    pub fn name_of(&self, token: u64) -> Option<&str> {
        (token != 0)
            .then(|| self.list.iter().find(|o| o.token == token))
            .flatten()
            .map(|o| o.name.as_str())
    }

    /// Owners whose stream the cycle has ended (a snapshot showed their
    /// token, and no axis of the newest names it any more): forgotten, and
    /// returned for the log.
    pub fn prune(&mut self, snap: &Snapshot) -> Vec<Owner> {
        let live = |t: u64| snap.axes[..snap.axis_count].iter().any(|a| a.owner == t);
        for o in &mut self.list {
            o.seen |= live(o.token);
        }
        let (keep, gone): (Vec<Owner>, Vec<Owner>) =
            (self.list.drain(..)).partition(|o| !o.seen || live(o.token));
        self.list = keep;
        gone
    }

    /// Every [`CHECK_EVERY`]: the owners whose node is not alive.
    pub fn dead(&mut self) -> Vec<Owner> {
        if self.list.is_empty() || Instant::now() < self.next_check {
            return Vec::new();
        }
        self.next_check = Instant::now() + CHECK_EVERY;
        let Some(cfg) = &self.config else {
            return Vec::new();
        };
        let mut alive: Vec<u128> = Vec::new();
        let listed = Node::<ipc::Service>::list(cfg, |state| {
            if let NodeState::Alive(v) = state {
                alive.push(v.id().value());
            }
            CallbackProgression::Continue
        });
        if listed.is_err() {
            // Not known: judged again at the next check.
            return Vec::new();
        }
        self.list
            .iter()
            .filter(|o| !alive.contains(&o.node_id))
            .cloned()
            .collect()
    }
}
