//! A control response built from typed values: the outcome of each axis
//! ([`AxisOutcome`], with a [`Reason`] when refused), the request's result
//! and message, a page of data. The bytes are those of [`ControlResponse`];
//! the `REASON_*` and `RESULT_*` numbers are written here and nowhere else
//! on the supervisor's side.

use crate::message::*;

/// Why an axis was refused, in the wire's terms (`REASON_*`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reason {
    /// No axis of that name.
    UnknownAxis,
    /// Homing is already in process on the axis.
    AlreadyHoming,
    /// The axis's I/O process is not attached.
    IoNotAttached,
    /// The Home instruction refuses, with its ERR / EXERR.
    Instruction { err: u16, exerr: u16 },
    /// The supervisor is shutting down.
    Exiting,
    /// The axis is a side of a gantry: name every side.
    Gantry,
    /// Another home sequence is running on the axis.
    Busy,
    /// A program owns the axis (ERR 3, Execution Collision).
    Owned,
    /// The token names no jog or stream of the axis.
    Token,
    /// The operation's instruction refuses, with its ERR / EXERR.
    Operation { err: u16, exerr: u16 },
}

impl Reason {
    /// The `REASON_*` number.
    pub fn code(self) -> u8 {
        match self {
            Reason::UnknownAxis => REASON_UNKNOWN_AXIS,
            Reason::AlreadyHoming => REASON_ALREADY_HOMING,
            Reason::IoNotAttached => REASON_IO_NOT_ATTACHED,
            Reason::Instruction { .. } => REASON_INSTRUCTION,
            Reason::Exiting => REASON_EXITING,
            Reason::Gantry => REASON_GANTRY,
            Reason::Busy => REASON_BUSY,
            Reason::Owned => REASON_OWNED,
            Reason::Token => REASON_TOKEN,
            Reason::Operation { .. } => REASON_OPERATION,
        }
    }

    /// Words for it (as [`reason_text`] of its number).
    pub fn text(self) -> &'static str {
        reason_text(self.code())
    }

    /// The instruction's ERR / EXERR, where it has one.
    pub fn codes(self) -> Option<(u16, u16)> {
        match self {
            Reason::Instruction { err, exerr } | Reason::Operation { err, exerr } => {
                Some((err, exerr))
            }
            Reason::Owned => Some((motion_homing::codes::ERR_EXECUTION_COLLISION, 0)),
            _ => None,
        }
    }
}

/// How one axis of a request came out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisOutcome {
    Accepted,
    /// Refused for no reason of its own: another named axis was refused,
    /// so nothing was started.
    NotStarted,
    Refused(Reason),
}

impl AxisOutcome {
    /// The wire's entry for axis `name` (its index not known here:
    /// [`NO_INDEX`]).
    pub fn answer(self, name: &str) -> AxisAnswer {
        let mut a = AxisAnswer {
            index: NO_INDEX,
            ..AxisAnswer::default()
        };
        put_str(&mut a.name, name);
        match self {
            AxisOutcome::Accepted => a.accepted = 1,
            AxisOutcome::NotStarted => {}
            AxisOutcome::Refused(r) => {
                a.reason = r.code();
                (a.err, a.exerr) = r.codes().unwrap_or((0, 0));
            }
        }
        a
    }
}

impl ControlResponse {
    /// Refused (`RESULT_REFUSED`), with why in words.
    pub fn refuse(&mut self, message: &str) {
        self.result = RESULT_REFUSED;
        put_str(&mut self.message, message);
    }

    /// The request itself is malformed (`RESULT_BAD_REQUEST`).
    pub fn bad_request(&mut self, message: &str) {
        self.result = RESULT_BAD_REQUEST;
        put_str(&mut self.message, message);
    }

    /// Nothing to fetch yet (`RESULT_NOT_READY`).
    pub fn not_ready(&mut self, message: &str) {
        self.result = RESULT_NOT_READY;
        put_str(&mut self.message, message);
    }

    /// Appends the answer of axis `name`; false (and nothing written) once
    /// [`MAX_AXES`] answers are there.
    pub fn push_answer(&mut self, name: &str, outcome: AxisOutcome) -> bool {
        let k = self.axis_count as usize;
        if k >= MAX_AXES {
            return false;
        }
        self.axes[k] = outcome.answer(name);
        self.axis_count += 1;
        true
    }

    /// Appends the answer of axis `name` at config index `index`, with the
    /// engine's operation id where the operation was accepted; false once
    /// [`MAX_AXES`] answers are there.
    pub fn push_axis(
        &mut self,
        name: &str,
        index: usize,
        outcome: AxisOutcome,
        op_id: u32,
    ) -> bool {
        let k = self.axis_count as usize;
        if !self.push_answer(name, outcome) {
            return false;
        }
        self.axes[k].index = u16::try_from(index).unwrap_or(NO_INDEX);
        self.axes[k].op_id = op_id;
        true
    }

    /// Accepted, with the page of `text` that starts at `offset`.
    pub fn page(&mut self, text: &[u8], offset: usize) {
        let end = (offset + DATA_LEN).min(text.len());
        let chunk = &text[offset.min(end)..end];
        self.data[..chunk.len()].copy_from_slice(chunk);
        self.data_len = chunk.len() as u32;
        self.offset = offset as u64;
        self.total = text.len() as u64;
        self.result = RESULT_ACCEPTED;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outcomes_become_the_wires_numbers() {
        let a = AxisOutcome::Refused(Reason::Instruction { err: 41, exerr: 20 }).answer("X");
        assert_eq!(
            (
                get_str(&a.name).as_str(),
                a.accepted,
                a.reason,
                a.err,
                a.exerr
            ),
            ("X", 0, REASON_INSTRUCTION, 41, 20)
        );
        let a = AxisOutcome::Accepted.answer("Y");
        assert_eq!((a.accepted, a.reason), (1, REASON_NONE));
        let a = AxisOutcome::NotStarted.answer("Z");
        assert_eq!((a.accepted, a.reason), (0, REASON_NONE));
        assert_eq!(Reason::Gantry.text(), "part of a gantry: name every side");
    }

    #[test]
    fn answers_and_pages_are_bounded() {
        let mut r = ControlResponse::zeroed();
        for _ in 0..MAX_AXES {
            assert!(r.push_answer("A", AxisOutcome::Accepted));
        }
        assert!(!r.push_answer("B", AxisOutcome::Accepted));
        assert_eq!(r.answers().len(), MAX_AXES);
        let text = vec![b'x'; DATA_LEN + 10];
        r.page(&text, DATA_LEN);
        assert_eq!(
            (r.data_len, r.offset, r.total),
            (10, DATA_LEN as u64, text.len() as u64)
        );
        r.page(&text, text.len() + 5);
        assert_eq!(r.data_len, 0);
    }
}
