// rp2040js's core and chip, bridged where they differ from the RP2040: SEV,
// the registers it does not model. (Its UART is bridged in uart.mjs, its
// USB in usb.mjs; the watchdog reset is the harness's.)

// rp2040js treats SEV as a no-op that only logs `SEV` at the info level; on
// one core it sets the core's own event register, so that the next WFE
// returns at once. `info` is the chip logger's: it does that on `SEV`
// (and so costs nothing on the other instructions).
export function sevAsOnTheChip(chip) {
  return (name, msg) => {
    if (msg === 'SEV') chip.core.eventRegistered = true;
  };
}

// rp2040js warns at every access to a register it does not model (a read
// gives 0xffffffff, a write does nothing). They are counted per register
// instead, and reported once at the end: `cargo xtask sim` tells the known
// ones from the others.
const UNMODELLED = /^Unimplemented peripheral (read from|write to) 0x([0-9a-f]+)/;
export function unmodelledCounter() {
  const counts = new Map(); // "name op offset" -> {peripheral, op, offset, count}
  return {
    // Counts `msg` if it is such a warning; whether it was.
    note(name, msg) {
      const match = UNMODELLED.exec(msg);
      if (!match) return false;
      const op = match[1] === 'read from' ? 'read' : 'write';
      const offset = parseInt(match[2], 16);
      const key = `${name} ${op} ${offset}`;
      const seen = counts.get(key) ?? { peripheral: name, op, offset, count: 0 };
      seen.count += 1;
      counts.set(key, seen);
      return true;
    },
    // One `unmodelled` event per register, then the counts start again.
    report(emit) {
      for (const seen of counts.values()) emit({ ev: 'unmodelled', ...seen });
      counts.clear();
    },
  };
}

// rp2040js has no XIP control registers (0x14000000..0x14000020): a read
// gives 0xffffffff. Before a flash operation embassy-rp waits for the XIP
// stream counter (STREAM_CTR) to reach 0, for ever at 0xffffffff. Here they
// read as on an idle chip: enabled, no stream, the FIFO empty, the flush
// done; writes (a flush, a stream set-up) have nothing to act on.
const XIP_CTRL = 0x14000000;
const XIP_CTRL_END = 0x14000020;
const XIP_IDLE = { 0x00: 0x3, 0x08: 0x3 }; // CTRL (enabled), STAT (FIFO empty, flush ready)
export function xipControlAsOnTheChip(chip) {
  const read = chip.readUint32.bind(chip);
  chip.readUint32 = (address) => {
    const a = address >>> 0;
    return a >= XIP_CTRL && a < XIP_CTRL_END ? XIP_IDLE[a - XIP_CTRL] ?? 0 : read(address);
  };
  const write = chip.writeUint32.bind(chip);
  chip.writeUint32 = (address, value) => {
    const a = address >>> 0;
    if (a < XIP_CTRL || a >= XIP_CTRL_END) write(address, value);
  };
}

// Speed only, the same behaviour: rp2040js looks each word written up among
// its peripherals before it tries the SRAM (a miss in a sparse table), and
// each word read passes the bridges here first. Word accesses to the SRAM,
// most of a program's, go straight to it. Wraps the bridges: call last.
const RAM_START = 0x20000000;
export function sramFirst(chip) {
  const view = chip.sramView;
  const end = RAM_START + chip.sram.length - 3;
  const read = chip.readUint32.bind(chip);
  chip.readUint32 = (address) => {
    const a = address >>> 0;
    return a >= RAM_START && a < end ? view.getUint32(a - RAM_START, true) : read(address);
  };
  const write = chip.writeUint32.bind(chip);
  chip.writeUint32 = (address, value) => {
    const a = address >>> 0;
    if (a >= RAM_START && a < end) view.setUint32(a - RAM_START, value, true);
    else write(address, value);
  };
}

// rp2040js has no ring oscillator: its RANDOMBIT register (ROSC + 0x1c)
// would read 0xffffffff, one and the same bit for ever. On the chip it is the
// oscillator's jitter. Here it reads as the bits of a fixed-seed xorshift, so
// that the firmware sees varied bits and a run still repeats exactly.
const ROSC_BASE = 0x40060;
const ROSC_RANDOMBIT = 0x1c;
export function roscRandomBit(chip) {
  const rosc = chip.peripherals[ROSC_BASE];
  const read = rosc.readUint32.bind(rosc);
  let state = 0x2545f491;
  rosc.readUint32 = (offset) => {
    if (offset !== ROSC_RANDOMBIT) return read(offset);
    state ^= state << 13;
    state ^= state >>> 17;
    state ^= state << 5;
    return state & 1;
  };
}

// The flash's unique id (command 4Bh) through the SSI. On the chip,
// embassy-rp's `blocking_unique_id` (from RAM, the boot ROM's
// `connect_internal_flash` and `flash_exit_xip` before it) puts the SSI in
// standard SPI, EEPROM-read mode (CTRLR0: SPI_FRF 0, TMOD 3), writes the
// command into DR and reads CTRLR1 + 1 frames back: four dummy bytes, then
// the flash's eight id bytes. rp2040js's SSI answers every DR read with 0
// (it only fakes the status register's reply for boot2), so every board
// would read the id 0. Here, in that mode, the bytes after 4Bh are the
// flash's: the dummy bytes and then `uid` (16 hex digits, the order the
// flash sends them), or all ones without one (a flash without the command
// leaves its output high: no id, as `BoardId` takes it). Any other command
// in that mode, and every other mode (boot2's), is rp2040js's own.
const SSI_BASE = 0x18000;
const SSI_CTRLR0 = 0x00;
const SSI_CTRLR1 = 0x04;
const SSI_SSIENR = 0x08;
const SSI_SR = 0x28;
const SSI_DR0 = 0x60;
const SR_TFNF_TFE = 0x6;
const SR_RFNE = 0x8;
const CMD_UNIQUE_ID = 0x4b;
const UNIQUE_ID_DUMMY = 4;
export function flashUniqueId(chip, uid) {
  const ssi = chip.peripherals[SSI_BASE];
  const id = uid ? [...Buffer.from(uid, 'hex')] : new Array(8).fill(0xff);
  const rx = []; // the frames received, not yet read
  let command = null; // the command of the transfer under way
  const eepromRead = () => ((ssi.crtlr0 >> 8) & 3) === 3 && ((ssi.crtlr0 >> 21) & 3) === 0;
  const read = ssi.readUint32.bind(ssi);
  ssi.readUint32 = (offset) => {
    if (command === CMD_UNIQUE_ID && offset === SSI_SR) return SR_TFNF_TFE | (rx.length ? SR_RFNE : 0);
    if (command === CMD_UNIQUE_ID && offset === SSI_DR0) return rx.shift() ?? 0xff;
    return read(offset);
  };
  const write = ssi.writeUint32.bind(ssi);
  ssi.writeUint32 = (offset, value) => {
    if (offset === SSI_SSIENR) {
      command = null;
      rx.length = 0;
    }
    if (offset === SSI_DR0 && ssi.ssienr & 1 && eepromRead() && command === null && (value & 0xff) === CMD_UNIQUE_ID) {
      command = CMD_UNIQUE_ID;
      const frames = read(SSI_CTRLR1) + 1;
      for (let i = 0; i < frames; i++) rx.push(i < UNIQUE_ID_DUMMY ? 0xff : (id[i - UNIQUE_ID_DUMMY] ?? 0xff));
      return;
    }
    write(offset, value);
  };
}
