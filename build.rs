//! Picks the memory layout and linker scripts for the board image being built.
//!
//! Only firmware builds (`target_os = "none"`) link anything; a host build of the
//! core library (the host tests) passes straight through.

use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=src/bin/pico/memory.x");
    println!("cargo:rerun-if-changed=src/bin/qemu/memory.x");

    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }
    let pico = env::var_os("CARGO_FEATURE_PICO").is_some();
    let qemu = env::var_os("CARGO_FEATURE_QEMU").is_some();
    let memory = match (pico, qemu) {
        (true, false) => "src/bin/pico/memory.x",
        (false, true) => "src/bin/qemu/memory.x",
        (true, true) => panic!(
            "features `pico` and `qemu` select different memory maps; \
             build the QEMU image with `--no-default-features --features qemu`"
        ),
        (false, false) => return, // library-only build for a thumb target (clippy, size checks)
    };

    // Put the chosen layout on the linker search path as `memory.x`, which
    // cortex-m-rt's link.x includes. No `memory.x` may sit in the package root:
    // the linker runs there and would find that one first, for every image.
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    fs::copy(memory, out.join("memory.x")).unwrap();
    println!("cargo:rustc-link-search={}", out.display());

    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    if pico {
        // Places `.boot2` at the start of flash (0x10000000). Without it the image
        // still links but the RP2040 boot ROM finds no valid second stage.
        println!("cargo:rustc-link-arg-bins=-Tlink-rp.x");
    }
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
