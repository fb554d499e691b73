//! Registers rp2040js does not model (a read gives 0xffffffff, a write is
//! dropped): the gaps known not to matter, and any other in full.

use std::fmt::Write as _;

use super::event::{Op, Unmodelled};

/// The known gaps, which embassy-rp's start-up touches: the peripheral, the
/// writes covered (`None`: any access), why it does not matter. None
/// changes what the firmware does here, which the pulse, console and store
/// checks of the same runs show.
const KNOWN: [(&str, Option<&[u32]>, &str); 4] = [
    (
        "ROSC_BASE",
        None,
        "the ring oscillator's set-up by the clock init (the harness answers its RANDOMBIT)",
    ),
    (
        "VREG_AND_CHIP_RESET_BASE",
        None,
        "the core voltage and the brown-out detector",
    ),
    (
        "UART0",
        Some(&[0x34]),
        "UARTIFLS, the FIFO trigger levels: the transmit level set is the reset value \
         sim/uart.mjs models; the receive side interrupts at every byte, sooner than the chip",
    ),
    (
        "USB",
        // SOF_RD, BUFF_CPU_SHOULD_HANDLE, USBPHY_DIRECT, _OVERRIDE, _TRIM,
        // (reserved), INTR, INTS.
        Some(&[0x48, 0x5c, 0x7c, 0x80, 0x84, 0x88, 0x8c, 0x98]),
        "zeros written when the USB driver clears the controller at start-up",
    ),
];

impl Unmodelled {
    /// Why this access does not matter, if it is a known gap.
    fn known(&self) -> Option<&'static str> {
        let &(.., why) = KNOWN.iter().find(|(peripheral, writes, _)| {
            *peripheral == self.peripheral
                && writes
                    .is_none_or(|offsets| self.op == Op::Write && offsets.contains(&self.offset))
        })?;
        Some(why)
    }
}

/// What a run prints about `accesses`: each unknown one in full; the known
/// ones each with why (`verbose`) or in one line.
pub fn lines(accesses: &[Unmodelled], verbose: bool) -> String {
    let (mut text, mut known, mut peripherals) = (String::new(), (0, 0), Vec::new());
    for access in accesses {
        let op = if access.op == Op::Read {
            "read from"
        } else {
            "write to"
        };
        let what = format!(
            "[{}] {op} 0x{:x} ({}x)",
            access.peripheral, access.offset, access.count
        );
        let _ = match access.known() {
            Some(why) if verbose => {
                writeln!(text, "emulator: unmodelled register, {what}: known, {why}")
            }
            Some(_) => {
                known = (known.0 + access.count, known.1 + 1);
                if !peripherals.contains(&access.peripheral.as_str()) {
                    peripherals.push(&access.peripheral);
                }
                Ok(())
            }
            None => writeln!(
                text,
                "emulator: unmodelled register, {what}: NOT a known gap (a read gives \
                 0xffffffff, a write is dropped; see sim/unmodelled.rs)"
            ),
        };
    }
    if known.1 > 0 {
        let summary = format!(
            "emulator: {} accesses to {} registers it does not model, all known gaps that do not \
             matter here ({}; --verbose lists them)\n",
            known.0,
            known.1,
            peripherals.join(", ")
        );
        text.insert_str(0, &summary);
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn access(peripheral: &str, op: Op, offset: u32, count: u64) -> Unmodelled {
        let peripheral = peripheral.to_owned();
        Unmodelled {
            peripheral,
            op,
            offset,
            count,
        }
    }

    #[test]
    fn known_gaps_are_one_line_and_others_stay_visible() {
        let accesses = [
            access("ROSC_BASE", Op::Write, 0x4, 1),
            access("ROSC_BASE", Op::Write, 0x8, 1),
            access("VREG_AND_CHIP_RESET_BASE", Op::Read, 0x0, 2),
            access("USB", Op::Write, 0x48, 1),
        ];
        assert_eq!(
            lines(&accesses, false),
            "emulator: 5 accesses to 4 registers it does not model, all known gaps that do not \
             matter here (ROSC_BASE, VREG_AND_CHIP_RESET_BASE, USB; --verbose lists them)\n"
        );
        let verbose = lines(&accesses, true);
        assert_eq!(verbose.lines().count(), 4, "{verbose}");
        assert!(verbose.contains("[VREG_AND_CHIP_RESET_BASE] read from 0x0 (2x): known, the core"));
        // A register of a known peripheral that is not on the list, a read
        // of a register only known as written, another peripheral: shown.
        let surprises = [
            access("USB", Op::Write, 0x40, 1),
            access("UART0", Op::Read, 0x34, 1),
            access("PIO0", Op::Write, 0x0, 7),
        ];
        let text = lines(&surprises, false);
        assert_eq!(text.lines().count(), 3, "{text}");
        assert!(
            text.lines().all(|line| line.contains("NOT a known gap")),
            "{text}"
        );
        assert!(text.contains("[PIO0] write to 0x0 (7x)"), "{text}");
        assert_eq!(lines(&[], false), "");
    }
}
