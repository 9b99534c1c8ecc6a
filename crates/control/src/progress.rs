//! Homing progress for a person: on a terminal one live line per axis
//! (phase, position, elapsed), redrawn in place; elsewhere (a log, a pipe)
//! one plain line per change of phase or result.

use std::io::{IsTerminal, Write};

use crate::message::*;

pub struct Progress {
    tty: bool,
    drawn: usize,
    /// Per followed axis: (phase, bits) last printed.
    last: Vec<(String, u16)>,
}

impl Progress {
    /// Progress on stderr (stdout may carry JSON).
    pub fn new() -> Self {
        Self {
            tty: std::io::stderr().is_terminal(),
            drawn: 0,
            last: Vec::new(),
        }
    }

    fn line(a: &AxisStatusEntry) -> String {
        let pos = if a.has(ST_FEEDBACK) {
            format!("{:>12.4}", a.position)
        } else {
            format!("{:>12}", "-")
        };
        let state = if a.has(ST_ER) {
            format!("ER {}/{}", a.err, a.exerr)
        } else if a.has(ST_PC) {
            "PC".to_string()
        } else if a.has(ST_IP) {
            "IP".to_string()
        } else if a.extra & SX_IN_SEQUENCE != 0 {
            "waiting".to_string()
        } else if a.has(ST_HOMED) {
            "homed".to_string()
        } else {
            String::new()
        };
        format!(
            "{:<10} {:<12} pos {pos}  {:>7.2} s  {state}",
            get_str(&a.name),
            get_str(&a.phase),
            a.elapsed_s
        )
    }

    /// A line of an operation (jog, move, stream): position, command and
    /// what the axis does.
    fn motion_line(a: &AxisStatusEntry) -> String {
        let val = |ok: bool, x: f64| {
            if ok && x.is_finite() {
                format!("{x:>12.4}")
            } else {
                format!("{:>12}", "-")
            }
        };
        let state = if a.has(ST_ER) {
            format!("ER {}/{}", a.err, a.exerr)
        } else if a.has(ST_STOPPING) {
            "stopping".to_string()
        } else if a.motion_has(MS_JOGGING) {
            "jogging".to_string()
        } else if a.motion_has(MS_MOVING) {
            "moving".to_string()
        } else if a.motion_has(MS_STREAMING) {
            "streaming".to_string()
        } else if a.op_flags & OP_PC != 0 {
            "done".to_string()
        } else {
            "at rest".to_string()
        };
        format!(
            "{:<10} pos {}  cmd {}  {state}",
            get_str(&a.name),
            val(a.has(ST_FEEDBACK), a.position),
            val(a.motion_has(MS_COMMAND), a.cmd_position),
        )
    }

    /// Shows the axes `members` of `st` as an operation's progress (jog,
    /// move, stream).
    pub fn show_motion(&mut self, st: &StatusFrame, members: &[usize]) {
        self.draw(st, members, Self::motion_line, |a| {
            a.bits & (ST_ER | ST_STOPPING) | a.motion << 8
        });
    }

    /// Shows the axes `members` of `st`.
    pub fn show(&mut self, st: &StatusFrame, members: &[usize]) {
        self.draw(st, members, Self::line, |a| {
            a.bits & (ST_ER | ST_PC | ST_IP | ST_HOMED)
        });
    }

    /// On a terminal every line redrawn in place; elsewhere a line per
    /// axis whenever its phase or `key` bits change.
    fn draw(
        &mut self,
        st: &StatusFrame,
        members: &[usize],
        line: fn(&AxisStatusEntry) -> String,
        key: fn(&AxisStatusEntry) -> u16,
    ) {
        let mut err = std::io::stderr().lock();
        if self.tty {
            if self.drawn > 0 {
                let _ = write!(err, "\x1b[{}F", self.drawn);
            }
            for &i in members {
                let _ = writeln!(err, "\x1b[2K{}", line(&st.axes[i]));
            }
            self.drawn = members.len();
        } else {
            if self.last.len() != members.len() {
                self.last = vec![(String::new(), 0); members.len()];
            }
            for (k, &i) in members.iter().enumerate() {
                let a = &st.axes[i];
                let key = (get_str(&a.phase), key(a));
                if key != self.last[k] {
                    let _ = writeln!(err, "{}", line(a));
                    self.last[k] = key;
                }
            }
        }
    }
}

impl Default for Progress {
    fn default() -> Self {
        Self::new()
    }
}
