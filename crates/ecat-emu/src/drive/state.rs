//! The CiA 402 states as the drive (slave side) has them, and their
//! statusword bits: what the state machine (`cia402.rs`) moves between and
//! what the motion (`motion.rs`) acts on, in a file of its own so that
//! neither imports the other.

/// CiA 402 states (slave side).
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
    /// The statusword's state bits.
    pub(super) fn bits(self) -> u16 {
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
}
