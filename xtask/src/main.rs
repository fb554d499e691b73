//! Host-side project commands, run as `cargo xtask <command>` from any folder
//! of the repository (the alias in `.cargo/config.toml` builds this crate for
//! the host). `cargo xtask help` lists them; `cli.rs` defines them.
//!
//! - `cargo xtask qemu`: build the QEMU image, run it and show the head's motion.
//! - `cargo xtask test`: every check the project has (host tests, formatting,
//!   lints, the Pico build and its memory budget, the QEMU log snapshot, the
//!   boot-time benchmark and its budget).
//! - `cargo xtask bench`: the boot-time benchmark in QEMU (engine against a
//!   direct-form f32 smoothing), as a table with a verdict.
//! - `cargo xtask preview`: CSV and PNG of a loop's stages (walk, smoothing,
//!   normalisation, closure), for people.
//! - `cargo xtask metrics`: loop-quality metrics over many seeds, both closures.
//! - `cargo xtask sim`: the Pico image in the RP2040 emulator, its pulses
//!   checked against the host frame for frame.
//! - `cargo xtask trace`: the firmware's frames simulated on the host, with
//!   scripted gestures and looks, as CSV and PNG.
//! - `cargo xtask uf2`: the firmware as a UF2 file for a board's BOOTSEL drive.
//! - `cargo xtask flash`: the runner of `cargo run --release`: BOOTSEL drive,
//!   debug probe, or what to install.
//! - `cargo xtask book`: the book (docs/) built with mdBook into
//!   target/book, every link in it checked.
//! - `cargo xtask panel`: the browser control panel, served and bridged to
//!   a head (emulated, QEMU or a serial port).
//!
//! The firmware commands install what they need and is missing: the
//! firmware's Rust target and, when running as root on Debian or Ubuntu, QEMU.
//! `preview` and `metrics` run the core library on the host only.

mod args;
mod bench;
mod board;
mod book;
mod cli;
mod console;
mod elf;
mod figures;
mod flash;
mod log;
mod metrics;
mod panel;
mod pico2;
mod plot;
mod preview;
mod project;
mod qemu;
mod reference;
mod setup;
mod sim;
mod snapshot;
mod steps;
mod test;
mod trace;
mod uf2;

use std::process::ExitCode;

use anyhow::Result;
use clap::{CommandFactory, Parser};

use cli::{Cli, Command};

fn main() -> ExitCode {
    let result: Result<bool> = match Cli::parse().command {
        None => Cli::command()
            .print_long_help()
            .map(|()| true)
            .map_err(Into::into),
        Some(Command::Qemu { bless, timeout }) => {
            qemu::command(Command::options(Some(bless), timeout, None))
        }
        Some(Command::Test {
            bless,
            timeout,
            budget,
        }) => test::command(Command::options(Some(bless), timeout, Some(budget))),
        Some(Command::Bench { timeout, budget }) => {
            bench::command(Command::options(None, timeout, Some(budget)))
        }
        Some(Command::Preview(args)) => preview::command(&args),
        Some(Command::Metrics(args)) => metrics::command(&args),
        Some(Command::Sim(args)) => sim::command(&args),
        Some(Command::Trace(args)) => trace::command(&args),
        Some(Command::Console(args)) => console::command(&args),
        Some(Command::Panel(args)) => panel::command(&args),
        Some(Command::Uf2(args)) => uf2::command(&args),
        Some(Command::Flash(args)) => flash::command(&args),
        Some(Command::Book) => book::command(),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::FAILURE
        }
    }
}
