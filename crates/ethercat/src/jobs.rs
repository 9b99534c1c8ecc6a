//! Background jobs of the bus thread, run between cycles one at a time
//! (their frames share the socket with the cycle's): bringing a SubDevice
//! back to OP, writing an axis' following error window over SDO.

use ethercrab::error::Error;
use ethercrab::MainDevice;

use crate::group::OpGroup;

/// A background job.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Job {
    /// SubDevice `i` is out of OP but answers: acknowledge its AL error, or
    /// ask SAFE-OP for OP.
    Recover(usize),
    /// 0x6065 of axis `axis` = `value`.
    Window { axis: usize, value: u32 },
}

/// How a job ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Done {
    Acknowledged,
    OpRequested,
    AlreadyOp,
    /// INIT / PRE-OP: power-cycled, its configuration is gone.
    LostConfiguration,
    WindowWritten,
}

/// Runs `job` (`sd_of_axis`: the SubDevice of each axis).
pub(crate) async fn run(
    job: Job,
    sd_of_axis: &[usize],
    group: &OpGroup,
    md: &MainDevice<'_>,
) -> Result<Done, Error> {
    match job {
        Job::Recover(i) => {
            let sd = group.subdevice(md, i)?;
            let st: u16 = sd.register_read(0x0130u16).await?;
            if st & 0x10 != 0 {
                sd.register_write(0x0120u16, (st & 0x0F) | 0x10).await?;
                return Ok(Done::Acknowledged);
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
        Job::Window { axis, value } => {
            let sd = group.subdevice(md, sd_of_axis[axis])?;
            sd.sdo_write(0x6065, 0, value).await?;
            Ok(Done::WindowWritten)
        }
    }
}
