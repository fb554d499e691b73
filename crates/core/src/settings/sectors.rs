//! A NOR flash whose erases go one sector at a time.
//!
//! On a chip that runs its code from the flash it writes (the RP2040's
//! XIP flash), an erase runs with the interrupts off: nothing may read the
//! flash meanwhile. An erase of several sectors in one call keeps them off
//! for all of them, up to 400 ms each (W25Q16JV, worst case), and no frame
//! runs and nothing feeds the watchdog for that long. `sequential-storage`
//! erases its whole range in one call when it starts a store afresh.
//! [`SectorWise`] splits every erase into one call per sector, so the
//! interrupts come back between sectors: a frame that fell due runs, and
//! feeds the watchdog.

use embedded_storage_async::nor_flash::{ErrorType, NorFlash, ReadNorFlash};

/// `F`, with every erase done one sector (`F::ERASE_SIZE`) at a time.
#[derive(Debug)]
pub struct SectorWise<F>(pub F);

impl<F: ErrorType> ErrorType for SectorWise<F> {
    type Error = F::Error;
}

impl<F: ReadNorFlash> ReadNorFlash for SectorWise<F> {
    const READ_SIZE: usize = F::READ_SIZE;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        self.0.read(offset, bytes).await
    }

    fn capacity(&self) -> usize {
        self.0.capacity()
    }
}

impl<F: NorFlash> NorFlash for SectorWise<F> {
    const WRITE_SIZE: usize = F::WRITE_SIZE;
    const ERASE_SIZE: usize = F::ERASE_SIZE;

    /// Erases `from..to` one sector after the other. A range that is not
    /// whole sectors goes to `F` as it is, which refuses it.
    async fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        let sector = u32::try_from(F::ERASE_SIZE).unwrap_or(u32::MAX);
        let whole = |at: u32| at.checked_rem(sector) == Some(0);
        if !whole(from) || !whole(to) || to < from {
            return self.0.erase(from, to).await;
        }
        let mut at = from;
        while at < to {
            let next = at.saturating_add(sector);
            self.0.erase(at, next).await?;
            at = next;
        }
        Ok(())
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        self.0.write(offset, bytes).await
    }
}
