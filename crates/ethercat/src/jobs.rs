//! Background jobs of the bus thread, run between cycles one at a time
//! (their frames share the socket with the cycle's): bringing a SubDevice
//! back to OP, looking for one that stopped answering, re-configuring one
//! that was power-cycled, writing an axis' following error window over SDO.

use ethercrab::error::Error;
use ethercrab::{Command, MainDevice};

use crate::group::OpGroup;
use crate::reconfigure::{self, Recovery};

/// A background job.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Job {
    /// SubDevice `i` is out of OP but answers: acknowledge its AL error, or
    /// ask SAFE-OP for OP.
    Recover(usize),
    /// SubDevice `i` does not answer: is it at its bus position without its
    /// station address (power-cycled)?
    Probe(usize),
    /// SubDevice `i` lost its configuration: set it up again.
    Reconfigure(usize),
    /// 0x6065 of axis `axis` = `value`.
    Window { axis: usize, value: u32 },
}

impl Job {
    /// How long the job may take before it counts as failed, ns.
    pub fn timeout_ns(self) -> u64 {
        match self {
            Job::Reconfigure(_) => 15_000_000_000,
            _ => 500_000_000,
        }
    }
}

/// How a job ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Done {
    /// An AL error acknowledged; its AL status code.
    Acknowledged {
        code: u16,
    },
    OpRequested,
    AlreadyOp,
    /// INIT / PRE-OP, or found without its station address: power-cycled,
    /// its configuration is gone.
    LostConfiguration,
    /// Still nobody at its bus position.
    Unreachable,
    Reconfigured,
    WindowWritten,
}

/// Runs `job` (`sd_of_axis`: the SubDevice of each axis).
pub(crate) async fn run(
    job: Job,
    sd_of_axis: &[usize],
    recovery: &Recovery,
    group: &OpGroup,
    md: &MainDevice<'_>,
) -> Result<Done, Error> {
    match job {
        Job::Recover(i) => {
            let sd = group.subdevice(md, i)?;
            let st: u16 = sd.register_read(0x0130u16).await?;
            if st & 0x10 != 0 {
                let code: u16 = sd.register_read(0x0134u16).await.unwrap_or(0);
                sd.register_write(0x0120u16, (st & 0x0F) | 0x10).await?;
                return Ok(Done::Acknowledged { code });
            }
            match st & 0x0F {
                0x08 => Ok(Done::AlreadyOp),
                0x04 => {
                    sd.register_write(0x0120u16, 0x0008u16).await?;
                    Ok(Done::OpRequested)
                }
                _ => Ok(Done::LostConfiguration),
            }
        }
        Job::Probe(i) => {
            let sd = group.subdevice(md, i)?;
            let at = u16::try_from(i).unwrap_or(u16::MAX);
            match Command::aprd(at, 0x0010).receive::<u16>(md).await {
                Ok(a) if a != sd.configured_address() => Ok(Done::LostConfiguration),
                Ok(_) => Ok(Done::AlreadyOp),
                Err(_) => Ok(Done::Unreachable),
            }
        }
        Job::Reconfigure(i) => match reconfigure::run(i, recovery, group, md).await {
            Ok(()) => Ok(Done::Reconfigured),
            Err(e) => {
                recovery.failed(i, e);
                Err(Error::Internal)
            }
        },
        Job::Window { axis, value } => {
            let sd = group.subdevice(md, sd_of_axis[axis])?;
            sd.sdo_write(0x6065, 0, value).await?;
            Ok(Done::WindowWritten)
        }
    }
}
