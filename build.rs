//! Linker setup for the Raspberry Pi Pico image (feature `pico`).
//!
//! Only firmware builds (`target_os = "none"`) link anything; a host build of
//! the core library (the host tests, the xtask) passes straight through, and
//! so does a thumb build without `pico`: the core as a dependency of the QEMU
//! images in `qemu/`, which link with their own memory map and scripts.

use std::{env, fs, path::PathBuf};

/// The Pico's memory map: flash, the boot stage and RAM.
const MEMORY_X: &str = "src/bin/pico/memory.x";

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed={MEMORY_X}");

    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none")
        || env::var_os("CARGO_FEATURE_PICO").is_none()
    {
        return;
    }

    // cortex-m-rt's link.x includes `memory.x`, which the linker looks for
    // in the workspace root (where it runs, and where none lies: the
    // workspace also holds the QEMU images) and then on the search path. The
    // Pico's memory map goes there, from next to the Pico binary. Only the
    // Pico build adds the path: a dependent package inherits its
    // dependencies' search paths, and the QEMU images must link with their
    // own memory map.
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    fs::copy(MEMORY_X, out.join("memory.x")).unwrap();
    println!("cargo:rustc-link-search={}", out.display());

    // No page alignment of sections: it would only waste flash.
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    // link-rp.x (from embassy-rp) places `.boot2`, the 256-byte second-stage
    // bootloader, at the start of flash (0x10000000, the BOOT2 region of
    // memory.x), where the RP2040 boot ROM loads and checksums it. Without it
    // the image still links but the board does not boot, silently.
    println!("cargo:rustc-link-arg-bins=-Tlink-rp.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
