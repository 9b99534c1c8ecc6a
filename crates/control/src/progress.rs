//! Homing progress for a person: on a terminal one live line per axis
//! (phase, position, elapsed), redrawn in place; elsewhere (a log, a pipe)
//! one plain line per change of phase or result.

use std::io::{IsTerminal, Write};

use crate::message::*;

pub struct Progress {
    tty: bool,
    drawn: usize,
    /// Per followed axis: (phase, the flags its line shows) last printed.
    last: Vec<(String, u64)>,
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
        let pos = cell(a.position());
        let state = if a.er() {
            format!("ER {}/{}", a.err(), a.exerr())
        } else if a.pc() {
            "PC".to_string()
        } else if a.ip() {
            "IP".to_string()
        } else if a.in_sequence() {
            "waiting".to_string()
        } else if a.homed() {
            "homed".to_string()
        } else {
            String::new()
        };
        format!(
            "{:<10} {:<12} pos {pos}  {:>7.2} s  {state}",
            a.name_text(),
            a.phase_text(),
            a.elapsed_s()
        )
    }

    /// A line of an operation (jog, move, stream): position, command and
    /// what the axis does.
    fn motion_line(a: &AxisStatusEntry) -> String {
        let state = if a.er() {
            format!("ER {}/{}", a.err(), a.exerr())
        } else if a.stopping() {
            "stopping".to_string()
        } else if let Some(what) = a.in_motion_as() {
            what.to_string()
        } else if a.op_pc() {
            "done".to_string()
        } else {
            "at rest".to_string()
        };
        format!(
            "{:<10} pos {}  cmd {}  {state}",
            a.name_text(),
            cell(a.position()),
            cell(a.cmd_position()),
        )
    }

    /// Shows the axes `members` of `st` as an operation's progress (jog,
    /// move, stream).
    pub fn show_motion(&mut self, st: &StatusFrame, members: &[usize]) {
        let shown = motion_status::axis::mask(&["er", "stopping", "op_pc"]);
        self.draw(
            st,
            members,
            Self::motion_line,
            shown | motion_status::axis::motion_mask(),
        );
    }

    /// Shows the axes `members` of `st`.
    pub fn show(&mut self, st: &StatusFrame, members: &[usize]) {
        let shown = motion_status::axis::mask(&["er", "pc", "ip", "in_sequence", "homed"]);
        self.draw(st, members, Self::line, shown);
    }

    /// On a terminal every line redrawn in place; elsewhere a line per
    /// axis whenever its phase or one of the flags `shown` changes.
    fn draw(
        &mut self,
        st: &StatusFrame,
        members: &[usize],
        line: fn(&AxisStatusEntry) -> String,
        shown: u64,
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
                let key = (a.phase_text(), a.flags & shown);
                if key != self.last[k] {
                    let _ = writeln!(err, "{}", line(a));
                    self.last[k] = key;
                }
            }
        }
    }
}

/// A number for a progress line (`-`: no value).
fn cell(x: Option<f64>) -> String {
    x.map_or(format!("{:>12}", "-"), |v| format!("{v:>12.4}"))
}

impl Default for Progress {
    fn default() -> Self {
        Self::new()
    }
}
