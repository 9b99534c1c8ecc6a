//! The SubDevice group in OP, with or without distributed clocks: the two
//! ethercrab group types behind one enum, and what the bus thread does with
//! the group as a whole (one cyclic exchange, leaving OP).

use std::time::Duration;

use ethercrab::error::Error;
use ethercrab::subdevice_group::{HasDc, NoDc, Op};
use ethercrab::{
    DefaultLock, MainDevice, SubDeviceGroup, SubDevicePdi, SubDeviceRef, SubDeviceState,
};

use crate::capacity::{MAX_PDI, MAX_SUBDEVICES};

/// A group of the bus's capacity.
pub(crate) type Group<S, DC> = SubDeviceGroup<MAX_SUBDEVICES, MAX_PDI, DefaultLock, S, DC>;

/// A SubDevice of the group with its process data.
pub(crate) type Pdi<'a> = SubDeviceRef<'a, SubDevicePdi<'a, MAX_PDI, DefaultLock>>;

/// The group the bus thread cycles.
pub(crate) enum OpGroup {
    FreeRun(Group<Op, NoDc>),
    Dc(Group<Op, HasDc>),
}

/// What one cyclic exchange brought back.
pub(crate) struct Exchanged {
    /// Working counter of the process-data datagram.
    pub wkc: u16,
    /// AL state of every SubDevice (`None`: it did not answer).
    pub states: heapless::Vec<SubDeviceState, MAX_SUBDEVICES>,
    /// With DC: the wait until the next cycle (SYNC0 + half a cycle).
    pub next_wait: Option<Duration>,
}

impl OpGroup {
    pub fn subdevice<'a>(&'a self, md: &'a MainDevice<'a>, i: usize) -> Result<Pdi<'a>, Error> {
        match self {
            OpGroup::FreeRun(g) => g.subdevice(md, i),
            OpGroup::Dc(g) => g.subdevice(md, i),
        }
    }

    pub fn len(&self) -> usize {
        match self {
            OpGroup::FreeRun(g) => g.len(),
            OpGroup::Dc(g) => g.len(),
        }
    }

    /// One process-data exchange (LRW + AL status, + the DC time with DC).
    pub async fn exchange(&self, md: &MainDevice<'_>) -> Result<Exchanged, Error> {
        match self {
            OpGroup::FreeRun(g) => {
                let r = g.tx_rx(md).await?;
                Ok(Exchanged {
                    wkc: r.working_counter,
                    states: r.subdevice_states,
                    next_wait: None,
                })
            }
            OpGroup::Dc(g) => {
                let r = g.tx_rx_dc(md).await?;
                Ok(Exchanged {
                    wkc: r.working_counter,
                    states: r.subdevice_states,
                    next_wait: Some(r.extra.next_cycle_wait),
                })
            }
        }
    }

    /// Leaves OP in order: the drives see their outputs go invalid (OP →
    /// SAFE-OP) and stop on their own ramp; then PRE-OP and INIT.
    pub async fn leave(self, md: &MainDevice<'_>) -> Result<(), Error> {
        match self {
            OpGroup::FreeRun(g) => leave(g, md).await,
            OpGroup::Dc(g) => leave(g, md).await,
        }
    }
}

async fn leave<DC>(g: Group<Op, DC>, md: &MainDevice<'_>) -> Result<(), Error> {
    let g = g.into_safe_op(md).await?;
    let g = g.into_pre_op(md).await?;
    g.into_init(md).await.map(|_| ())
}
