//! The hold-to-run jogs started by Jog calls, kept by the bridge thread.
//!
//! The control service runs a jog only while its lease is renewed
//! ([`crate::methods::JOG_LEASE_MS`]). The bridge renews it every
//! [`crate::methods::JOG_RENEW_MS`] — but only while the calling session
//! lives and the call's Duration has not run out; then it ends the jog
//! (a renewal with the end flag: a stop of this jog only). If
//! `motion-opcua` itself dies, the renewals stop and the supervisor's
//! lease runs out: the jog stops within [`crate::methods::JOG_LEASE_MS`].
//!
//! A Jog call by the same session on the same axis at the same speed while
//! its jog runs extends the Duration instead of starting a new jog: that is
//! the keep-alive an HMI sends while its button is held.
//!
//! No I/O here: the bridge sends what [`Jogs::due`] says.

use std::time::{Duration, Instant};

/// Is the session that started a jog still there?
pub type Alive = Box<dyn Fn() -> bool + Send>;

/// Who asked for a jog: the session (its numeric id) and how to tell that
/// it still lives.
pub struct Watch {
    pub session: u32,
    pub alive: Alive,
}

struct Running {
    axis: String,
    speed: f64,
    token: u64,
    session: u32,
    alive: Alive,
    until: Instant,
    next: Instant,
}

/// What the bridge sends for a jog now.
#[derive(Clone, Debug, PartialEq)]
pub struct Renewal {
    pub axis: String,
    pub token: u64,
    /// End the jog (else: renew its lease).
    pub end: bool,
    /// Why it ends, for the log.
    pub why: &'static str,
}

/// The running jogs (at most one per axis).
pub struct Jogs {
    running: Vec<Running>,
    every: Duration,
}

impl Jogs {
    pub fn new(every: Duration) -> Self {
        Self {
            running: Vec::new(),
            every,
        }
    }

    /// A Jog call of `session`: if its jog at `speed` runs on `axis`,
    /// extends it to `duration` from `now` and returns its token.
    pub fn extend(
        &mut self,
        axis: &str,
        speed: f64,
        duration: Duration,
        session: u32,
        now: Instant,
    ) -> Option<u64> {
        let r = self
            .running
            .iter_mut()
            .find(|r| r.axis == axis && r.session == session && r.speed == speed)?;
        r.until = now + duration;
        Some(r.token)
    }

    /// The control service accepted a jog (`token`): renew it from now on.
    /// A jog this one replaced on the axis is forgotten (the supervisor
    /// replaced it too).
    pub fn started(
        &mut self,
        axis: &str,
        speed: f64,
        duration: Duration,
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
            alive: watch.alive,
            until: now + duration,
            next: now + self.every,
        });
    }

    /// The renewals and ends due at `now`; ended jogs are forgotten.
    pub fn due(&mut self, now: Instant) -> Vec<Renewal> {
        let mut out = Vec::new();
        let every = self.every;
        self.running.retain_mut(|r| {
            let why = if now >= r.until {
                Some("its duration ran out")
            } else if !(r.alive)() {
                Some("the session that started it is gone")
            } else {
                None
            };
            if let Some(why) = why {
                out.push(Renewal {
                    axis: r.axis.clone(),
                    token: r.token,
                    end: true,
                    why,
                });
                return false;
            }
            if now >= r.next {
                r.next = now + every;
                out.push(Renewal {
                    axis: r.axis.clone(),
                    token: r.token,
                    end: false,
                    why: "",
                });
            }
            true
        });
        out
    }

    /// A renewal of `token` was refused: the jog ended otherwise (a stop,
    /// a limit, a fault, a lease the supervisor let run out).
    pub fn gone(&mut self, token: u64) {
        self.running.retain(|r| r.token != token);
    }

    /// Every jog ended (shutting down): what to send.
    pub fn end_all(&mut self, why: &'static str) -> Vec<Renewal> {
        self.running
            .drain(..)
            .map(|r| Renewal {
                axis: r.axis,
                token: r.token,
                end: true,
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
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;

    const MS: Duration = Duration::from_millis(1);

    fn watch(session: u32, alive: &Arc<AtomicBool>) -> Watch {
        let a = alive.clone();
        Watch {
            session,
            alive: Box::new(move || a.load(Ordering::Acquire)),
        }
    }

    #[test]
    fn renewed_until_the_duration_runs_out_or_the_session_goes() {
        let t0 = Instant::now();
        let alive = Arc::new(AtomicBool::new(true));
        let mut j = Jogs::new(100 * MS);
        j.started("X", 5.0, 1000 * MS, 7, watch(1, &alive), t0);
        assert!(j.due(t0 + 50 * MS).is_empty());
        let s = j.due(t0 + 100 * MS);
        assert_eq!((s.len(), s[0].token, s[0].end), (1, 7, false));
        assert!(j.due(t0 + 150 * MS).is_empty(), "once per period");
        // The same session, same speed: extended, no new jog.
        assert_eq!(j.extend("X", 5.0, 1000 * MS, 1, t0 + 900 * MS), Some(7));
        assert_eq!(j.extend("X", 5.0, 1000 * MS, 2, t0 + 900 * MS), None);
        assert_eq!(j.extend("X", -5.0, 1000 * MS, 1, t0 + 900 * MS), None);
        assert!(j.due(t0 + 1500 * MS).iter().all(|s| !s.end));
        let s = j.due(t0 + 1900 * MS);
        assert_eq!(
            (s[0].end, s[0].why),
            (true, "its duration ran out"),
            "ends at the extended time"
        );
        assert!(j.is_empty());

        j.started("X", 5.0, 5000 * MS, 8, watch(1, &alive), t0);
        alive.store(false, Ordering::Release);
        let s = j.due(t0 + MS);
        assert_eq!(
            (s[0].token, s[0].end, s[0].why),
            (8, true, "the session that started it is gone")
        );
        assert!(j.is_empty());
    }

    #[test]
    fn a_new_jog_replaces_the_axis_s_and_refusals_forget() {
        let t0 = Instant::now();
        let alive = Arc::new(AtomicBool::new(true));
        let mut j = Jogs::new(100 * MS);
        j.started("X", 5.0, 1000 * MS, 1, watch(1, &alive), t0);
        j.started("Y", 5.0, 1000 * MS, 2, watch(1, &alive), t0);
        j.started("X", -5.0, 1000 * MS, 3, watch(2, &alive), t0);
        assert_eq!(j.len(), 2);
        j.gone(3);
        assert_eq!(j.len(), 1);
        let s = j.end_all("stopping");
        assert_eq!((s.len(), s[0].token, s[0].end), (1, 2, true));
        assert!(j.is_empty());
    }
}
