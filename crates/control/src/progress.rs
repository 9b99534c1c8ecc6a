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

    /// Shows the axes `members` of `st`.
    pub fn show(&mut self, st: &StatusFrame, members: &[usize]) {
        let mut err = std::io::stderr().lock();
        if self.tty {
            if self.drawn > 0 {
                let _ = write!(err, "\x1b[{}F", self.drawn);
            }
            for &i in members {
                let _ = writeln!(err, "\x1b[2K{}", Self::line(&st.axes[i]));
            }
            self.drawn = members.len();
        } else {
            if self.last.len() != members.len() {
                self.last = vec![(String::new(), 0); members.len()];
            }
            for (k, &i) in members.iter().enumerate() {
                let a = &st.axes[i];
                let key = (
                    get_str(&a.phase),
                    a.bits & (ST_ER | ST_PC | ST_IP | ST_HOMED),
                );
                if key != self.last[k] {
                    let _ = writeln!(err, "{}", Self::line(a));
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
