//! The CiA 402 (IEC 61800-7-201) drive state machine, master side.
//!
//! Pure and sans-I/O: every bus cycle the statusword (0x6041) goes in and
//! the controlword (0x6040) comes out. ethercrab has no CiA 402 support; this
//! module is all of it.
//!
//! ```text
//!            power on
//!               │
//!   ┌───────────▼──────────┐   (automatic)
//!   │ Not ready to switch on│─────────────┐
//!   └───────────────────────┘             ▼
//!                              ┌────────────────────┐  fault reset (bit 7 ↑)  ┌───────┐
//!            ┌────────────────▶│ Switch on disabled │◀────────────────────────│ Fault │
//!            │ disable voltage └────────────────────┘                         └───▲───┘
//!            │                      │ shutdown ▲                                  │
//!            │                      ▼          │ shutdown            ┌────────────┴─────────┐
//!            │               ┌────────────────────┐                  │ Fault reaction active │◀── any state
//!            ├───────────────│ Ready to switch on │                  └──────────────────────┘    on a fault
//!            │               └────────────────────┘
//!            │                      │ switch on ▲ shutdown
//!            │                      ▼           │
//!            │               ┌────────────────────┐
//!            ├───────────────│    Switched on     │
//!            │               └────────────────────┘
//!            │                      │ enable operation ▲ disable operation
//!            │                      ▼                  │
//!            │               ┌────────────────────┐  quick stop  ┌───────────────────┐
//!            └───────────────│ Operation enabled  │─────────────▶│ Quick stop active │──▶ (disable voltage)
//!                            └────────────────────┘              └───────────────────┘
//! ```
//!
//! [`Cia402::step`] walks the drive towards a [`Target`] one transition per
//! cycle, always commanding the transition the *reported* state allows, so a
//! drive that lags a few cycles or refuses a transition is simply asked
//! again. A fault is reset only on request ([`Cia402::request_fault_reset`]):
//! bit 7 low for one cycle, then high (the rising edge is the command) until
//! the drive leaves Fault or [`FAULT_RESET_CYCLES`] pass.
//!
//! Kept apart on purpose from the drive side the test fixture emulates
//! (`ecat-emu`'s `drive::cia402`), although both spell the same states and
//! statusword codes: each is written from the standard on its own, so that
//! one misreading of it shared by both could not pass the wire tests that
//! pit one against the other.

/// Statusword (0x6041) bits.
pub mod sw {
    pub const READY_TO_SWITCH_ON: u16 = 1 << 0;
    pub const SWITCHED_ON: u16 = 1 << 1;
    pub const OPERATION_ENABLED: u16 = 1 << 2;
    pub const FAULT: u16 = 1 << 3;
    pub const VOLTAGE_ENABLED: u16 = 1 << 4;
    /// Active *low*: 0 = a quick stop is being executed.
    pub const QUICK_STOP: u16 = 1 << 5;
    pub const SWITCH_ON_DISABLED: u16 = 1 << 6;
    pub const WARNING: u16 = 1 << 7;
    pub const REMOTE: u16 = 1 << 9;
    pub const TARGET_REACHED: u16 = 1 << 10;
    pub const INTERNAL_LIMIT_ACTIVE: u16 = 1 << 11;
    /// CSP: the drive follows the target position.
    pub const CSP_FOLLOWING_TARGET: u16 = 1 << 12;
    /// CSP: following error.
    pub const CSP_FOLLOWING_ERROR: u16 = 1 << 13;

    /// Mask for the states whose code does not use the quick-stop bit.
    pub const MASK_4F: u16 = 0x004F;
    /// Mask for the states whose code uses the quick-stop bit.
    pub const MASK_6F: u16 = 0x006F;
}

/// Controlword (0x6040) bits and the device control commands.
pub mod cw {
    pub const SWITCH_ON: u16 = 1 << 0;
    pub const ENABLE_VOLTAGE: u16 = 1 << 1;
    /// Active *low*: 0 = quick stop.
    pub const QUICK_STOP: u16 = 1 << 2;
    pub const ENABLE_OPERATION: u16 = 1 << 3;
    pub const FAULT_RESET: u16 = 1 << 7;
    pub const HALT: u16 = 1 << 8;

    /// Command "shutdown" (transitions 2, 6, 8): → Ready to switch on.
    pub const CMD_SHUTDOWN: u16 = 0x0006;
    /// Command "switch on" (transition 3) / "disable operation" (5): → Switched on.
    pub const CMD_SWITCH_ON: u16 = 0x0007;
    /// Command "enable operation" (transitions 4, 16): → Operation enabled.
    pub const CMD_ENABLE_OPERATION: u16 = 0x000F;
    /// Command "disable voltage" (transitions 7, 9, 10, 12): → Switch on disabled.
    pub const CMD_DISABLE_VOLTAGE: u16 = 0x0000;
    /// Command "quick stop" (transitions 7, 10, 11): → Quick stop active.
    pub const CMD_QUICK_STOP: u16 = 0x0002;
    /// Command "fault reset" (transition 15, on the rising edge).
    pub const CMD_FAULT_RESET: u16 = 0x0080;
}

/// Cycles bit 7 is held high waiting for the drive to leave Fault; after
/// that the reset counts as failed (the cause persists) and a new request is
/// needed.
pub const FAULT_RESET_CYCLES: u32 = 100;

/// The drive states of CiA 402, decoded from the statusword.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum State {
    NotReadyToSwitchOn,
    SwitchOnDisabled,
    ReadyToSwitchOn,
    SwitchedOn,
    OperationEnabled,
    QuickStopActive,
    FaultReactionActive,
    Fault,
}

impl State {
    /// Decodes 0x6041 with the standard masks (CiA 402-2, statusword table).
    /// A bit pattern the standard does not define (e.g. all bits set) decodes
    /// as `NotReadyToSwitchOn`: never as enabled.
    pub fn from_statusword(word: u16) -> State {
        let s4f = word & sw::MASK_4F;
        let s6f = word & sw::MASK_6F;
        match () {
            _ if s4f == 0x0000 => State::NotReadyToSwitchOn,
            _ if s4f == 0x0040 => State::SwitchOnDisabled,
            _ if s6f == 0x0021 => State::ReadyToSwitchOn,
            _ if s6f == 0x0023 => State::SwitchedOn,
            _ if s6f == 0x0027 => State::OperationEnabled,
            _ if s6f == 0x0007 => State::QuickStopActive,
            _ if s4f == 0x000F => State::FaultReactionActive,
            _ if s4f == 0x0008 => State::Fault,
            _ => State::NotReadyToSwitchOn,
        }
    }

    /// The statusword a drive reports in this state (the state bits only;
    /// voltage enabled set where the power stage is up).
    pub fn statusword(self) -> u16 {
        match self {
            State::NotReadyToSwitchOn => 0x0000,
            State::SwitchOnDisabled => 0x0040,
            State::ReadyToSwitchOn => 0x0021,
            State::SwitchedOn => 0x0033,
            State::OperationEnabled => 0x0037,
            State::QuickStopActive => 0x0017,
            State::FaultReactionActive => 0x001F,
            State::Fault => 0x0008,
        }
    }

    /// Power stage on and following the set-point.
    pub fn is_enabled(self) -> bool {
        self == State::OperationEnabled
    }

    /// Fault or fault reaction.
    pub fn is_fault(self) -> bool {
        matches!(self, State::Fault | State::FaultReactionActive)
    }

    /// Short name for messages.
    pub fn name(self) -> &'static str {
        match self {
            State::NotReadyToSwitchOn => "not ready to switch on",
            State::SwitchOnDisabled => "switch on disabled",
            State::ReadyToSwitchOn => "ready to switch on",
            State::SwitchedOn => "switched on",
            State::OperationEnabled => "operation enabled",
            State::QuickStopActive => "quick stop active",
            State::FaultReactionActive => "fault reaction active",
            State::Fault => "fault",
        }
    }
}

/// Where the master wants the drive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// Power stage off: "shutdown" to Ready to switch on (from Quick stop
    /// active: "disable voltage").
    Disabled,
    /// Operation enabled, one transition per cycle.
    Enabled,
    /// Quick stop: the drive decelerates on its quick-stop ramp (0x6085);
    /// from states without a running power stage this is "disable voltage".
    QuickStop,
    /// "Disable voltage" from every state: power stage off at once, no ramp
    /// (the emergency stop).
    Off,
    /// "Disable operation" (transition 5, Operation enabled → Switched on):
    /// the drive stops following and closes its holding brake (0x605C) with
    /// the power stage still on — the step before disable voltage on an
    /// axis with a brake. Quick stop active stays there (at rest it holds);
    /// states without a running drive function stay where they are.
    DisableOperation,
}

/// Fault-reset handshake progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Reset {
    Idle,
    /// Requested; bit 7 goes high once the last controlword had it low.
    Pending,
    /// Bit 7 high since this many cycles.
    High(u32),
}

/// The master-side state machine of one drive.
#[derive(Clone, Copy, Debug)]
pub struct Cia402 {
    reset: Reset,
    last: u16,
    failed_resets: u32,
}

impl Default for Cia402 {
    fn default() -> Self {
        Self::new()
    }
}

impl Cia402 {
    pub const fn new() -> Self {
        Self {
            reset: Reset::Idle,
            last: cw::CMD_DISABLE_VOLTAGE,
            failed_resets: 0,
        }
    }

    /// Ask for a fault reset. Acted on while the drive reports Fault (after a
    /// fault reaction completes); a request while the drive is not faulted is
    /// dropped at the next [`step`](Self::step).
    pub fn request_fault_reset(&mut self) {
        if self.reset == Reset::Idle {
            self.reset = Reset::Pending;
        }
    }

    /// A reset is requested or in progress.
    pub fn fault_reset_pending(&self) -> bool {
        self.reset != Reset::Idle
    }

    /// Resets that timed out (the drive stayed in Fault).
    pub fn failed_resets(&self) -> u32 {
        self.failed_resets
    }

    /// The controlword sent last.
    pub fn last_controlword(&self) -> u16 {
        self.last
    }

    /// One cycle: the drive's statusword in, the controlword to send out.
    pub fn step(&mut self, statusword: u16, target: Target) -> u16 {
        let state = State::from_statusword(statusword);
        let word = self.command(state, target);
        self.last = word;
        word
    }

    fn command(&mut self, state: State, target: Target) -> u16 {
        match state {
            State::Fault => return self.fault_reset_word(),
            State::FaultReactionActive => {
                // Wait for the reaction to end; keep bit 7 low so the reset
                // edge can follow.
                if let Reset::High(_) = self.reset {
                    self.reset = Reset::Pending;
                }
                return cw::CMD_DISABLE_VOLTAGE;
            }
            _ => {
                // Not (or no longer) in fault: a pending reset is done or moot.
                self.reset = Reset::Idle;
            }
        }
        match (target, state) {
            (_, State::NotReadyToSwitchOn) => cw::CMD_DISABLE_VOLTAGE,

            (Target::Enabled, State::SwitchOnDisabled) => cw::CMD_SHUTDOWN,
            (Target::Enabled, State::ReadyToSwitchOn) => cw::CMD_SWITCH_ON,
            (Target::Enabled, State::SwitchedOn) => cw::CMD_ENABLE_OPERATION,
            (Target::Enabled, State::OperationEnabled) => cw::CMD_ENABLE_OPERATION,
            // Leaving Quick stop active for Operation enabled (transition 16)
            // is optional (0x605A = 5..8); the portable way is back through
            // Switch on disabled.
            (Target::Enabled, State::QuickStopActive) => cw::CMD_DISABLE_VOLTAGE,

            (Target::Disabled, State::QuickStopActive) => cw::CMD_DISABLE_VOLTAGE,
            (Target::Disabled, _) => cw::CMD_SHUTDOWN,

            (Target::QuickStop, _) => cw::CMD_QUICK_STOP,

            (Target::Off, _) => cw::CMD_DISABLE_VOLTAGE,

            (Target::DisableOperation, State::OperationEnabled | State::SwitchedOn) => {
                cw::CMD_SWITCH_ON
            }
            (Target::DisableOperation, State::QuickStopActive) => cw::CMD_QUICK_STOP,
            (Target::DisableOperation, State::ReadyToSwitchOn) => cw::CMD_SHUTDOWN,
            (Target::DisableOperation, _) => cw::CMD_DISABLE_VOLTAGE,

            (_, State::Fault | State::FaultReactionActive) => cw::CMD_DISABLE_VOLTAGE,
        }
    }

    fn fault_reset_word(&mut self) -> u16 {
        match self.reset {
            Reset::Idle => cw::CMD_DISABLE_VOLTAGE,
            Reset::Pending => {
                if self.last & cw::FAULT_RESET != 0 {
                    // bit 7 must be seen low first, or there is no edge
                    cw::CMD_DISABLE_VOLTAGE
                } else {
                    self.reset = Reset::High(1);
                    cw::CMD_FAULT_RESET
                }
            }
            Reset::High(n) => {
                if n >= FAULT_RESET_CYCLES {
                    self.reset = Reset::Idle;
                    self.failed_resets = self.failed_resets.saturating_add(1);
                    cw::CMD_DISABLE_VOLTAGE
                } else {
                    self.reset = Reset::High(n + 1);
                    cw::CMD_FAULT_RESET
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [State; 8] = [
        State::NotReadyToSwitchOn,
        State::SwitchOnDisabled,
        State::ReadyToSwitchOn,
        State::SwitchedOn,
        State::OperationEnabled,
        State::QuickStopActive,
        State::FaultReactionActive,
        State::Fault,
    ];

    #[test]
    fn decode_standard_patterns_and_ignore_other_bits() {
        for s in ALL {
            assert_eq!(State::from_statusword(s.statusword()), s, "{s:?}");
            // remote, target reached, warning, manufacturer bits do not matter
            let noisy = s.statusword() | 0xFE80;
            assert_eq!(State::from_statusword(noisy), s, "{s:?} noisy");
        }
        // the classic values seen on real drives
        assert_eq!(State::from_statusword(0x0250), State::SwitchOnDisabled);
        assert_eq!(State::from_statusword(0x0231), State::ReadyToSwitchOn);
        assert_eq!(State::from_statusword(0x0233), State::SwitchedOn);
        assert_eq!(State::from_statusword(0x1637), State::OperationEnabled);
        assert_eq!(State::from_statusword(0x0217), State::QuickStopActive);
        assert_eq!(State::from_statusword(0x021F), State::FaultReactionActive);
        assert_eq!(State::from_statusword(0x0218), State::Fault);
        // undefined patterns are never "enabled"
        for w in [0x0001u16, 0x0003, 0x0020, 0x0060, 0x0061, 0x006F] {
            assert!(!State::from_statusword(w).is_enabled(), "{w:#06x}");
        }
        assert!(State::Fault.is_fault() && State::FaultReactionActive.is_fault());
        assert!(ALL.iter().filter(|s| s.is_enabled()).count() == 1);
    }

    /// (state, target) → controlword, every pair, no reset pending.
    #[test]
    fn every_transition_command() {
        use State::*;
        use Target::*;
        let table: [(State, Target, u16); 32] = [
            (NotReadyToSwitchOn, Off, 0x0000),
            (SwitchOnDisabled, Off, 0x0000),
            (ReadyToSwitchOn, Off, 0x0000),  // 7
            (SwitchedOn, Off, 0x0000),       // 10
            (OperationEnabled, Off, 0x0000), // 9
            (QuickStopActive, Off, 0x0000),  // 12
            (FaultReactionActive, Off, 0x0000),
            (Fault, Off, 0x0000),
            (NotReadyToSwitchOn, Enabled, 0x0000),
            (NotReadyToSwitchOn, Disabled, 0x0000),
            (NotReadyToSwitchOn, QuickStop, 0x0000),
            (SwitchOnDisabled, Enabled, 0x0006),  // 2
            (SwitchOnDisabled, Disabled, 0x0006), // stays / prepares
            (SwitchOnDisabled, QuickStop, 0x0002),
            (ReadyToSwitchOn, Enabled, 0x0007),    // 3
            (ReadyToSwitchOn, Disabled, 0x0006),   // stays
            (ReadyToSwitchOn, QuickStop, 0x0002),  // 7
            (SwitchedOn, Enabled, 0x000F),         // 4
            (SwitchedOn, Disabled, 0x0006),        // 6
            (SwitchedOn, QuickStop, 0x0002),       // 10
            (OperationEnabled, Enabled, 0x000F),   // stays
            (OperationEnabled, Disabled, 0x0006),  // 8
            (OperationEnabled, QuickStop, 0x0002), // 11
            (QuickStopActive, Enabled, 0x0000),    // 12, then up again
            (QuickStopActive, Disabled, 0x0000),   // 12
            (QuickStopActive, QuickStop, 0x0002),  // stays
            (FaultReactionActive, Enabled, 0x0000),
            (FaultReactionActive, Disabled, 0x0000),
            (FaultReactionActive, QuickStop, 0x0000),
            (Fault, Enabled, 0x0000), // no reset requested: stays in fault
            (Fault, Disabled, 0x0000),
            (Fault, QuickStop, 0x0000),
        ];
        for (state, target, word) in table {
            let mut m = Cia402::new();
            assert_eq!(
                m.step(state.statusword(), target),
                word,
                "{state:?} → {target:?}"
            );
            assert_eq!(m.last_controlword(), word);
        }
    }

    /// A minimal CiA 402 drive that follows the controlword the way the
    /// standard's transition table says, to run the master against.
    fn drive(state: State, word: u16, last_word: u16) -> State {
        use State::*;
        let fault_reset_edge = word & cw::FAULT_RESET != 0 && last_word & cw::FAULT_RESET == 0;
        let ev = word & cw::ENABLE_VOLTAGE != 0;
        let qs = word & cw::QUICK_STOP != 0; // high = no quick stop
        let so = word & cw::SWITCH_ON != 0;
        let eo = word & cw::ENABLE_OPERATION != 0;
        let shutdown = ev && qs && !so;
        let switch_on = ev && qs && so;
        let quick_stop = ev && !qs;
        match state {
            NotReadyToSwitchOn => SwitchOnDisabled,
            SwitchOnDisabled if shutdown => ReadyToSwitchOn,
            ReadyToSwitchOn if switch_on && eo => OperationEnabled,
            ReadyToSwitchOn if switch_on => SwitchedOn,
            ReadyToSwitchOn if !ev || quick_stop => SwitchOnDisabled,
            SwitchedOn if switch_on && eo => OperationEnabled,
            SwitchedOn if shutdown => ReadyToSwitchOn,
            SwitchedOn if !ev || quick_stop => SwitchOnDisabled,
            OperationEnabled if switch_on && !eo => SwitchedOn,
            OperationEnabled if shutdown => ReadyToSwitchOn,
            OperationEnabled if !ev => SwitchOnDisabled,
            OperationEnabled if quick_stop => QuickStopActive,
            QuickStopActive if !ev => SwitchOnDisabled,
            FaultReactionActive => Fault,
            Fault if fault_reset_edge => SwitchOnDisabled,
            s => s,
        }
    }

    fn run(m: &mut Cia402, mut state: State, target: Target, cycles: usize) -> State {
        for _ in 0..cycles {
            let last = m.last_controlword();
            let word = m.step(state.statusword(), target);
            state = drive(state, word, last);
        }
        state
    }

    #[test]
    fn enables_from_power_up_in_four_cycles_and_back() {
        let mut m = Cia402::new();
        let mut s = State::NotReadyToSwitchOn;
        let mut seen = vec![s];
        for _ in 0..4 {
            let last = m.last_controlword();
            s = drive(s, m.step(s.statusword(), Target::Enabled), last);
            seen.push(s);
        }
        assert_eq!(
            seen,
            [
                State::NotReadyToSwitchOn,
                State::SwitchOnDisabled,
                State::ReadyToSwitchOn,
                State::SwitchedOn,
                State::OperationEnabled
            ]
        );
        // stays
        assert_eq!(run(&mut m, s, Target::Enabled, 10), State::OperationEnabled);
        // disable: one cycle to Ready to switch on (power stage off)
        assert_eq!(run(&mut m, s, Target::Disabled, 1), State::ReadyToSwitchOn);
    }

    #[test]
    fn quick_stop_then_re_enable_goes_round_through_switch_on_disabled() {
        let mut m = Cia402::new();
        let s = run(&mut m, State::SwitchOnDisabled, Target::Enabled, 3);
        assert_eq!(s, State::OperationEnabled);
        let s = run(&mut m, s, Target::QuickStop, 1);
        assert_eq!(s, State::QuickStopActive);
        assert_eq!(run(&mut m, s, Target::QuickStop, 5), State::QuickStopActive);
        // a drive with 0x605A = 2 drops to Switch on disabled by itself
        let s = run(&mut m, State::SwitchOnDisabled, Target::QuickStop, 3);
        assert_eq!(s, State::SwitchOnDisabled);
        // enabling from Quick stop active: disable voltage first
        let s = run(&mut m, State::QuickStopActive, Target::Enabled, 1);
        assert_eq!(s, State::SwitchOnDisabled);
        assert_eq!(run(&mut m, s, Target::Enabled, 3), State::OperationEnabled);
        // disabling from Quick stop active
        assert_eq!(
            run(&mut m, State::QuickStopActive, Target::Disabled, 1),
            State::SwitchOnDisabled
        );
    }

    #[test]
    fn fault_stays_without_request_and_resets_on_the_edge() {
        let mut m = Cia402::new();
        let s = run(&mut m, State::FaultReactionActive, Target::Enabled, 20);
        assert_eq!(s, State::Fault, "no reset asked for: stays");
        assert!(!m.fault_reset_pending());

        m.request_fault_reset();
        assert!(m.fault_reset_pending());
        // last word had bit 7 low: the edge goes out at once
        assert_eq!(m.step(State::Fault.statusword(), Target::Enabled), 0x0080);
        let s = drive(State::Fault, 0x0080, 0x0000);
        assert_eq!(s, State::SwitchOnDisabled);
        // then up as usual, request consumed
        assert_eq!(run(&mut m, s, Target::Enabled, 3), State::OperationEnabled);
        assert!(!m.fault_reset_pending());
    }

    #[test]
    fn fault_reset_waits_for_the_reaction_and_needs_bit7_low_first() {
        let mut m = Cia402::new();
        m.request_fault_reset();
        // during the reaction: bit 7 low, request kept
        assert_eq!(
            m.step(State::FaultReactionActive.statusword(), Target::Enabled),
            0x0000
        );
        assert!(m.fault_reset_pending());
        assert_eq!(m.step(State::Fault.statusword(), Target::Enabled), 0x0080);

        // a drive that does not leave fault (cause persists): bit 7 held,
        // then dropped after FAULT_RESET_CYCLES and counted
        let mut m = Cia402::new();
        m.request_fault_reset();
        let mut high = 0;
        for _ in 0..(FAULT_RESET_CYCLES + 5) {
            if m.step(State::Fault.statusword(), Target::Enabled) & cw::FAULT_RESET != 0 {
                high += 1;
            }
        }
        assert_eq!(high, FAULT_RESET_CYCLES);
        assert_eq!(m.failed_resets(), 1);
        assert!(!m.fault_reset_pending());
        // a new request produces a new edge (bit 7 was low in the last word)
        m.request_fault_reset();
        assert_eq!(m.step(State::Fault.statusword(), Target::Enabled), 0x0080);

        // when the last word had bit 7 high (e.g. a reset that raced a new
        // fault), it is first dropped for one cycle
        let mut m = Cia402::new();
        m.request_fault_reset();
        assert_eq!(m.step(State::Fault.statusword(), Target::Enabled), 0x0080);
        // the drive faults again during the reaction...
        assert_eq!(
            m.step(State::FaultReactionActive.statusword(), Target::Enabled),
            0x0000
        );
        assert_eq!(m.step(State::Fault.statusword(), Target::Enabled), 0x0080);
    }

    #[test]
    fn reset_request_without_fault_is_dropped() {
        let mut m = Cia402::new();
        m.request_fault_reset();
        assert_eq!(
            m.step(State::SwitchOnDisabled.statusword(), Target::Enabled),
            0x0006
        );
        assert!(!m.fault_reset_pending());
        // a later fault is not reset by that old request
        assert_eq!(m.step(State::Fault.statusword(), Target::Enabled), 0x0000);
    }

    #[test]
    fn reset_during_reset_is_one_request() {
        let mut m = Cia402::new();
        m.request_fault_reset();
        assert_eq!(m.step(State::Fault.statusword(), Target::Disabled), 0x0080);
        m.request_fault_reset(); // already in progress: no restart
        assert_eq!(m.step(State::Fault.statusword(), Target::Disabled), 0x0080);
        // leaving fault ends it; disabled target then shuts down
        assert_eq!(
            m.step(State::SwitchOnDisabled.statusword(), Target::Disabled),
            0x0006
        );
        assert!(!m.fault_reset_pending());
    }

    #[test]
    fn disable_operation_keeps_the_power_stage_for_the_brake() {
        use State::*;
        for (state, word) in [
            (OperationEnabled, 0x0007), // 5
            (SwitchedOn, 0x0007),
            (QuickStopActive, 0x0002), // holds at rest
            (ReadyToSwitchOn, 0x0006),
            (SwitchOnDisabled, 0x0000),
        ] {
            assert_eq!(
                Cia402::new().step(state.statusword(), Target::DisableOperation),
                word,
                "{state:?}"
            );
        }
        let s = drive(OperationEnabled, 0x0007, 0x000F);
        assert_eq!(s, SwitchedOn);
    }

    #[test]
    fn garbage_statuswords_never_enable() {
        let mut m = Cia402::new();
        for w in 0..=u16::MAX {
            let word = m.step(w, Target::Enabled);
            // only the defined device control commands ever go out
            assert!(
                [0x0000, 0x0002, 0x0006, 0x0007, 0x000F, 0x0080].contains(&word),
                "{w:#06x} → {word:#06x}"
            );
        }
    }
}
