//! The trigger inputs on GPIO pins: an [`InputSource`] over as many pins as
//! the board gives (up to [`SLOTS`]), each named by its GPIO number.
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

use embassy_futures::select::select_array;
use embassy_rp::Peri;
use embassy_rp::gpio::{AnyPin, Flex, Pin, Pull as RpPull};
use idle_head_core::input::{InputIds, Pull, SLOTS};
use idle_head_firmware::input::InputSource;

/// GPIO pins as the trigger inputs, in the order the board gives them:
/// each is `input <n>` for its GPIO number `n`.
pub struct GpioInputs {
    pins: [Option<Flex<'static>>; SLOTS],
    ids: InputIds,
}

impl GpioInputs {
    /// The inputs on `pins` (GP2 to GP5 on the Pico), each an input pulled
    /// down until the input task gives it its role's pull. At most
    /// [`SLOTS`] pins (checked when it compiles).
    #[must_use]
    pub fn new<const N: usize>(pins: [Peri<'static, AnyPin>; N]) -> Self {
        const { assert!(N <= SLOTS, "more trigger inputs than the settings keep") };
        let mut numbers = [0; SLOTS];
        let mut flexes = [const { None }; SLOTS];
        for ((pin, number), slot) in pins.into_iter().zip(&mut numbers).zip(&mut flexes) {
            *number = pin.pin();
            let mut flex = Flex::new(pin);
            flex.set_as_input();
            flex.set_pull(RpPull::Down);
            *slot = Some(flex);
        }
        // (Distinct: each pin is owned once.)
        let ids = InputIds::new(numbers.get(..N).unwrap_or_default()).unwrap_or(InputIds::NONE);
        Self { pins: flexes, ids }
    }
}

/// Waits until `pin` is at the level it was not at in `seen` (bit `i`), if
/// there and watched; for ever if not.
async fn other_level(pin: Option<&mut Flex<'static>>, i: usize, seen: u8, watched: u8) {
    let bit = 1 << i;
    match pin {
        Some(pin) if watched & bit != 0 => {
            if seen & bit != 0 {
                pin.wait_for_low().await;
            } else {
                pin.wait_for_high().await;
            }
        }
        _ => pending::<()>().await,
    }
}

impl InputSource for GpioInputs {
    fn ids(&self) -> InputIds {
        self.ids
    }

    fn set_pull(&mut self, i: usize, pull: Pull) {
        if let Some(Some(pin)) = self.pins.get_mut(i) {
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
            .filter(|(_, pin)| pin.as_ref().is_some_and(Flex::is_high))
            .fold(0, |bits, (i, _)| bits | (1 << i))
    }

    async fn changed(&mut self, seen: u8, watched: u8) {
        let mut pins = self.pins.iter_mut();
        select_array(core::array::from_fn::<_, SLOTS, _>(|i| {
            other_level(pins.next().and_then(Option::as_mut), i, seen, watched)
        }))
        .await;
    }
}
