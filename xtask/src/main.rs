//! Host-side project commands, `cargo xtask <command>` from any folder of
//! the repository: `cli.rs` defines them, docs/dev/xtask.md describes them.

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

use std::{process::ExitCode, time::Duration};

use clap::{CommandFactory, Parser};

use args::Options;
use cli::{Cli, Command};

fn main() -> ExitCode {
    let options = |bless, timeout: args::Timeout, no_budget| Options {
        bless,
        timeout: Duration::from_secs(timeout.timeout),
        no_budget,
    };
    let result = match Cli::parse().command {
        None => Cli::command()
            .print_long_help()
            .map(|()| true)
            .map_err(Into::into),
        Some(Command::Qemu { bless, timeout }) => qemu::command(options(bless, timeout, false)),
        Some(Command::Test {
            bless,
            timeout,
            no_budget,
            only,
            stage: None,
        }) => test::command(options(bless, timeout, no_budget), only.as_deref()),
        Some(Command::Test {
            stage: Some(stage), ..
        }) => test::stage(&stage),
        Some(Command::Bench { timeout, no_budget }) => {
            bench::command(options(false, timeout, no_budget))
        }
        Some(Command::Preview(args)) => preview::command(&args),
        Some(Command::Sim(args)) => sim::command(&args),
        Some(Command::Trace(args)) => trace::command(&args),
        Some(Command::Console(args)) => console::command(&args),
        Some(Command::Panel(args)) => panel::command(&args),
        Some(Command::Uf2(args)) => uf2::command(&args),
        Some(Command::Flash(args)) => flash::run(&args, &flash::Surroundings::here()),
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
