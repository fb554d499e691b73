//! The Raspberry Pi Pico's pinout, which the Pico 2 keeps: where the servos
//! and the console go on both boards.
//!
//! | what        | GPIO | board pin | peripheral         |
//! |-------------|------|-----------|--------------------|
//! | pitch servo | GP16 | 21        | PWM0 A             |
//! | roll servo  | GP18 | 24        | PWM1 A             |
//! | yaw servo   | GP20 | 26        | PWM2 A             |
//! | console TX  | GP0  | 1         | UART0, 115200 8N1  |
//! | console RX  | GP1  | 2         | UART0, by DMA channel 0 |
//! | console     | USB  |           | CDC-ACM serial port|
//! | input 2     | GP2  | 4         | GPIO, trigger input|
//! | input 3     | GP3  | 5         | GPIO, trigger input|
//! | input 4     | GP4  | 6         | GPIO, trigger input|
//! | input 5     | GP5  | 7         | GPIO, trigger input|
//! | DMX512 in   | GP9  | 12        | UART1 RX, 250 kbaud 8N2 |
//! | radar TX in | GP13 | 17        | PIO0 SM0, 256000 8N1, by DMA channel 1 |
//! | (radar RX)  | GP12 | 16        | not used: only for configuring the module |
//!
//! One PWM slice per servo (GPIO n drives slice ⌊n/2⌋ mod 8), so each
//! output starts on its own first valid pulse ([`crate::pwm`]). The wiring
//! (grounds, power, 3.3 V inputs) is the user guide's. A board with another
//! pinout, or fewer parts, builds its [`Board`] the same way with its own
//! pins, adding only the parts it has (`examples/minimal.rs`: servos and
//! USB only).

use embassy_rp::pio::Pio;
use embassy_rp::{Peripherals, usb};

use crate::input::GpioInputs;
use crate::pwm::ServoPwm;
use crate::{Board, Irqs, SERVO_CLOCK};

/// The [`Board`] of a Raspberry Pi Pico or Pico 2 named `name`, from the
/// chip's peripherals. The servo outputs stay low until the first frame.
#[must_use]
pub fn board(p: Peripherals, name: &'static str) -> Board {
    let Pio {
        mut common, sm0, ..
    } = Pio::new(p.PIO0, Irqs);
    let radar = crate::radar::receiver(&mut common, sm0, p.PIN_13, p.DMA_CH1);
    // PIO0's instruction memory keeps the program for as long as the
    // board runs.
    core::mem::forget(common);
    let servos = [
        ServoPwm::new(p.PWM_SLICE0, p.PIN_16, &SERVO_CLOCK),
        ServoPwm::new(p.PWM_SLICE1, p.PIN_18, &SERVO_CLOCK),
        ServoPwm::new(p.PWM_SLICE2, p.PIN_20, &SERVO_CLOCK),
    ];
    let inputs = GpioInputs::new([
        p.PIN_2.into(),
        p.PIN_3.into(),
        p.PIN_4.into(),
        p.PIN_5.into(),
    ]);
    Board::new(
        name,
        servos,
        "pitch GP16 (PWM0 A), roll GP18 (PWM1 A), yaw GP20 (PWM2 A)",
        p.WATCHDOG,
    )
    .with_uart(
        crate::uart::console(p.UART0, p.PIN_0, p.PIN_1, p.DMA_CH0),
        "UART0 GP0 TX, GP1 RX",
    )
    .with_usb(usb::Driver::new(p.USB, Irqs))
    .with_flash(p.FLASH)
    .with_dmx(crate::dmx::receiver(p.UART1, p.PIN_9), "UART1 RX GP9")
    .with_inputs(inputs, "input 2 GP2, input 3 GP3, input 4 GP4, input 5 GP5")
    .with_radar(radar, "LD2450 TX to GP13 (PIO0 SM0, DMA channel 1)")
}
