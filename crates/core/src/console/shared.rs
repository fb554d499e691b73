//! The console's handler on a board with several ports: the core's
//! [`ConsoleService`], one for all of them, behind a blocking mutex
//! ([`Shared`]).
//!
//! The console tasks run in one thread-mode executor and a command is
//! carried out without an `.await`, so the two never want the service at
//! once; the `RefCell` (borrowed with `try_borrow_mut`, never a panic) is
//! in the console tasks only, never on the frame path, which reaches the
//! service's state through the queue and the [`ConsoleLink`] alone.
//!
//! Free of the board: the emulator check (`cargo xtask sim`) computes the
//! replies it expects with it on the host, over a `RamStorage`.
//!
//! [`ConsoleLink`]: crate::console::ConsoleLink

use core::cell::RefCell;
use core::fmt::Write as _;

use crate::command::Command;
use crate::console::{ConsoleService, ErrorCode, Handler, Reply};
use crate::settings::SettingsStorage;
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::blocking_mutex::raw::NoopRawMutex;

/// One service for both ports, in thread mode.
pub type SharedService<S> = Mutex<NoopRawMutex, RefCell<ConsoleService<'static, S>>>;

/// A port's handle on the shared service.
pub struct Shared<S: 'static> {
    service: &'static SharedService<S>,
    port: u8,
}

impl<S: SettingsStorage> Shared<S> {
    /// Port `port`'s handle on `service` (`0..PORTS`: the port its
    /// queued actions' outcomes and its telemetry rate are kept for, see
    /// [`ConsoleLink`]).
    pub const fn new(service: &'static SharedService<S>, port: u8) -> Self {
        Self { service, port }
    }
}

impl<S: SettingsStorage> Handler for Shared<S> {
    fn command(&mut self, command: Command, reply: &mut Reply<'_>) {
        self.service.lock(|cell| match cell.try_borrow_mut() {
            Ok(mut service) => service.command_on(self.port, command, reply),
            // Cannot happen (see the module docs); an answer all the same.
            Err(_) => {
                reply
                    .err(ErrorCode::Busy)
                    .write_str("the other port's command is running")
                    .ok();
            }
        });
    }
}
