// DMX512 on UART1's RX line (GP9), as a lighting console sends it, and
// rp2040js's UART bridged where it lacks what DMX needs:
//
// - A break: on the chip, the PL011 sees the line held low for longer than
//   a character and puts one zero character with its break and framing
//   flags (BE, bit 10, and FE, bit 8, of UARTDR) into the receive FIFO,
//   after a character time of low; the next character follows once the line
//   has gone high again and a start bit came. rp2040js has no line, only
//   `feedByte`: here the break character goes into the FIFO with those
//   flags at the time the chip would load it, in order with the bytes.
// - A byte that finds the FIFO full is lost, and the next character carries
//   the overrun flag (OE, bit 11), as on the chip (rp2040js drops it
//   silently).
// - The receive interrupt comes at the FIFO's trigger level and after a
//   pause of 32 bit periods, as on the chip (uart.mjs); rp2040js raises it
//   at every byte.
// - Everything else (the FIFO, UARTDR's flags) is rp2040js's own.
//
// The line: frames back to back, each a break, a mark after break, the
// start code 0 and `slots` slots at `byte_ns` a byte (11 bits at 250 kbaud:
// 44 µs), one every `period_ns` plus a random gap of up to `jitter_ns`
// (a console's frames are not locked to the head's). A frame carries the
// slot values in effect when it starts; `changes` set them (and `stop`
// stops the frames; a later change starts them again).
//
//   cfg: { start_ns, period_ns, jitter_ns, break_ns, mab_ns, byte_ns, slots,
//          address, changes: [{at_ns, set: [[slot, value], ...], stop}] }
//
// (slots in `set` relative to `address`, 1-based). Events:
//   {"ev":"dmx","ns":..,"frame":n,"changed":true}   the last byte of the
//       first frame that carries a change went out (its end)

import { receiveInterruptsAsOnTheChip } from './uart.mjs';

const UARTDR_FE = 1 << 8;
const UARTDR_BE = 1 << 10;
const UARTDR_OE = 1 << 11;
const LCR_H = 0x2c;
const BAUD = 250000;

export function dmxLine(cfg, emit) {
  const changes = [...cfg.changes].sort((a, b) => a.at_ns - b.at_ns);
  const universe = new Uint8Array(513); // [0] is the start code
  let uart = null;
  let now = () => 0;
  let overrun = false;
  let checked = false;
  let interrupts = null; // the receive interrupts as on the chip
  let rng = 0x1f2e3d4c;
  const random = () => {
    rng ^= rng << 13;
    rng ^= rng >>> 17;
    rng ^= rng << 5;
    return (rng >>> 0) / 4294967296;
  };

  // The frame being sent: its bytes (null for none) and its schedule.
  let frame = null;
  let number = 0;
  let next = cfg.start_ns; // when the next frame starts
  let stopped = false;
  let dirty = false; // a change is waiting for the next frame

  function apply(upTo) {
    while (changes.length && changes[0].at_ns <= upTo) {
      const change = changes.shift();
      for (const [slot, value] of change.set ?? []) universe[cfg.address + slot - 1] = value;
      if (change.stop) {
        stopped = true;
      } else {
        if (stopped) next = Math.max(next, change.at_ns);
        stopped = false;
      }
      dirty = true;
    }
  }

  function startFrame(at) {
    apply(at);
    if (stopped) {
      frame = null;
      next = changes.length ? changes[0].at_ns : Infinity;
      return;
    }
    const bytes = universe.slice(0, cfg.slots + 1);
    // The break character, then the start code and the slots.
    const times = [at + cfg.byte_ns];
    for (let i = 0; i <= cfg.slots; i++) times.push(at + cfg.break_ns + cfg.mab_ns + (i + 1) * cfg.byte_ns);
    frame = { bytes, times, at: 0, changed: dirty, n: number };
    dirty = false;
    number += 1;
    const end = times[times.length - 1];
    next = Math.max(at + cfg.period_ns, end) + Math.floor(random() * cfg.jitter_ns);
  }

  function receive(value) {
    if (uart.rxFIFO.full) {
      overrun = true;
      return;
    }
    uart.feedByte(overrun ? value | UARTDR_OE : value);
    overrun = false;
  }

  function check() {
    if (checked) return;
    checked = true;
    const lcr = uart.lineCtrlRegister;
    // WLEN 8 bits (0b11), STP2 set, no parity.
    const framing = ((lcr >> 5) & 3) === 3 && (lcr & 0x08) !== 0 && (lcr & 0x02) === 0;
    if (uart.baudRate !== BAUD || !framing) {
      emit({ ev: 'emu', level: 'warn', msg: `[dmx] UART1 at ${uart.baudRate} baud, LCR_H ${lcr.toString(16)}: not 250000 8N2` });
    }
  }

  return {
    // A new boot's chip: the line goes on into its UART1.
    attach(chipUart, clock) {
      uart = chipUart;
      now = clock;
      overrun = false;
      interrupts = receiveInterruptsAsOnTheChip(uart, clock);
    },
    // When the next character is due, or the receive timeout (Infinity if neither).
    due() {
      return Math.min(frame ? frame.times[frame.at] : next, interrupts.due());
    },
    // Puts every character whose time has come into UART1's FIFO.
    feed() {
      const t = now();
      interrupts.check();
      for (;;) {
        if (!frame) {
          if (t < next) return;
          startFrame(next);
          if (!frame) return;
        }
        if (frame.times[frame.at] > t) return;
        if (frame.at === 0) {
          receive(UARTDR_BE | UARTDR_FE); // the break
        } else {
          if (frame.at === 1) check();
          receive(frame.bytes[frame.at - 1]);
        }
        frame.at += 1;
        if (frame.at === frame.times.length) {
          if (frame.changed) emit({ ev: 'dmx', ns: frame.times[frame.at - 1], frame: frame.n, changed: true });
          frame = null;
        }
      }
    },
  };
}
