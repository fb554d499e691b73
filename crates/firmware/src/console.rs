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

use core::future::pending;

use embassy_futures::select::{Either3, select3};
use embassy_time::{Duration, Instant, Timer};
use idle_head_core::bottango::{Curves, TIMEOUT_MS};
use idle_head_core::console::{
    ConsoleLink, DualSession, Handler, Outbox, PORT_REPLY, Shared, SharedService, telemetry_line,
};
use idle_head_core::settings::SettingsStorage;

use crate::log;

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
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
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
/// exactly one reply from `handler`, in the order of the lines. When the
/// port reports received bytes lost, the line in progress is answered
/// `err line bytes lost …` (docs/user/protocol.md says what a flood does to
/// the lines around it).
///
/// A reply that waits for the frame task (a queued action) is finished
/// when the port's outcome with its ticket arrives, or after
/// [`OUTCOME_FRAMES`] frames without one as [`unanswered`]. The port reads
/// on meanwhile: the lines after it are carried out at once and their
/// replies held behind it ([`Outbox`]); only when the outbox is full do
/// the bytes wait (in the port's receive buffer). Between lines the port
/// streams telemetry at the rate `watch` set ([`telemetry_line`]), from the
/// status the frame task published: written here, never by the frame task.
/// A tick whose line cannot go out because the host reads too slowly, or
/// because replies wait, is dropped and counted in the next line's `lost=`.
/// In a Bottango session there is no telemetry (the port speaks Bottango's
/// protocol), and a line that pauses for [`TIMEOUT_MS`] is dropped and
/// answered `TIMEOUT`.
///
/// [`unanswered`]: idle_head_core::console::unanswered
pub async fn serve<P: Port, H: Handler>(
    port: &mut P,
    session: &mut DualSession<'_>,
    handler: &mut H,
    place: Place<'_>,
) -> Gone {
    let mut buf = [0; READ_CHUNK];
    // Bytes read and not yet taken: `buf[at..read]`.
    let (mut at, mut read) = (0, 0);
    let wait = place.frame * OUTCOME_FRAMES;
    let mut replies = Replies {
        outbox: Outbox::new(),
        out: [0; PORT_REPLY],
        wait,
        wait_ms: u32::try_from(wait.as_millis()).unwrap_or(u32::MAX),
    };
    let mut watch = Watch::default();
    place.link.set_watch(place.port, 0);
    place.link.forget_outcomes(place.port);
    loop {
        if let Err(gone) = replies.flush(port, place).await {
            return gone;
        }
        match replies
            .take(
                port,
                session,
                handler,
                buf.get(at..read).unwrap_or_default(),
            )
            .await
        {
            Ok(taken) => at += taken,
            Err(gone) => return gone,
        }
        let rate = telemetry_rate(port.open(), session.bottango(), place);
        let tick = watch.due(rate, Instant::now()).unwrap_or(Instant::MAX);
        // A Bottango line in progress times out; nothing else does.
        let armed = session.bottango() && session.in_progress();
        let timeout = if armed {
            Instant::now() + Duration::from_millis(TIMEOUT_MS)
        } else {
            Instant::MAX
        };
        let given_up = replies
            .outbox
            .due()
            .map_or(Instant::MAX, Instant::from_ticks);
        // Bytes left over wait for room; else read more.
        let reading = at >= read;
        let event = select3(
            async {
                if reading {
                    port.read(&mut buf).await
                } else {
                    pending().await
                }
            },
            place.link.answered(place.port),
            at_or_never(tick.min(timeout).min(given_up)),
        )
        .await;
        match event {
            Either3::First(Ok(Received::Bytes(n))) => (at, read) = (0, n),
            Either3::First(Ok(Received::Lost)) => session.lose(),
            Either3::First(Err(gone)) => return gone,
            Either3::Third(()) if armed && Instant::now() >= timeout => {
                let was = session.bottango();
                if let Some(reply) = session.timeout()
                    && let Some(now) = replies.outbox.reply(reply)
                    && let Err(gone) = port.write(now).await
                {
                    return gone;
                }
                log_mode(was, session.bottango());
            }
            Either3::Third(()) if Instant::now() >= tick => {
                // Telemetry goes out between replies, never among them.
                if !replies.outbox.is_busy() {
                    let status = place.link.status();
                    let text = telemetry_line(&status, watch.lost, &mut replies.out);
                    if let Err(gone) = port.write(text).await {
                        return gone;
                    }
                }
                watch.sent(rate, Instant::now());
            }
            // An outcome arrived, or a reply is given up on: both are
            // taken at the top of the loop.
            Either3::Second(()) | Either3::Third(()) => {}
        }
    }
}

/// The telemetry lines a second the port streams now: none in a Bottango
/// session; none once the host closed the port (DTR dropped), which stops
/// the port's `watch` for good.
fn telemetry_rate(open: bool, bottango: bool, place: Place<'_>) -> u8 {
    if !open {
        place.link.set_watch(place.port, 0);
    }
    if bottango {
        0
    } else {
        place.link.watch(place.port)
    }
}

/// Waits until `at`; for ever if `at` is [`Instant::MAX`] (no timer then:
/// arming one costs).
async fn at_or_never(at: Instant) {
    if at == Instant::MAX {
        pending::<()>().await;
    } else {
        Timer::at(at).await;
    }
}

/// A port's replies on their way out ([`Outbox`]), with the buffer they
/// are written from and how long one waits for the frame task (also in
/// ms, converted once: a 64-bit division costs hundreds of instructions
/// on a Cortex-M0+).
struct Replies {
    outbox: Outbox,
    out: [u8; PORT_REPLY],
    wait: Duration,
    wait_ms: u32,
}

impl Replies {
    /// Takes the outcomes that arrived and gives up on the replies past
    /// their time, then writes every reply whose turn has come.
    async fn flush(&mut self, port: &mut impl Port, place: Place<'_>) -> Result<(), Gone> {
        while let Some(outcome) = place.link.take_outcome(place.port) {
            self.outbox.resolve(&outcome);
        }
        self.outbox.expire(Instant::now().as_ticks(), self.wait_ms);
        loop {
            let n = self.outbox.take_ready(&mut self.out);
            if n == 0 {
                return Ok(());
            }
            port.write(self.out.get(..n).unwrap_or_default()).await?;
        }
    }

    /// Takes `bytes` into `session` for as long as their replies have room:
    /// a reply goes out at once or is held, a reply that waits for the
    /// frame task joins the outbox. Returns how many bytes it took.
    async fn take<H: Handler>(
        &mut self,
        port: &mut impl Port,
        session: &mut DualSession<'_>,
        handler: &mut H,
        bytes: &[u8],
    ) -> Result<usize, Gone> {
        let was = session.bottango();
        let mut taken = 0;
        while let Some(rest) = bytes.get(taken..)
            && !rest.is_empty()
            && self.outbox.has_room()
        {
            let (took, reply_len) = self.take_line(session, handler, rest);
            taken += took;
            if reply_len > 0 {
                port.write(self.out.get(..reply_len).unwrap_or_default())
                    .await?;
            }
        }
        log_mode(was, session.bottango());
        Ok(taken)
    }

    /// Takes `bytes` into `session` up to the end of the first line (the
    /// bytes of a line go in with no await among them: an async loop a
    /// byte costs several times as much). Returns how many it took and the
    /// length of the reply to write now, copied to `out` (0: none, the
    /// reply is held or waits, or no line ended).
    fn take_line<H: Handler>(
        &mut self,
        session: &mut DualSession<'_>,
        handler: &mut H,
        bytes: &[u8],
    ) -> (usize, usize) {
        for (at, &byte) in bytes.iter().enumerate() {
            let mut reply_len = 0;
            let reply = session.push(byte, handler);
            let ended = reply.is_some();
            if let Some(line) = reply.and_then(|reply| self.outbox.reply(reply))
                && let Some(out) = self.out.get_mut(..line.len())
            {
                out.copy_from_slice(line);
                reply_len = line.len();
            }
            let later = session.take_later();
            let waits = later.is_some();
            if let Some(later) = later {
                let due = (Instant::now() + self.wait).as_ticks();
                // (Room was checked before the line.)
                let _ = self.outbox.wait(later, due);
            }
            if ended || waits {
                return (at + 1, reply_len);
            }
        }
        (bytes.len(), 0)
    }
}

/// Logs a port switching to Bottango's protocol or back.
fn log_mode(was: bool, is: bool) {
    match (was, is) {
        (false, true) => log::info!(
            "console: Bottango handshake: a Bottango driver (protocol {=str}) until STOP",
            idle_head_core::bottango::VERSION
        ),
        (true, false) => log::info!("console: Bottango STOP: the console again"),
        _ => {}
    }
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
    /// When the next line is due at `rate` lines a second (`None`: off),
    /// `now`.
    fn due(&mut self, rate: u8, now: Instant) -> Option<Instant> {
        if rate == 0 {
            self.next = None;
            self.rate = 0;
            return None;
        }
        if rate != self.rate || self.next.is_none() {
            self.rate = rate;
            self.next = Some(now);
        }
        self.next
    }

    /// A line went out, and it is `now`: the next is due a period after
    /// this one; ticks that passed meanwhile (the write waited for a slow
    /// host) are lost.
    fn sent(&mut self, rate: u8, now: Instant) {
        let period = Duration::from_hz(u64::from(rate.max(1)));
        let Some(mut next) = self.next else { return };
        next += period;
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
/// by the shared `service`, a Bottango session's curves to `curves`.
pub async fn run<P: Port, S: SettingsStorage>(
    port: &mut P,
    service: &'static SharedService<S>,
    name: &'static str,
    place: Place<'_>,
    curves: &Curves,
) -> ! {
    let mut session = DualSession::new(Some(curves));
    let mut handler = Shared::new(service, place.port);
    loop {
        port.connected().await;
        session.reset();
        let Gone = serve(port, &mut session, &mut handler, place).await;
        session.reset();
        place.link.set_watch(place.port, 0);
        log::info!("console {=str}: the host went away", name);
    }
}

#[cfg(test)]
mod tests;
