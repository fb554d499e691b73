// rp2040js's UART, bridged where it differs from the RP2040's PL011:
//
// - It has no DMA control register (UARTDMACR): a read gives 0xffffffff, as
//   for any register it lacks, so a driver that checks for DMA first
//   (embassy-rp's buffered UART) returns from every interrupt without
//   serving it, and the interrupt never ends. Here it reads back what was
//   written, 0 after reset.
// - It sends each byte the moment the firmware writes it, and raises the
//   transmit interrupt again on every interrupt check, so once the firmware
//   unmasks it (embassy-rp's buffered UART keeps it unmasked) it never
//   clears. On the chip a byte takes ten bit times (86.8 µs at 115200 8N1)
//   and waits in a 32-byte transmit FIFO; the interrupt is raised when the
//   FIFO drains to its trigger level (4 bytes, the reset value). Here the
//   bytes queue and leave at the line rate the firmware set, UARTFR says
//   whether the FIFO is full (TXFF), empty (TXFE) or busy (BUSY), and the
//   interrupt comes as on the chip and stays cleared when the firmware
//   clears it. So replies take their real time, and a sender that does not
//   wait for them fills the receive side as on a board.
// - It drops a byte that arrives at a full receive FIFO without a word. The
//   PL011 flags it: the next character read carries the overrun bit (OE,
//   bit 11 of UARTDR), which embassy-rp reports as an overrun error. The
//   harness sets `uart.overrun` when it has to drop a byte.

const UARTDR = 0x00;
const UARTFR = 0x18;
const UARTDMACR = 0x48;
const UARTDR_OE = 1 << 11;
const UART_TXINTR = 1 << 5;
const FR_BUSY = 1 << 3;
const FR_TXFF = 1 << 5;
const FR_TXFE = 1 << 7;
const TX_FIFO = 32;
const TX_TRIGGER = 4;

/// Bridges `uart`; `now()` is the virtual time in ns. Adds `uart.txDue()`
/// (when the next byte leaves, Infinity if none waits) and `uart.sendDue()`
/// (sends every byte whose time has come, to `uart.onByte`).
export function uartAsOnTheChip(uart, now) {
  let dmacr = 0;
  const tx = []; // the transmit FIFO
  let txNext = Infinity; // when its first byte has left the wire
  const byteNs = () => (10 * 1e9) / (uart.baudRate || 115200);
  uart.overrun = false;
  uart.checkInterrupts = function () {
    this.rp2040.setInterrupt(this.irq, !!(this.interruptStatus & this.interruptMask));
  };
  const read = uart.readUint32.bind(uart);
  uart.readUint32 = (offset) => {
    if (offset === UARTDMACR) return dmacr;
    if (offset === UARTFR) {
      const rx = read(offset) & ~(FR_BUSY | FR_TXFF | FR_TXFE);
      const full = tx.length >= TX_FIFO ? FR_TXFF : 0;
      return rx | full | (tx.length === 0 ? FR_TXFE : FR_BUSY);
    }
    if (offset === UARTDR && uart.overrun && !uart.rxFIFO.empty) {
      uart.overrun = false;
      return read(offset) | UARTDR_OE;
    }
    return read(offset);
  };
  const write = uart.writeUint32.bind(uart);
  uart.writeUint32 = (offset, value) => {
    if (offset === UARTDMACR) {
      dmacr = value & 0x7;
      return;
    }
    if (offset === UARTDR) {
      if (!uart.enabled || tx.length >= TX_FIFO) return; // a full FIFO drops it, as the chip does
      if (tx.length === 0) txNext = now() + byteNs();
      tx.push(value & 0xff);
      return;
    }
    write(offset, value);
  };
  uart.txDue = () => txNext;
  uart.sendDue = () => {
    while (tx.length > 0 && now() >= txNext) {
      uart.onByte?.(tx.shift());
      txNext = tx.length > 0 ? txNext + byteNs() : Infinity;
      if (tx.length === TX_TRIGGER) {
        uart.interruptStatus |= UART_TXINTR;
        uart.checkInterrupts();
      }
    }
  };
}
