//! Settings sectors as a firmware would have left them: the version 1
//! fixture, or a record written by the core's `SettingsStore` to RAM.

use std::{
    future::Future,
    path::Path,
    pin::pin,
    task::{Context, Poll, Waker},
};

use super::node::Fill;
use anyhow::{Context as _, Result, bail, ensure};
use embedded_storage_async::nor_flash::NorFlashErrorKind::{self, OutOfBounds};
use embedded_storage_async::nor_flash::{ErrorType, NorFlash, ReadNorFlash};
use idle_head_core::settings::{RawRecord, Record, SETTINGS_BUFFER, Settings, SettingsStore};

/// The Pico's flash: erase sector and write unit.
const SECTOR: usize = 4096;

/// The version 1 fixture's sectors (`len` bytes).
pub fn version_1_sectors(root: &Path, len: usize) -> Result<Vec<u8>> {
    let path = root.join("host-tests/fixtures/settings-v1-sectors.bin");
    let bytes = std::fs::read(&path).with_context(|| format!("reading {}", path.display()))?;
    ensure!(
        bytes.len() == len,
        "{} holds {} bytes, not the {len} of the settings region",
        path.display(),
        bytes.len()
    );
    Ok(bytes)
}

/// `len` bytes of settings sectors (whole sectors) holding one record of
/// layout version `V` (its payload: `payload`), as the store writes it.
pub fn store_of_version<const V: u16>(payload: &[u8], len: usize) -> Result<Vec<u8>> {
    let record = RawRecord::<V, 240>::new(payload).context("a payload of at most 240 bytes")?;
    plant::<_, 256>(&record, len).with_context(|| format!("planting a version {V} record"))
}

/// `len` bytes of settings sectors holding `settings`, as `save` leaves them.
pub fn settings_sectors(settings: &Settings, len: usize) -> Result<Vec<u8>> {
    plant::<_, SETTINGS_BUFFER>(settings, len).context("planting the settings")
}

/// `len` bytes of sectors the core's `SettingsStore` saved `record` to.
fn plant<R: Record, const BUF: usize>(record: &R, len: usize) -> Result<Vec<u8>> {
    let flash = RamFlash(vec![0xff; len]);
    let mut store: SettingsStore<RamFlash, R, BUF> =
        SettingsStore::new(flash, 0..u32::try_from(len)?)
            .map_err(|e| anyhow::anyhow!("the settings store refused the range: {e:?}"))?;
    // Polled once: [`RamFlash`] never waits.
    let saved = pin!(store.save(record)).poll(&mut Context::from_waker(Waker::noop()));
    match saved {
        Poll::Ready(Ok(())) => Ok(store.into_flash().0),
        Poll::Ready(Err(e)) => bail!("{e:?}"),
        Poll::Pending => bail!("the store's save waited"),
    }
}

/// NOR flash in RAM: erased bytes read `0xff`, a write clears bits.
struct RamFlash(Vec<u8>);

impl ErrorType for RamFlash {
    type Error = NorFlashErrorKind;
}

impl RamFlash {
    fn span(&mut self, offset: u32, len: usize) -> Result<&mut [u8], NorFlashErrorKind> {
        let start = usize::try_from(offset).map_err(|_| OutOfBounds)?;
        self.0.get_mut(start..start + len).ok_or(OutOfBounds)
    }
}

impl ReadNorFlash for RamFlash {
    const READ_SIZE: usize = 1;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        bytes.copy_from_slice(self.span(offset, bytes.len())?);
        Ok(())
    }

    fn capacity(&self) -> usize {
        self.0.len()
    }
}

impl NorFlash for RamFlash {
    const WRITE_SIZE: usize = 1;
    const ERASE_SIZE: usize = SECTOR;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        let len =
            usize::try_from(to.checked_sub(from).ok_or(OutOfBounds)?).map_err(|_| OutOfBounds)?;
        self.span(from, len)?.fill(0xff);
        Ok(())
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        for (cell, byte) in self.span(offset, bytes.len())?.iter_mut().zip(bytes) {
            *cell &= byte;
        }
        Ok(())
    }
}

/// The settings sectors of the image `elf` filled with `sectors(len)`.
pub fn fill(elf: &Path, sectors: impl FnOnce(usize) -> Result<Vec<u8>>) -> Result<Fill> {
    let image = crate::elf::Image::read(elf)?;
    let region = image.settings.context("the image has no settings region")?;
    let hex = sectors(usize::try_from(region.end - region.start)?)?;
    Ok(Fill {
        addr: region.start,
        hex,
    })
}

/// `len` bytes of noise (xorshift32): a store no firmware wrote.
pub fn noise(len: usize) -> Vec<u8> {
    let mut x: u32 = 0x2545_f491;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        x.to_le_bytes()[0]
    };
    (0..len).map(|_| next()).collect()
}
