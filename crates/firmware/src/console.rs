//! The console on a board's byte ports (a UART, a USB serial port).
//!
//! Each port has a task of its own in thread mode with its own session
//! ([`DualSession`]): bytes in, one reply line out per input line; a
//! Bottango handshake turns the port into a Bottango driver until `STOP`
//! or until the host goes away. The commands
//! are carried out by a [`Handler`], the one generic parameter of
//! [`serve`]; actions reach the frame task only through its
//! [`CommandQueue`], which it drains between frames, and servo
//! calibrations, seeds and the head's status through the
//! [`ConsoleLink`](idle_head_core::console::ConsoleLink). The frame task runs
//! in an executor above the console tasks, and the ports' interrupts sit
//! below it: a flood of bytes on any port never delays a frame.
//!
//! The handler is the core's `ConsoleService`, one for all ports
//! ([`Shared`]), with the board's settings store: a servo changed on one
//! port shows on the other.
//!
//! A board implements [`Port`] for each of its transports and runs
//! [`run`] in a task per port.
//!
//! [`CommandQueue`]: idle_head_core::behaviour::CommandQueue

use embassy_futures::select::{Either, select};
use embassy_time::{Duration, Instant, Timer, with_timeout};
use idle_head_core::bottango::TIMEOUT_MS;
use idle_head_core::console::{
    ConsoleLink, DualSession, Handler, Outcome, Shared, SharedService, outcome_reply,
    telemetry_line, unanswered,
};
use idle_head_core::settings::SettingsStorage;

use crate::boot::SHOW;

/// The console's baud rate on a UART (8 data bits, no parity, 1 stop bit).
pub const UART_BAUD: u32 = 115_200;

/// Bytes [`serve`] reads at once: a full-speed USB packet.
pub const READ_CHUNK: usize = 64;

/// Frames the console waits for the frame task to take a queued action
/// before it answers `err state` (it takes one within two frames while
/// the frames run).
pub const OUTCOME_FRAMES: u32 = 5;

/// What a [`Port`] read brought.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Received {
    /// This many bytes, in the buffer.
    Bytes(usize),
    /// Received bytes were lost (a UART overrun or framing error).
    Lost,
}

/// A byte port the console runs over.
// The executors here are single-threaded: no `Send` bound is wanted on the
// futures, which is what the lint warns about.
#[allow(async_fn_in_trait)]
pub trait Port {
    /// Waits until a host is there to talk to (a terminal opened a USB
    /// serial port); at once for a port that is always there (a UART).
    async fn connected(&mut self) {}
    /// Whether a host still has the port open (a USB serial port's DTR);
    /// always for a UART. Telemetry stops when it closes.
    fn open(&self) -> bool {
        true
    }
    /// Waits for bytes and reads some into `buf`, or reports received
    /// bytes lost; `Err` when the port is gone (a USB host disconnected).
    /// Cancel-safe: a read dropped before it completes takes no byte.
    async fn read(&mut self, buf: &mut [u8]) -> Result<Received, Gone>;
    /// Writes all of `bytes`.
    async fn write(&mut self, bytes: &[u8]) -> Result<(), Gone>;
}

/// The port went away: the session ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub struct Gone;

/// Where a port's console is: its number (`0..PORTS`, for the outcomes
/// of its actions and its telemetry rate), the link shared with the frame
/// task, and the frame period (the telemetry's time base and the outcome
/// wait's unit).
#[derive(Clone, Copy)]
pub struct Place<'a> {
    /// The port's number.
    pub port: u8,
    /// The link shared with the frame task.
    pub link: &'a ConsoleLink,
    /// The time between frames.
    pub frame: Duration,
}

/// Runs `session` over `port` until the port goes away: every line gets
/// exactly one reply from `handler`. When the port reports received bytes
/// lost, the line in progress is answered `err line bytes lost …`
/// (docs/user/protocol.md says what a flood does to the lines around it).
///
/// A reply that waits for the frame task (a queued action) is finished
/// when the port's outcome with its ticket arrives, or after
/// [`OUTCOME_FRAMES`] frames without one as [`unanswered`]; the bytes
/// after its line wait meanwhile. Between lines the port streams
/// telemetry at the rate `watch` set ([`telemetry_line`]), from the
/// status the frame task published: written here, never by the frame
/// task. A tick whose line cannot go out because the host reads too
/// slowly is dropped and counted in the next line's `lost=`. In a
/// Bottango session there is no telemetry (the port speaks Bottango's
/// protocol), and a line that pauses for [`TIMEOUT_MS`] is dropped and
/// answered `TIMEOUT`.
pub async fn serve<P: Port, H: Handler>(
    port: &mut P,
    session: &mut DualSession<'_>,
    handler: &mut H,
    place: Place<'_>,
) -> Gone {
    let mut buf = [0; READ_CHUNK];
    let mut watch = Watch::default();
    place.link.set_watch(place.port, 0);
    loop {
        // The host closed the port (DTR dropped): its telemetry stops.
        if !port.open() {
            place.link.set_watch(place.port, 0);
        }
        let rate = if session.bottango() {
            0
        } else {
            place.link.watch(place.port)
        };
        let due = watch.due(rate).unwrap_or(Instant::MAX);
        // A Bottango line in progress times out; nothing else does.
        let armed = session.bottango() && session.in_progress();
        let timeout = if armed {
            Instant::now() + Duration::from_millis(TIMEOUT_MS)
        } else {
            Instant::MAX
        };
        let read = match select(port.read(&mut buf), Timer::at(due.min(timeout))).await {
            Either::First(read) => read,
            Either::Second(()) if armed && Instant::now() >= timeout => {
                let was = session.bottango();
                if let Some(reply) = session.timeout()
                    && let Err(gone) = port.write(reply).await
                {
                    return gone;
                }
                log_mode(was, session.bottango());
                continue;
            }
            Either::Second(()) => {
                // Between replies: the reply buffer is free for the line.
                let status = place.link.status();
                let text = telemetry_line(&status, watch.lost, session.spare());
                if let Err(gone) = port.write(text).await {
                    return gone;
                }
                watch.sent(rate);
                continue;
            }
        };
        let n = match read {
            Ok(Received::Bytes(n)) => n,
            Ok(Received::Lost) => {
                session.lose();
                continue;
            }
            Err(gone) => return gone,
        };
        let was = session.bottango();
        for &byte in buf.get(..n).unwrap_or_default() {
            if let Some(reply) = session.push(byte, handler)
                && !reply.is_empty()
                && let Err(gone) = port.write(reply).await
            {
                return gone;
            }
            if let Some(ticket) = session.waiting() {
                let outcome = outcome(place, ticket).await;
                let wait = place.frame * OUTCOME_FRAMES;
                let reply = session.finish(|reply| match &outcome {
                    Some(outcome) => outcome_reply(reply, &outcome.result),
                    None => unanswered(reply, wait.as_millis() as u32),
                });
                if let Some(reply) = reply
                    && let Err(gone) = port.write(reply).await
                {
                    return gone;
                }
            }
        }
        log_mode(was, session.bottango());
    }
}

/// Logs a port switching to Bottango's protocol or back.
fn log_mode(was: bool, is: bool) {
    match (was, is) {
        (false, true) => defmt::info!(
            "console: Bottango handshake: a Bottango driver (protocol {=str}) until STOP",
            idle_head_core::bottango::VERSION
        ),
        (true, false) => defmt::info!("console: Bottango STOP: the console again"),
        _ => {}
    }
}

/// The outcome of the port's action with `ticket`, if a frame takes it
/// within [`OUTCOME_FRAMES`].
async fn outcome(place: Place<'_>, ticket: u8) -> Option<Outcome> {
    let slot = place.link.outcomes(place.port)?;
    let mine = async {
        loop {
            let outcome = slot.wait().await;
            if outcome.ticket == ticket {
                return outcome;
            }
        }
    };
    with_timeout(place.frame * OUTCOME_FRAMES, mine).await.ok()
}

/// A port's telemetry schedule: when the next line is due, and the lines
/// dropped so far.
#[derive(Default)]
struct Watch {
    /// The next line's time, while streaming.
    next: Option<Instant>,
    rate: u8,
    lost: u32,
}

impl Watch {
    /// When the next line is due at `rate` lines a second (`None`: off).
    fn due(&mut self, rate: u8) -> Option<Instant> {
        if rate == 0 {
            self.next = None;
            self.rate = 0;
            return None;
        }
        if rate != self.rate || self.next.is_none() {
            self.rate = rate;
            self.next = Some(Instant::now());
        }
        self.next
    }

    /// A line went out: the next is due a period after this one; ticks
    /// that passed meanwhile (the write waited for a slow host) are lost.
    fn sent(&mut self, rate: u8) {
        let period = Duration::from_hz(u64::from(rate.max(1)));
        let Some(mut next) = self.next else { return };
        next += period;
        let now = Instant::now();
        while next <= now {
            next += period;
            self.lost = self.lost.saturating_add(1);
        }
        self.next = Some(next);
    }
}

/// Runs the console on `port` for as long as the board runs: a session per
/// connection (the half-typed line of a host that went away is forgotten,
/// its telemetry stops and a Bottango session ends), commands carried out
/// by the shared `service`.
pub async fn run<P: Port, S: SettingsStorage>(
    port: &mut P,
    service: &'static SharedService<S>,
    name: &'static str,
    place: Place<'_>,
) -> ! {
    let mut session = DualSession::new(Some(&SHOW.curves));
    let mut handler = Shared::new(service, place.port);
    loop {
        port.connected().await;
        session.reset();
        let Gone = serve(port, &mut session, &mut handler, place).await;
        session.reset();
        place.link.set_watch(place.port, 0);
        defmt::info!("console {=str}: the host went away", name);
    }
}
