// A stand-in for the RP2040's boot ROM: just the flash functions that
// embassy-rp's flash driver looks up, done by the harness on the emulator's
// flash array. rp2040js runs without a boot ROM (none is shipped with it,
// and none is committed here); without one, `rom_table_lookup` is a call to
// address 0 and every flash erase or write fails. The harness loads it in
// every run: the boot reads the flash's unique id after the ROM's
// `connect_internal_flash` and `flash_exit_xip` (the id itself comes over
// the SSI, which chip.mjs answers).
//
// The layout is the documented one (RP2040 datasheet, 2.8.2 "Bootrom
// Contents"): the magic `Mu\x01` and the ROM version at 0x10..0x13, then
// 16-bit pointers to the function table (0x14), the data table (0x16) and
// `rom_table_lookup` (0x18). Every function here is two Thumb instructions,
// `bkpt #n; bx lr`: the harness sees the breakpoint, does the work on the
// chip's registers and memory, and the function returns as the real one
// would. `rom_table_lookup(table, code)` is one of them; it answers the
// codes below and 0 (with a complaint) for any other.
//
// A sector erase and a page program take virtual time, as on the chip,
// while the firmware holds its interrupts off: `erase_ns` per 4 KiB sector,
// `program_ns` per 256-byte page (W25Q16JV: 45 ms and 0.4 ms typically, up
// to 400 ms and 3 ms). The time passes through the harness's `pass`, which
// goes on feeding the chip from outside (UART and DMX lines, USB) meanwhile,
// as the world does while a flash operation stalls the CPU.

const FLASH_START = 0x10000000;
const SECTOR = 4096;
const PAGE = 256;
const FUNC_TABLE = 0x80;
const DATA_TABLE = 0x90;
const FUNCTIONS = 0x100; // `bkpt #n; bx lr` for function n, 4 bytes each
const BKPT = 0xbe00;
const BX_LR = 0x4770;
const ROM_BREAKPOINTS = 0xa0; // breakpoint numbers from here on are the ROM's

// Function n is named by its two-letter code; 0 is `rom_table_lookup`.
const CODES = ['', 'IF', 'EX', 'RE', 'RP', 'FC', 'CX', 'C4', 'MC'];

const code = (name) => name.charCodeAt(0) | (name.charCodeAt(1) << 8);
const entry = (n) => (FUNCTIONS + 4 * n) | 1;

/// The ROM image, as `RP2040.loadBootrom` takes it.
export function romImage() {
  const bytes = new Uint8Array(16 * 1024);
  const view = new DataView(bytes.buffer);
  bytes.set([0x4d, 0x75, 0x01, 3], 0x10); // 'M', 'u', 1, version 3 (B2)
  view.setUint16(0x14, FUNC_TABLE, true);
  view.setUint16(0x16, DATA_TABLE, true);
  view.setUint16(0x18, entry(0), true);
  CODES.forEach((_, n) => {
    view.setUint16(FUNCTIONS + 4 * n, BKPT | (ROM_BREAKPOINTS + n), true);
    view.setUint16(FUNCTIONS + 4 * n + 2, BX_LR, true);
  });
  return new Uint32Array(bytes.buffer);
}

/// Serves ROM breakpoint `number` on `chip`; false if it is not one of the
/// ROM's. `timing` is {erase_ns, program_ns}; `report(event)` is told of
/// every erase and program, `complain(text)` of a call it cannot serve;
/// `pass(ns)` lets the virtual time of an erase or a program pass.
export function serveRom(chip, number, timing, report, complain, pass) {
  const n = number - ROM_BREAKPOINTS;
  // Only the ROM's own breakpoints (the core has already stepped past it).
  const at = chip.core.PC - 2;
  if (n < 0 || n >= CODES.length || at !== FUNCTIONS + 4 * n) return false;
  const r = chip.core.registers;
  const inFlash = (address, length) =>
    address >= 0 && length >= 0 && address + length <= chip.flash.length;
  switch (CODES[n]) {
    case '': {
      // rom_table_lookup(table, code): only the function table is served.
      const found = CODES.findIndex((name, i) => i > 0 && code(name) === r[1]);
      if (r[0] !== FUNC_TABLE || found < 1) {
        complain(`ROM lookup of ${hexCode(r[1])} in table ${r[0]} is not served`);
        r[0] = 0;
      } else {
        r[0] = entry(found);
      }
      break;
    }
    case 'IF': // connect_internal_flash
    case 'EX': // flash_exit_xip
    case 'FC': // flash_flush_cache
    case 'CX': // flash_enter_cmd_xip
      break;
    case 'RE': {
      // flash_range_erase(offset, count, block_size, block_cmd)
      const [offset, count] = [r[0] >>> 0, r[1] >>> 0];
      if (offset % SECTOR || count % SECTOR || !inFlash(offset, count)) {
        complain(`flash_range_erase(${offset}, ${count}) is not whole sectors of the flash`);
        break;
      }
      chip.flash.fill(0xff, offset, offset + count);
      const ns = (count / SECTOR) * timing.erase_ns;
      report({ op: 'erase', addr: FLASH_START + offset, len: count, busy_ns: ns });
      pass(ns);
      break;
    }
    case 'RP': {
      // flash_range_program(offset, data, count): NOR flash only clears bits.
      const [offset, data, count] = [r[0] >>> 0, r[1] >>> 0, r[2] >>> 0];
      if (offset % PAGE || count % PAGE || !inFlash(offset, count)) {
        complain(`flash_range_program(${offset}, .., ${count}) is not whole pages of the flash`);
        break;
      }
      for (let i = 0; i < count; i++) chip.flash[offset + i] &= chip.readUint8(data + i);
      const ns = (count / PAGE) * timing.program_ns;
      report({ op: 'program', addr: FLASH_START + offset, len: count, busy_ns: ns });
      pass(ns);
      break;
    }
    case 'C4': // memcpy44(dest, src, n)
    case 'MC': {
      // memcpy(dest, src, n)
      const [dest, src, count] = [r[0] >>> 0, r[1] >>> 0, r[2] >>> 0];
      for (let i = 0; i < count; i++) chip.writeUint8(dest + i, chip.readUint8(src + i));
      break;
    }
  }
  return true;
}

function hexCode(value) {
  return JSON.stringify(String.fromCharCode(value & 0xff, (value >> 8) & 0xff));
}
