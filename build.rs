//! Linker setup for the Raspberry Pi Pico image: its memory map
//! (`memory.x`) and linker scripts.

use std::{env, fs, path::PathBuf};

/// The Pico's memory map: flash, the boot stage and RAM.
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

    // The same linker arguments for the Pico image (the bin) and the
    // example boards (examples/), which run on a Pico too.
    for targets in ["bins", "examples"] {
        link_args(targets);
    }
}

/// The linker arguments of the `targets` (`bins`, `examples`).
fn link_args(targets: &str) {
    // No page alignment of sections: it would only waste flash.
    println!("cargo:rustc-link-arg-{targets}=--nmagic");
    println!("cargo:rustc-link-arg-{targets}=-Tlink.x");
    // link-rp.x (from embassy-rp) places `.boot2`, the 256-byte second-stage
    // bootloader, at the start of flash (0x10000000, the BOOT2 region of
    // memory.x), where the RP2040 boot ROM loads and checksums it. Without it
    // the image still links but the board does not boot, silently.
    println!("cargo:rustc-link-arg-{targets}=-Tlink-rp.x");
    println!("cargo:rustc-link-arg-{targets}=-Tdefmt.x");
}
