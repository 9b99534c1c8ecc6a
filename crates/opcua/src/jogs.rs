//! The hold-to-run jogs started by Jog calls, kept by the bridge thread.
//!
//! An OPC UA jog is hold to run like motionctl's: its lease is the call's
//! Duration (at most [`crate::methods::MAX_JOG_S`]), and the control
//! service stops the axis when the lease runs out unless the jog is
//! renewed — and only a new Jog call renews it. A call is authorised like
//! any other (`manager.rs`: the client certificate still trusted, the
//! session over Sign & Encrypt, its user an operator), so every renewal is
//! checked again; a client that hangs, whose link is cut or whose HMI
//! froze with its session open stops the axis within its lease, whatever
//! the session's timeout. If `motion-opcua` itself dies, nothing renews
//! either.
//!
//! A Jog call by the same session on the same axis at the same speed while
//! its jog runs renews that jog (for the lease of the call that started
//! it) instead of starting a new one: the call an HMI repeats while its
//! button is held. Between calls the bridge ends a jog at once when its
//! session is gone or its caller may no longer call (a certificate no
//! longer trusted, a role taken away): [`Watch::may_run`], checked on
//! every pass of the bridge's loop.
//!
//! No I/O here: the bridge sends what [`Jogs::due`] says.

use std::time::{Duration, Instant};

/// May the jog of a session go on? `Err(why)` when not.
pub type MayRun = Box<dyn Fn() -> Result<(), &'static str> + Send>;

/// Who asked for a jog: the session (its numeric id) and whether it may
/// still run a jog.
pub struct Watch {
    pub session: u32,
    pub may_run: MayRun,
}

struct Running {
    axis: String,
    speed: f64,
    token: u64,
    session: u32,
    may_run: MayRun,
    /// The supervisor stops it by itself after this (the lease).
    until: Instant,
    lease: Duration,
}

/// A jog the bridge ends now, and why (for the log).
#[derive(Clone, Debug, PartialEq)]
pub struct End {
    pub axis: String,
    pub token: u64,
    pub why: &'static str,
}

/// The running jogs (at most one per axis).
#[derive(Default)]
pub struct Jogs {
    running: Vec<Running>,
}

impl Jogs {
    pub fn new() -> Self {
        Self::default()
    }

    /// The token of the jog of `session` at `speed` on `axis`, if one runs
    /// (a Jog call for it is a renewal).
    pub fn running(&self, axis: &str, speed: f64, session: u32) -> Option<u64> {
        self.running
            .iter()
            .find(|r| r.axis == axis && r.session == session && r.speed == speed)
            .map(|r| r.token)
    }

    /// The supervisor renewed jog `token` at `now`.
    pub fn renewed(&mut self, token: u64, now: Instant) {
        if let Some(r) = self.running.iter_mut().find(|r| r.token == token) {
            r.until = now + r.lease;
        }
    }

    /// The control service accepted a jog (`token`) with `lease`. A jog
    /// this one replaced on the axis is forgotten (the supervisor replaced
    /// it too).
    pub fn started(
        &mut self,
        axis: &str,
        speed: f64,
        lease: Duration,
        token: u64,
        watch: Watch,
        now: Instant,
    ) {
        self.running.retain(|r| r.axis != axis);
        self.running.push(Running {
            axis: axis.to_string(),
            speed,
            token,
            session: watch.session,
            may_run: watch.may_run,
            until: now + lease,
            lease,
        });
    }

    /// The jogs to end now (their session is gone or may no longer call);
    /// those whose lease ran out are forgotten (the supervisor stopped
    /// them).
    pub fn due(&mut self, now: Instant) -> Vec<End> {
        let mut out = Vec::new();
        self.running.retain(|r| {
            if now >= r.until {
                log::info!(
                    "jog on axis {} ended: its lease ran out (not called again within its Duration)",
                    r.axis
                );
                return false;
            }
            match (r.may_run)() {
                Ok(()) => true,
                Err(why) => {
                    out.push(End {
                        axis: r.axis.clone(),
                        token: r.token,
                        why,
                    });
                    false
                }
            }
        });
        out
    }

    /// A renewal of `token` was refused: the jog ended otherwise (a stop,
    /// a limit, a fault, its lease).
    pub fn gone(&mut self, token: u64) {
        self.running.retain(|r| r.token != token);
    }

    /// Every jog ended (shutting down): what to send.
    pub fn end_all(&mut self, why: &'static str) -> Vec<End> {
        self.running
            .drain(..)
            .map(|r| End {
                axis: r.axis,
                token: r.token,
                why,
            })
            .collect()
    }

    /// The daemon is gone: its jogs with it.
    pub fn forget(&mut self) {
        self.running.clear();
    }

    pub fn len(&self) -> usize {
        self.running.len()
    }

    pub fn is_empty(&self) -> bool {
        self.running.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU8, Ordering};
    use std::sync::Arc;

    const MS: Duration = Duration::from_millis(1);

    /// 0: may run; 1: session gone; 2: no longer an operator.
    fn watch(session: u32, state: &Arc<AtomicU8>) -> Watch {
        let s = state.clone();
        Watch {
            session,
            may_run: Box::new(move || match s.load(Ordering::Acquire) {
                0 => Ok(()),
                1 => Err("the session that started it is gone"),
                _ => Err("its caller may no longer call"),
            }),
        }
    }

    #[test]
    fn a_jog_lasts_its_lease_from_the_last_call_and_no_longer() {
        let t0 = Instant::now();
        let ok = Arc::new(AtomicU8::new(0));
        let mut j = Jogs::new();
        j.started("X", 5.0, 1000 * MS, 7, watch(1, &ok), t0);
        assert_eq!(j.running("X", 5.0, 1), Some(7));
        assert_eq!(j.running("X", 5.0, 2), None, "another session's call");
        assert_eq!(j.running("X", -5.0, 1), None, "another speed");
        assert!(j.due(t0 + 900 * MS).is_empty());
        j.renewed(7, t0 + 900 * MS);
        assert!(j.due(t0 + 1800 * MS).is_empty(), "renewed for its lease");
        assert_eq!(j.len(), 1);
        assert!(j.due(t0 + 1900 * MS).is_empty(), "lease over: forgotten");
        assert!(j.is_empty());
    }

    #[test]
    fn a_jog_ends_at_once_when_its_caller_may_no_longer_run_it() {
        let t0 = Instant::now();
        for (state, why) in [
            (1, "the session that started it is gone"),
            (2, "its caller may no longer call"),
        ] {
            let s = Arc::new(AtomicU8::new(0));
            let mut j = Jogs::new();
            j.started("X", 5.0, 1000 * MS, 8, watch(1, &s), t0);
            assert!(j.due(t0 + MS).is_empty());
            s.store(state, Ordering::Release);
            let e = j.due(t0 + 2 * MS);
            assert_eq!((e.len(), e[0].token, e[0].why), (1, 8, why));
            assert!(j.is_empty());
        }
    }

    #[test]
    fn a_new_jog_replaces_the_axis_s_and_refusals_forget() {
        let t0 = Instant::now();
        let ok = Arc::new(AtomicU8::new(0));
        let mut j = Jogs::new();
        j.started("X", 5.0, 1000 * MS, 1, watch(1, &ok), t0);
        j.started("Y", 5.0, 1000 * MS, 2, watch(1, &ok), t0);
        j.started("X", -5.0, 1000 * MS, 3, watch(2, &ok), t0);
        assert_eq!(j.len(), 2);
        j.gone(3);
        assert_eq!(j.len(), 1);
        let s = j.end_all("stopping");
        assert_eq!((s.len(), s[0].token), (1, 2));
        assert!(j.is_empty());
    }
}
