//! The trigger inputs on GPIO pins: an [`InputSource`] over four pins.
//!
//! Each pin is an input with the pull its role needs (set by the input
//! task): the internal pull-up for a button to ground (active low), the
//! internal pull-down for a presence sensor (active high) and for an input
//! that is off. The pull-down, rather than none, makes an unplugged sensor
//! or a broken wire read low, nobody there: the head rests as it would in
//! an empty room, instead of waking at random from a floating pin. A PIR
//! module's output (push-pull, 3.3 V) drives the pin well past the
//! pull-down's ~50 kΩ.
//!
//! Waiting is interrupt-driven: for every watched pin the source waits for
//! the level it did *not* read last (a level interrupt, which fires at once
//! if the pin is there already), so no change is missed between a read and
//! the wait. Their interrupt (`IO_IRQ_BANK0`, priority 3 as embassy-rp sets
//! it) sits below the frame task's.

use core::future::pending;

use embassy_futures::select::select4;
use embassy_rp::Peri;
use embassy_rp::gpio::{AnyPin, Flex, Pull as RpPull};
use idle_head_core::input::{INPUTS, Pull};
use idle_head_firmware::input::InputSource;

/// Four GPIO pins as the trigger inputs, the first as `input 2`.
pub struct GpioInputs {
    pins: [Flex<'static>; INPUTS],
}

impl GpioInputs {
    /// The inputs on `pins` (GP2 to GP5 on the Pico), each an input pulled
    /// down until the input task gives it its role's pull.
    #[must_use]
    pub fn new(pins: [Peri<'static, AnyPin>; INPUTS]) -> Self {
        Self {
            pins: pins.map(|pin| {
                let mut flex = Flex::new(pin);
                flex.set_as_input();
                flex.set_pull(RpPull::Down);
                flex
            }),
        }
    }
}

/// Waits until `pin` is at the level it was not at in `seen` (bit `i`), if
/// watched; for ever if not.
async fn other_level(pin: &mut Flex<'static>, i: usize, seen: u8, watched: u8) {
    let bit = 1 << i;
    if watched & bit == 0 {
        pending::<()>().await;
    } else if seen & bit != 0 {
        pin.wait_for_low().await;
    } else {
        pin.wait_for_high().await;
    }
}

impl InputSource for GpioInputs {
    fn set_pull(&mut self, i: usize, pull: Pull) {
        if let Some(pin) = self.pins.get_mut(i) {
            pin.set_pull(match pull {
                Pull::Up => RpPull::Up,
                Pull::Down => RpPull::Down,
            });
        }
    }

    fn levels(&mut self) -> u8 {
        self.pins
            .iter()
            .enumerate()
            .filter(|(_, pin)| pin.is_high())
            .fold(0, |bits, (i, _)| bits | (1 << i))
    }

    async fn changed(&mut self, seen: u8, watched: u8) {
        let [a, b, c, d] = &mut self.pins;
        select4(
            other_level(a, 0, seen, watched),
            other_level(b, 1, seen, watched),
            other_level(c, 2, seen, watched),
            other_level(d, 3, seen, watched),
        )
        .await;
    }
}
