//! Registers rp2040js does not model (a read gives 0xffffffff, a write is
//! dropped), as the harness counts the accesses to them: the gaps known not
//! to matter for these images, each with the reason, and any other, which a
//! run shows in full.

use std::fmt::Write as _;

use super::event::Access;

/// Accesses to one register the emulator does not model.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Unmodelled {
    /// The peripheral as rp2040js names it.
    pub peripheral: String,
    pub op: Access,
    /// The register's offset in the peripheral.
    pub offset: u32,
    pub count: u64,
}

/// A gap of the emulator known not to matter here.
struct Known {
    /// The peripheral as rp2040js names it.
    peripheral: &'static str,
    /// The accesses it covers: `None` any, else these writes only.
    writes: Option<&'static [u32]>,
    /// Why it does not matter.
    why: &'static str,
}

/// The known gaps. embassy-rp's start-up touches each of them; none changes
/// what the firmware does in the emulator, which the pulse, console and
/// store checks of the same runs show.
const KNOWN: [Known; 5] = [
    Known {
        peripheral: "ROSC_BASE",
        writes: None,
        why: "the ring oscillator's set-up by the clock init (the emulator's clocks need \
              none; the harness answers its RANDOMBIT register)",
    },
    Known {
        peripheral: "VREG_AND_CHIP_RESET_BASE",
        writes: None,
        why: "the core voltage and the brown-out detector (nothing to regulate in an emulator)",
    },
    Known {
        peripheral: "UART0",
        // UARTIFLS.
        writes: Some(&[0x34]),
        why: "UARTIFLS, the FIFO trigger levels: the transmit level set is the reset value \
              that sim/uart.mjs models, and the receive side interrupts at every byte, \
              sooner than the chip",
    },
    Known {
        peripheral: "UART1",
        // UARTIFLS.
        writes: Some(&[0x34]),
        why: "UARTIFLS of the DMX receiver: the receive side interrupts at every byte, \
              sooner than the chip's trigger level, and the handler reads whatever is \
              in the FIFO either way",
    },
    Known {
        peripheral: "USB",
        // SOF_RD, BUFF_CPU_SHOULD_HANDLE, USBPHY_DIRECT, USBPHY_DIRECT_OVERRIDE,
        // USBPHY_TRIM, (reserved), INTR, INTS.
        writes: Some(&[0x48, 0x5c, 0x7c, 0x80, 0x84, 0x88, 0x8c, 0x98]),
        why: "zeros written when the USB driver clears the controller's registers at \
              start-up (PHY control, read-only status)",
    },
];

impl Unmodelled {
    /// Why this access does not matter, if it is a known gap.
    fn known(&self) -> Option<&'static str> {
        KNOWN
            .iter()
            .find(|known| {
                known.peripheral == self.peripheral
                    && known.writes.is_none_or(|offsets| {
                        self.op == Access::Write && offsets.contains(&self.offset)
                    })
            })
            .map(|known| known.why)
    }

    /// `[USB] write to 0x48 (3x)`.
    fn describe(&self) -> String {
        let op = match self.op {
            Access::Read => "read from",
            Access::Write => "write to",
        };
        format!(
            "[{}] {op} 0x{:x} ({}x)",
            self.peripheral, self.offset, self.count
        )
    }
}

/// The lines a run prints about `accesses`: with `verbose`, each access and
/// why a known one does not matter; without, one line for the known ones
/// and each unknown one in full.
pub fn lines(accesses: &[Unmodelled], verbose: bool) -> String {
    let (known, unknown): (Vec<&Unmodelled>, Vec<&Unmodelled>) =
        accesses.iter().partition(|access| access.known().is_some());
    let mut text = String::new();
    if verbose {
        for access in &known {
            let why = access.known().unwrap_or_default();
            let _ = writeln!(
                text,
                "emulator: unmodelled register, {}: known, {why}",
                access.describe()
            );
        }
    } else if !known.is_empty() {
        let mut peripherals: Vec<&str> = Vec::new();
        for access in &known {
            if !peripherals.contains(&access.peripheral.as_str()) {
                peripherals.push(&access.peripheral);
            }
        }
        let _ = writeln!(
            text,
            "emulator: {} accesses to {} registers it does not model, all known gaps that do not \
             matter here ({}; --verbose lists them)",
            known.iter().map(|a| a.count).sum::<u64>(),
            known.len(),
            peripherals.join(", ")
        );
    }
    for access in unknown {
        let _ = writeln!(
            text,
            "emulator: unmodelled register, {}: NOT a known gap (a read gives 0xffffffff, a \
             write is dropped; see sim/unmodelled.rs)",
            access.describe()
        );
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn access(peripheral: &str, op: Access, offset: u32, count: u64) -> Unmodelled {
        Unmodelled {
            peripheral: peripheral.to_owned(),
            op,
            offset,
            count,
        }
    }

    #[test]
    fn known_gaps_are_one_line_and_others_stay_visible() {
        let accesses = [
            access("ROSC_BASE", Access::Write, 0x4, 1),
            access("ROSC_BASE", Access::Write, 0x8, 1),
            access("VREG_AND_CHIP_RESET_BASE", Access::Read, 0x0, 2),
            access("USB", Access::Write, 0x48, 1),
        ];
        let quiet = lines(&accesses, false);
        assert_eq!(
            quiet,
            "emulator: 5 accesses to 4 registers it does not model, all known gaps that do not \
             matter here (ROSC_BASE, VREG_AND_CHIP_RESET_BASE, USB; --verbose lists them)\n"
        );
        let verbose = lines(&accesses, true);
        assert_eq!(verbose.lines().count(), 4, "{verbose}");
        assert!(
            verbose
                .contains("[VREG_AND_CHIP_RESET_BASE] read from 0x0 (2x): known, the core voltage")
        );

        // A register of a known peripheral that is not on the list, a read
        // of a register only known as written, another peripheral: shown.
        let surprises = [
            access("USB", Access::Write, 0x40, 1),
            access("UART0", Access::Read, 0x34, 1),
            access("PIO0", Access::Write, 0x0, 7),
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
