//! Linker setup for the QEMU images (`lm3s6965evb`).
//!
//! The memory map is `memory.x` in this directory. The linker runs in the
//! workspace root, where no `memory.x` lies, so cortex-m-rt's link.x finds
//! this one on the search path, where it is copied (as the Pico image's is).

use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory.x");

    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    fs::copy("memory.x", out.join("memory.x")).unwrap();
    println!("cargo:rustc-link-search={}", out.display());

    // No page alignment of sections: it would only waste flash.
    println!("cargo:rustc-link-arg-bins=--nmagic");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    // No link-rp.x: the LM3S6965 boots from the vector table at address 0.
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
