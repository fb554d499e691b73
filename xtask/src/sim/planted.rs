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
use idle_head_core::settings::{RawRecord, Record, SETTINGS_BUFFER, Settings, SettingsStore};
use sequential_storage::mock_flash::{MockFlashBase, WriteCountCheck};

/// The Pico's settings sectors: bytes read and written one at a time, 4 KiB
/// sectors, four of them (as `host-tests` has them).
type PicoSectors = MockFlashBase<4, 1, 4096>;

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
    // Erased bytes read 0xff, a write clears bits, as on the chip; any
    // number of writes between erases, at any alignment.
    let flash = PicoSectors::new(WriteCountCheck::Disabled, None, false);
    let range = PicoSectors::FULL_FLASH_RANGE;
    ensure!(
        usize::try_from(range.end) == Ok(len),
        "the settings region is {len} bytes, not the Pico's {}",
        range.end
    );
    let mut store: SettingsStore<PicoSectors, R, BUF> = SettingsStore::new(flash, range)
        .map_err(|e| anyhow::anyhow!("the settings store refused the range: {e:?}"))?;
    // Polled once: the mock flash never waits.
    let saved = pin!(store.save(record)).poll(&mut Context::from_waker(Waker::noop()));
    match saved {
        Poll::Ready(Ok(())) => Ok(store.into_flash().as_bytes().to_vec()),
        Poll::Ready(Err(e)) => bail!("{e:?}"),
        Poll::Pending => bail!("the store's save waited"),
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
