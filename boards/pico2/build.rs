//! Linker setup for the Raspberry Pi Pico 2 image: its memory map
//! (`memory.x`) and linker scripts.

use std::{env, fs, path::PathBuf};

/// The Pico 2's memory map: flash, the settings sectors, RAM, and where the
/// boot ROM's start block goes.
const MEMORY_X: &str = "memory.x";

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed={MEMORY_X}");

    // cortex-m-rt's link.x includes `memory.x`, which the linker looks for
    // where it runs, the workspace's root (crates/, where none lies), and
    // then on the search path, where it goes from here.
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    fs::copy(MEMORY_X, out.join("memory.x")).unwrap();
    println!("cargo:rustc-link-search={}", out.display());

    // No page alignment of sections: it would only waste flash.
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    // No link-rp.x: the RP2350 has no second-stage bootloader. Its start
    // block is placed by memory.x (included by link.x).
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
