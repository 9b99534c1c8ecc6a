//! The operations of the engine (enable, disable, reset, jog and its
//! renewals, move, and whatever the engine declares next), and the setpoint
//! stream's acquire and release: the rules the control thread applies to a
//! typed request before the cycle sees it, one concern per function —
//! which axes the names mean (a gantry's name for all its sides, a side
//! named alone refused; none: every axis for an operation that says so),
//! an operation's axis parameters by name, one axis or gantry for a
//! hold-to-run one and its token, a named program for a stream, the owner
//! token — then the cycle's answer per axis (the engines' ERR / EXERR), the
//! owners' table and the log line. What these rules need of an operation
//! its kind says (`OpKind::all_by_default`, `OpKind::held`): no operation
//! is named here.

use super::axes::no_answer;
use super::owners::Owner;
use super::ControlThread;
use crate::shared::Ask;
use motion_control::stream::{StreamAxis, StreamMap};
use motion_control::{Axes, ControlResponse};
use motion_homing::Operation;

/// A random token (never 0): names a jog or a stream's owner.
fn token() -> u64 {
    getrandom::u64().unwrap_or_else(|_| motion_rt::now_ns()) | 1
}

impl ControlThread {
    /// An operation of the named axes (none named: every axis, for the
    /// operations that say so), a gantry whole; its axis parameters by
    /// name; a hold-to-run one on one axis or gantry, its answer carrying
    /// the token that names it.
    pub(super) fn operation(&mut self, axes: &Axes, mut op: Operation, r: &mut ControlResponse) {
        let kind = op.kind();
        let what = kind.name();
        let default = if kind.all_by_default() {
            self.every_axis()
        } else {
            0
        };
        let Some(mask) = self.axes_of(axes, default, r) else {
            return;
        };
        if mask == 0 {
            return r.bad_request(&format!("{what} needs an axis"));
        }
        if !self.whole_gantries(mask, r) {
            return;
        }
        let machine = &self.s.machine;
        let mut lookup = |n: &str| machine.axis_index(n).and_then(|i| u16::try_from(i).ok());
        if let Err(e) = op.resolve_axes(&mut lookup) {
            return r.bad_request(&format!("{what}: {e}"));
        }
        if !kind.held() {
            self.deliver(what, mask, op, 0, r);
            return;
        }
        if !self.one_axis_or_gantry(mask) {
            return r.bad_request(&format!("{what} takes one axis or one gantry"));
        }
        let t = token();
        if self.deliver(what, mask, op, t, r) {
            r.token = t;
        }
    }

    /// Renews (or ends) jog `token` (no log line: ten a second).
    pub(super) fn jog_renew(
        &mut self,
        axes: &Axes,
        token: u64,
        end: bool,
        r: &mut ControlResponse,
    ) {
        let Some(mask) = self.axes_of(axes, 0, r) else {
            return;
        };
        let ack = match self.ask(Ask::JogRenew { token, mask, end }) {
            Ok(a) => a,
            Err(u) => return no_answer(r, u),
        };
        let running = (0..self.s.machine.axes.len())
            .filter(|&i| ack.axes[i].accepted())
            .fold(0u64, |m, i| m | 1 << i);
        if running == 0 {
            return r.refuse("no jog of this token runs (it ended: stop, limit, fault, lease)");
        }
        self.answers(running, &ack, r);
        r.result = motion_control::RESULT_ACCEPTED;
    }

    /// Takes the named axes over for program `owner`'s setpoint stream.
    pub(super) fn stream_acquire(
        &mut self,
        axes: &Axes,
        owner: &str,
        node_id: u128,
        r: &mut ControlResponse,
    ) {
        if let Err(e) = motion_config::names::check_name(owner) {
            return r.bad_request(&format!("stream owner: {e}"));
        }
        let Some(mask) = self.axes_of(axes, 0, r) else {
            return;
        };
        if mask == 0 {
            return r.bad_request("stream needs an axis");
        }
        if !self.whole_gantries(mask, r) {
            return;
        }
        let t = token();
        let ack = match self.ask(Ask::StreamAcquire { mask, token: t }) {
            Ok(a) => a,
            Err(u) => return no_answer(r, u),
        };
        let (all, why) = self.answers(mask, &ack, r);
        self.verdict(&format!("stream of {owner}"), mask, all, why, r);
        if !all {
            return;
        }
        r.token = t;
        self.owners.add(Owner {
            token: t,
            name: owner.to_string(),
            node_id,
            mask,
            seen: false,
        });
        let map = self.stream_map(axes);
        r.page(map.as_bytes(), 0);
    }

    /// Ends the stream of `token`.
    pub(super) fn stream_release(&mut self, token: u64, r: &mut ControlResponse) {
        let ack = match self.ask(Ask::StreamRelease { token }) {
            Ok(a) => a,
            Err(u) => return no_answer(r, u),
        };
        let mask = (0..self.s.machine.axes.len())
            .filter(|&i| ack.axes[i].accepted())
            .fold(0u64, |m, i| m | 1 << i);
        if mask == 0 {
            return r.refuse("no stream of this token (released, or ended by a stop or a fault)");
        }
        let (all, why) = self.answers(mask, &ack, r);
        let who = self.owners.remove(token).map_or(String::new(), |o| o.name);
        self.verdict(&format!("stream release of {who}"), mask, all, why, r);
    }

    /// The owners whose node is gone: their streams released (their axes
    /// stop). Every 100 ms, from the thread's loop.
    pub(super) fn check_owners(&mut self) {
        for o in self.owners.dead() {
            let t = o.token;
            let released = self.ask(Ask::StreamRelease { token: t });
            self.owners.remove(t);
            log::warn!(
                "stream owner {} (iceoryx2 node {:x}) is gone: its axes are released and stop{}",
                o.name,
                o.node_id,
                match released {
                    Ok(_) => "",
                    Err(u) => u.text(),
                }
            );
        }
        let hub = self.hub.lock();
        if let Some(snap) = hub.snapshot.as_deref() {
            for o in self.owners.prune(snap) {
                log::info!("the stream of {} ended", o.name);
            }
        }
    }

    /// Sends an operation to the cycle and answers per axis; true when every
    /// axis accepted it.
    fn deliver(
        &mut self,
        what: &str,
        mask: u64,
        op: Operation,
        token: u64,
        r: &mut ControlResponse,
    ) -> bool {
        let ack = match self.ask(Ask::Op { mask, op, token }) {
            Ok(a) => a,
            Err(u) => {
                no_answer(r, u);
                return false;
            }
        };
        let (all, why) = self.answers(mask, &ack, r);
        self.verdict(what, mask, all, why, r);
        all
    }

    /// The mask is one axis, or all sides of one gantry.
    fn one_axis_or_gantry(&self, mask: u64) -> bool {
        let m = &self.s.machine;
        mask.count_ones() == 1
            || m.gantries
                .iter()
                .any(|g| g.axes.iter().fold(0u64, |k, &i| k | 1 << i) == mask)
    }

    /// The acquire answer's map: per requested name, the index its
    /// setpoints address and the sides that index moves (JSON).
    fn stream_map(&self, axes: &Axes) -> String {
        let m = &self.s.machine;
        let entries = axes.names().iter().filter_map(|n| {
            if let Some(g) = m.gantries.iter().find(|g| &g.name == n) {
                let mut sides: Vec<u32> = g.axes.iter().map(|&i| i as u32).collect();
                sides.sort_unstable();
                return Some(StreamAxis {
                    name: n.clone(),
                    index: sides[0],
                    sides,
                });
            }
            let i = m.axis_index(n)?;
            // A side named with the others: its gantry's lead moves them all.
            let mut sides: Vec<u32> = match m.gantry_of(i) {
                Some(g) => m.gantries[g].axes.iter().map(|&k| k as u32).collect(),
                None => vec![i as u32],
            };
            sides.sort_unstable();
            Some(StreamAxis {
                name: n.clone(),
                index: sides[0],
                sides,
            })
        });
        let map = StreamMap {
            axes: entries.collect(),
        };
        serde_json::to_string(&map).unwrap_or_default()
    }
}
