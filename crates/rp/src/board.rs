//! What a board hands over ([`Board`]): the three servo outputs and the
//! watchdog, which every board has, and the parts it may have, each added
//! with a method of its own. [`start`](crate::start) runs the tasks of the
//! parts there are; the console answers for the others with
//! `err unavailable` (the table of parts is [`Board`]'s).

use embassy_rp::Peri;
use embassy_rp::peripherals::{FLASH, USB, WATCHDOG};
use idle_head_core::console::BoardParts;
use idle_head_core::input::InputIds;
use idle_head_firmware::input::InputSource;

use crate::dmx::DmxUart;
use crate::input::GpioInputs;
use crate::pwm::ServoPwm;
use crate::radar::RadarRx;
use crate::uart::UartPort;

/// A part and where it is wired, for the log (`"UART0 GP0 TX, GP1 RX"`).
pub(crate) struct Wired<T> {
    pub(crate) part: T,
    pub(crate) pins: &'static str,
}

/// A board: its servos and watchdog, and the optional parts it has:
///
/// | part | method | without it |
/// |---|---|---|
/// | console on a UART | [`Board::with_uart`] | no console there |
/// | console on USB (CDC-ACM) | [`Board::with_usb`] | no console there |
/// | settings store in flash, unique id | [`Board::with_flash`] | the built-in settings; `save`, `load`: `err unavailable`; `seed board` plays the paper's seeds |
/// | DMX512 receiver | [`Board::with_dmx`] | `dmx`: `err unavailable`, no `dmx=` in `status` |
/// | trigger inputs | [`Board::with_inputs`] | `input <n>`: `err unavailable`, no `inputs=` in `status` |
/// | LD2450 radar | [`Board::with_radar`] | `radar`: `err unavailable` |
/// The Pico's is [`pico::board`](crate::pico::board);
/// `examples/minimal.rs` at the repository's top builds one with servos and
/// USB only.
pub struct Board {
    pub(crate) name: &'static str,
    pub(crate) servos: [ServoPwm; 3],
    pub(crate) servo_pins: &'static str,
    pub(crate) watchdog: Peri<'static, WATCHDOG>,
    pub(crate) uart: Option<Wired<UartPort>>,
    pub(crate) usb: Option<embassy_rp::usb::Driver<'static, USB>>,
    pub(crate) flash: Option<Peri<'static, FLASH>>,
    pub(crate) dmx: Option<Wired<DmxUart>>,
    pub(crate) inputs: Option<Wired<GpioInputs>>,
    pub(crate) radar: Option<Wired<Option<RadarRx>>>,
}

impl Board {
    /// A board named `name` (for the log) with the servo outputs
    /// `[pitch, roll, yaw]`, each on a PWM slice of its own clocked by
    /// [`SERVO_CLOCK`](crate::SERVO_CLOCK) ([`ServoPwm::new`]), wired as
    /// `servo_pins` says (`"pitch GP16 (PWM0 A), …"`), and the watchdog:
    /// nothing else yet.
    #[must_use]
    pub fn new(
        name: &'static str,
        servos: [ServoPwm; 3],
        servo_pins: &'static str,
        watchdog: Peri<'static, WATCHDOG>,
    ) -> Self {
        Self {
            name,
            servos,
            servo_pins,
            watchdog,
            uart: None,
            usb: None,
            flash: None,
            dmx: None,
            inputs: None,
            radar: None,
        }
    }

    /// With the console on a UART ([`uart::console`](crate::uart::console)),
    /// wired as `pins` says; console port 0.
    #[must_use]
    pub fn with_uart(mut self, uart: UartPort, pins: &'static str) -> Self {
        self.uart = Some(Wired { part: uart, pins });
        self
    }

    /// With the console on the USB port's CDC-ACM serial port; console
    /// port 1.
    #[must_use]
    pub fn with_usb(mut self, usb: embassy_rp::usb::Driver<'static, USB>) -> Self {
        self.usb = Some(usb);
        self
    }

    /// With the settings store in `flash` (the last sectors, `SETTINGS` in
    /// the board's memory.x) and the unique id read from it.
    #[must_use]
    pub fn with_flash(mut self, flash: Peri<'static, FLASH>) -> Self {
        self.flash = Some(flash);
        self
    }

    /// With the DMX512 receiver ([`dmx::receiver`](crate::dmx::receiver)),
    /// wired as `pins` says.
    #[must_use]
    pub fn with_dmx(mut self, dmx: DmxUart, pins: &'static str) -> Self {
        self.dmx = Some(Wired { part: dmx, pins });
        self
    }

    /// With the trigger inputs ([`GpioInputs`]: `input <n>` for each pin's
    /// GPIO number), wired as `pins` says.
    #[must_use]
    pub fn with_inputs(mut self, inputs: GpioInputs, pins: &'static str) -> Self {
        self.inputs = Some(Wired { part: inputs, pins });
        self
    }

    /// With the radar's receiver ([`radar::receiver`](crate::radar::receiver);
    /// `None` if it could not be set up: logged, and the board runs as one
    /// without a radar), wired as `pins` says.
    #[must_use]
    pub fn with_radar(mut self, radar: Option<RadarRx>, pins: &'static str) -> Self {
        self.radar = Some(Wired { part: radar, pins });
        self
    }

    /// What the console answers for: the inputs' numbers, DMX, a radar
    /// that was set up.
    pub(crate) fn parts(&self) -> BoardParts {
        BoardParts {
            inputs: self
                .inputs
                .as_ref()
                .map_or(InputIds::NONE, |inputs| inputs.part.ids()),
            dmx: self.dmx.is_some(),
            radar: self
                .radar
                .as_ref()
                .is_some_and(|radar| radar.part.is_some()),
        }
    }
}
