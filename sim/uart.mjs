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
// - It has no way to receive a byte that arrives at a full receive FIFO, nor
//   a damaged one. `uart.receive` does both as the PL011 does: a byte that
//   finds the FIFO full is lost, and the next character read carries the
//   overrun bit (OE, bit 11 of UARTDR); a damaged byte carries the framing
//   error bit (FE, bit 8). Both also set their raw interrupt status bits
//   (UARTRIS: FERIS, bit 7; OERIS, bit 10), which stay until cleared.
// - It never asks the DMA for a received character: on the chip the UART
//   raises its RX DREQ while the receive FIFO holds a character and UARTDMACR
//   enables receive DMA (RXDMAE), and the DMA's read of UARTDR takes it. Here
//   the DREQ follows the FIFO the same way, so a DMA channel paced by it
//   empties the FIFO character by character, the flags in bits 8 to 11 with
//   each.

const UARTDR = 0x00;
const UARTFR = 0x18;
const UARTDMACR = 0x48;
const UARTDR_OE = 1 << 11;
const UARTDR_FE = 1 << 8;
const RIS_FE = 1 << 7;
const RIS_OE = 1 << 10;
const DMACR_RXDMAE = 1 << 0;
const UART_TXINTR = 1 << 5;
const FR_BUSY = 1 << 3;
const FR_TXFF = 1 << 5;
const FR_TXFE = 1 << 7;
const TX_FIFO = 32;
const TX_TRIGGER = 4;

/// Bridges `uart`; `now()` is the virtual time in ns. Adds `uart.txDue()`
/// (when the next byte leaves, Infinity if none waits), `uart.sendDue()`
/// (sends every byte whose time has come, to `uart.onByte`) and
/// `uart.receive(byte, damaged)` (a byte on the RX line; false if it was
/// lost at a full FIFO).
export function uartAsOnTheChip(uart, now) {
  let dmacr = 0;
  const tx = []; // the transmit FIFO
  let txNext = Infinity; // when its first byte has left the wire
  const byteNs = () => (10 * 1e9) / (uart.baudRate || 115200);
  let overrun = false; // a byte was lost at a full receive FIFO
  // The RX DREQ: set while receive DMA is on and a character waits.
  const rxDreq = () => {
    if (dmacr & DMACR_RXDMAE && !uart.rxFIFO.empty) uart.rp2040.dma.setDREQ(uart.dreq.rx);
    else uart.rp2040.dma.clearDREQ(uart.dreq.rx);
  };
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
    if (offset === UARTDR) {
      const flag = overrun && !uart.rxFIFO.empty ? UARTDR_OE : 0;
      if (flag) overrun = false;
      const value = read(offset) | flag;
      rxDreq();
      return value;
    }
    return read(offset);
  };
  const write = uart.writeUint32.bind(uart);
  uart.writeUint32 = (offset, value) => {
    if (offset === UARTDMACR) {
      dmacr = value & 0x7;
      rxDreq();
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
  uart.receive = (byte, damaged) => {
    if (uart.rxFIFO.full) {
      overrun = true;
      uart.interruptStatus |= RIS_OE;
      uart.checkInterrupts();
      return false;
    }
    if (damaged) uart.interruptStatus |= RIS_FE;
    uart.feedByte(byte | (damaged ? UARTDR_FE : 0));
    rxDreq();
    return true;
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

// The PL011's receive interrupts, which rp2040js raises at every byte (it
// models no trigger level and no timeout; UARTIFLS is not even kept). On
// the chip:
// - RXINTR (UARTRIS bit 4) rises when the receive FIFO fills to the level
//   UARTIFLS's RXIFLSEL sets (4, 8, 16, 24 or 28 of its 32 characters; 16
//   after reset), and falls when reads take it below that level;
// - RTINTR (bit 6), the receive timeout, rises when characters wait in the
//   FIFO and none came for 32 bit periods, and falls when reads empty it;
// - a write to UARTICR clears either (rp2040js's own).
// So a handler that empties the FIFO runs once per few characters, not per
// character. Returns `due()`, when the timeout would rise (Infinity if
// none can), and `check()`, which raises it once its time has come.
const UARTIFLS = 0x34;
const RXINTR = 1 << 4;
const RTINTR = 1 << 6;
const RX_LEVELS = [4, 8, 16, 24, 28];

export function receiveInterruptsAsOnTheChip(uart, now) {
  let ifls = 0x12; // both levels at 1/2 after reset
  let timeoutAt = Infinity; // 32 bit periods after the last character came
  const level = () => RX_LEVELS[(ifls >> 3) & 7] ?? 28;
  const raise = (bits) => {
    uart.interruptStatus |= bits;
    uart.checkInterrupts();
  };
  uart.feedByte = (value) => {
    uart.rxFIFO.push(value);
    timeoutAt = now() + (32 * 1e9) / (uart.baudRate || 115200);
    if (uart.rxFIFO.itemCount >= level()) raise(RXINTR);
  };
  const read = uart.readUint32.bind(uart);
  uart.readUint32 = (offset) => {
    if (offset === UARTIFLS) return ifls;
    if (offset !== 0x00) return read(offset);
    const value = uart.rxFIFO.pull();
    if (uart.rxFIFO.itemCount < level()) uart.interruptStatus &= ~RXINTR;
    if (uart.rxFIFO.empty) {
      uart.interruptStatus &= ~RTINTR;
      timeoutAt = Infinity;
    }
    uart.checkInterrupts();
    return value;
  };
  const write = uart.writeUint32.bind(uart);
  uart.writeUint32 = (offset, value) => {
    if (offset === UARTIFLS) ifls = value & 0x3f;
    else write(offset, value);
  };
  return {
    due: () => timeoutAt,
    check() {
      if (now() < timeoutAt) return;
      timeoutAt = Infinity;
      if (!uart.rxFIFO.empty) raise(RTINTR);
    },
  };
}
