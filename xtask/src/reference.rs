//! The reference the QEMU run is checked against, computed on the host by the
//! same core library the firmware links.

use anyhow::{Result, anyhow};
use idle_head_core::motion::{DEFAULT_HEAD, DEFAULT_N, HeadTrajectories, Integral16};

/// Checksum of the three default loops (`DEFAULT_HEAD`, `DEFAULT_N` samples,
/// `Integral16` storage with its loop scales), as the firmware prints it in its summary line.
pub fn checksum() -> Result<u32> {
    let mut head = Box::new(HeadTrajectories::<Integral16, DEFAULT_N>::new());
    head.generate(&DEFAULT_HEAD)
        .map_err(|error| anyhow!("generating the default loops on the host: {error}"))?;
    Ok(head.checksum())
}
