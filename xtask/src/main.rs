//! Host-side project commands, run as `cargo xtask <command>` from any
//! folder of the repository (the alias in `.cargo/config.toml` builds this
//! crate for the host). `cargo xtask help` lists them; `cli.rs` defines
//! them, docs/dev/xtask.md describes them.

mod args;
mod bench;
mod board;
mod book;
mod cli;
#[cfg(test)]
mod comments;
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
            only,
        }) => test::command(
            Command::options(Some(bless), timeout, Some(budget)),
            only.as_deref(),
        ),
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
