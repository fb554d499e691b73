// Runs a Raspberry Pi Pico flash image in rp2040js and reports what happened
// as JSON lines on stdout, one event per line. It only reports raw facts;
// `cargo xtask sim` decodes and checks them. Here: the power-up, the boots
// and the watchdog's resets, the RTT log, the run loops; beside it, the
// emulator's gaps (chip.mjs, uart.mjs, pio.mjs), the USB host (usb.mjs),
// DMX512 (dmx.mjs), the radar (radar.mjs), what the outside scripts
// (script.mjs), the boot ROM (rom.mjs).
//
//   node harness.mjs '<config as JSON>'    (or @<file> holding it)
//
// config: {
//   flash:      path of the flash image: a UF2 file (`.uf2`, each block's payload at its
//               address), or a binary loaded at 0x10000000,
//   vtor:       vector table address (0x10000100 behind a 256-byte boot2),
//   rtt:        address of `_SEGGER_RTT` (0 = no RTT),
//   pins:       GPIO numbers whose edges to report,
//   slices:     PWM slices whose compare writes to report,
//   probe:      entry address of a function whose cycles to report per call (0 = none),
//   stack:      [low, high) of the stack region, scanned for paint at the end of a boot,
//   paint:      the stack paint word,
//   ns:         virtual time to run, in nanoseconds,
//   wall_ms:    wall-time limit,
//   silence_ns: end the run when nothing (log byte, pin edge) happens for this long,
//   uart:       bytes for UART0's RX line, a list of {boot, hex, at_ns, byte_ns, errors}: in
//               boot `boot`, from at_ns after its start on, one byte every byte_ns (the line
//               rate), the bytes at the indices in `errors` received with a framing error
//               (line noise); the scripts of one boot go out one after the other,
//   usb:        optional, bytes for the USB serial port: {hex, at_ns}: rp2040js's CDC-ACM
//               host enumerates the device, and from at_ns on sends the bytes; boot 0 only;
//               or a list of them, each sent at its time,
//   dmx:        optional, DMX512 frames on UART1's RX line (GP9): see dmx.mjs,
//   rom:        optional, {erase_ns, program_ns}: how long a sector erase and a page program
//               of the boot ROM's flash functions (rom.mjs, always there: the boot reads the
//               flash's unique id through them) take; the W25Q16JV's worst case without,
//   uid:        optional, the flash's unique id, 16 hex digits (chip.mjs; without: none, all ones),
//   radar:      optional, an HLK-LD2450 on GP13 (radar.mjs), its frames from the script's time 0;
//               without, GP13 sits at its pad's pull (nothing wired),
//   flash_fill: optional, {addr, hex}: bytes written over the image's flash before power-on,
//   power_cycles_ns: optional, virtual times at which the power goes off and on again:
//               the next boot starts from the flash as the last one left it, nothing else kept,
//   live:       optional, true: a head for a person (`cargo xtask panel --sim`): the chip runs
//               at real time (virtual time kept within a few ms of the wall clock since the
//               start) for as long as stdin is open; each stdin line is hex digits, bytes for
//               the USB serial port (sent once the CDC-ACM host has configured the device),
//               or `dtr 0` / `dtr 1`: the host closes or opens the port (DTR and RTS),
//               or `pin <n> 0` / `pin <n> 1`: the outside drives input n (of `inputs`) low or high;
//               the bytes the device sends are `usb` events, the log `rtt` events, flushed as
//               they come; `ns`, `silence_ns`, `uart`, `usb` and the power cycles are not used,
//   inputs:     optional, GPIOs the outside drives as inputs (GP2 to GP5): each sits at the level
//               its pad's pull gives it (pull-up: high, else low) until the script drives it,
//   stream:     optional, a stream of console lines for UART0 or USB, made as they go out (stream.mjs),
//   script:     optional, boot 0's script, its times counted from the first frame (when
//               `anchor_slice`, a PWM slice, is enabled): {anchor_slice, pins: [{at_ns, pin,
//               high}], lines: [{at_ns, hex}], byte_ns}: a pin driven high or low at at_ns; a
//               console line on UART0's RX line at the line rate, its last byte in by at_ns less
//               `early_ns` (so that the firmware has it before the frame due at at_ns),
// }
//
// Events ("ns" is virtual time since power-on, across resets):
//   {"ev":"boot","n":0,"ns":..}                     a boot starts (0 = power-on)
//   {"ev":"rtt","ns":..,"hex":".."}                 bytes from the RTT up-buffer
//   {"ev":"edge","pin":16,"high":true,"ns":..}      a pin changed level ("reset":true: by a reset)
//   {"ev":"cc","slice":0,"value":..,"ns":..}        a PWM compare register write
//   {"ev":"en","slice":0,"on":true,"ns":..}         a PWM slice enabled or disabled
//   {"ev":"call","cycles":..,"ns":..}               one call of the probed function
//   {"ev":"watchdog","ns":..,"reason":1}            the watchdog fired (1 timer, 2 forced)
//   {"ev":"power_cycle","ns":..}                    the power went off (the next boot follows)
//   {"ev":"flash","op":"erase","addr":..,"len":..,"busy_ns":..,"ns":..}
//                                                   the ROM erased or programmed ("program") flash
//   {"ev":"stack","n":0,"low":..}                   lowest stack address written in boot n
//   {"ev":"uart","ns":..,"hex":".."}                bytes UART0 sent (TX), stamped with the first
//   {"ev":"uart_rx","ns":..,"n":..}                  the last scripted byte went onto the RX line
//   {"ev":"drive","pin":2,"high":true,"ns":..}      the script drove an input pin (the time of its edge)
//   {"ev":"uart_overrun","ns":..}                   a scripted byte found UART0's RX FIFO full
//   {"ev":"usb_connected","ns":..}                  the CDC-ACM host configured the device
//   {"ev":"usb","ns":..,"hex":".."}                 bytes the device sent on its CDC-ACM IN endpoint
//   {"ev":"usb_in","ns":..,"n":..}                  the host sent a scripted chunk of n bytes
//   {"ev":"dmx","ns":..,"frame":..,"changed":true}  a DMX frame with a change ended (dmx.mjs)
//   {"ev":"radar","ns":..,"frames":..}              the radar frames sent in the run, at its end
//   {"ev":"unmodelled","peripheral":"ROSC_BASE","op":"write","offset":4,"count":1}
//                                                   accesses to a register rp2040js does not
//                                                   model, counted over the run (at its end)
//   {"ev":"emu","level":"warn","msg":".."}          another complaint of the emulator
//   {"ev":"end","why":"time|silent|asleep|wall|break|error|closed","ns":..,"instructions":..,"wall_ms":..}
//                                                   ("closed": stdin closed, in a live run)

import { readFileSync } from 'node:fs';
import { RP2040 } from 'rp2040js';
import {
  flashUniqueId,
  roscRandomBit,
  sevAsOnTheChip,
  sramFirst,
  unmodelledCounter,
  xipControlAsOnTheChip,
} from './chip.mjs';
import { pioInStep } from './pio.mjs';
import { RADAR_PIN, radarLine } from './radar.mjs';
import { romImage, serveRom } from './rom.mjs';
import { scripted } from './script.mjs';
import { uartAsOnTheChip } from './uart.mjs';
import { usbLink } from './usb.mjs';
import { dmxLine } from './dmx.mjs';
import { lineStream } from './stream.mjs';

// The configuration, as JSON or `@<file>` with the JSON in it.
const arg = process.argv[2] ?? '{}';
const cfg = JSON.parse(arg.startsWith('@') ? readFileSync(arg.slice(1), 'utf8') : arg);
const FLASH_START = 0x10000000;
const RAM_START = 0x20000000;
const NS_PER_CYCLE = 8; // 125 MHz, as rp2040js's own Simulator assumes
const WATCHDOG_BASE = 0x40058;
const RTT_WRITE = 36; // offsets in `_SEGGER_RTT`: up-buffer 0's write, read, flags
const RTT_READ = 40;
const RTT_FLAGS = 44;
const RTT_BUFFER = 28;
const RTT_SIZE = 32;
const RTT_BLOCK_IF_FULL = 2; // what a debugger sets, so that no log byte is dropped

const image = readFileSync(cfg.flash);
const started = Date.now();
let out = '';
const emit = (event) => {
  out += JSON.stringify(event) + '\n';
  if (out.length > 1 << 16) flush();
};
const flush = () => {
  if (out) process.stdout.write(out);
  out = '';
};

let mcu; // the current boot's chip
let boot = -1;
let bootNs = 0; // virtual time at which the current boot started
let lastActivity = 0; // virtual time of the last log byte or pin edge
let instructions = 0;
let watchdogFired = null; // {reason, scratch} once the watchdog fires in this boot
let stop = null; // why the run ends, once it does
const level = new Map(cfg.pins.map((pin) => [pin, false]));
const now = () => bootNs + mcu.clock.nanos;
const active = () => {
  lastActivity = now();
};

// The parts: the registers rp2040js lacks (chip.mjs), the USB serial port
// (usb.mjs), what the outside scripts (script.mjs), DMX512 on UART1's RX
// line (dmx.mjs).
const unmodelled = unmodelledCounter();
const stream = lineStream(cfg);
const usb = usbLink(cfg, { emit, now, active }, stream);
const outside = scripted(cfg, { emit, now, active, chip: () => mcu, boot: () => boot, bootNs: () => bootNs }, stream);
const dmx = cfg.dmx ? dmxLine(cfg.dmx, emit) : null;
// The PIO state machines in step with the CPU (pio.mjs), and what drives
// GP13: the radar's TX (radar.mjs), or nothing wired, the pad's pull.
const pio = pioInStep();
const radar = cfg.radar ? radarLine(cfg.radar) : null;
pio.drive(
  RADAR_PIN,
  radar?.line ?? {
    level: () => mcu.gpio[RADAR_PIN].pullupEnabled,
    next: (t, high) => (mcu.gpio[RADAR_PIN].pullupEnabled === high ? t : Infinity),
  },
);
// The boot ROM's flash functions take the W25Q16JV's worst case unless told.
const romTiming = cfg.rom ?? { erase_ns: 400e6, program_ns: 3e6 };

// The flash at power-on: the image, and `flash_fill` over it.
function firstFlash() {
  const flash = new Uint8Array(16 << 20).fill(0xff);
  if (!cfg.flash.endsWith('.uf2')) flash.set(image);
  for (let at = 0; cfg.flash.endsWith('.uf2') && at < image.length; at += 512) {
    const word = (offset) => image.readUInt32LE(at + offset);
    if (word(0) !== 0x0a324655 || word(4) !== 0x9e5d5157 || word(508) !== 0x0ab16f30) {
      throw new Error(`${cfg.flash}: block ${at / 512} is not a UF2 block`);
    }
    flash.set(image.subarray(at + 32, at + 32 + word(16)), word(12) - FLASH_START);
  }
  if (cfg.flash_fill) flash.set(Buffer.from(cfg.flash_fill.hex, 'hex'), cfg.flash_fill.addr - FLASH_START);
  return flash;
}

// A fresh chip, as after power-on, a power cycle or a watchdog reset. The
// flash keeps what was written to it. The watchdog's REASON and SCRATCH
// registers survive a watchdog reset, and SRAM keeps its contents.
function powerUp(kept) {
  const chip = new RP2040();
  chip.loadBootrom(romImage()); // (this erases the flash: load it after)
  chip.logger = {
    debug() {},
    info: sevAsOnTheChip(chip),
    warn: (name, msg) => unmodelled.note(name, msg) || emit({ ev: 'emu', level: 'warn', msg: `[${name}] ${msg}` }),
    error: (name, msg) => emit({ ev: 'emu', level: 'error', msg: `[${name}] ${msg}` }),
  };
  chip.onBreak = (code) => {
    const flashOp = (op) => {
      emit({ ev: 'flash', ...op, ns: now() });
      lastActivity = now();
    };
    const complain = (msg) => emit({ ev: 'emu', level: 'error', msg });
    if (serveRom(chip, code, romTiming, flashOp, complain, stall)) return;
    emit({ ev: 'emu', level: 'error', msg: `breakpoint ${code} at ${hex(chip.core.PC)}` });
    stop = 'break';
  };
  chip.flash.set(kept.flash);
  const watchdog = chip.peripherals[WATCHDOG_BASE];
  if (kept.sram) {
    chip.sram.set(kept.sram);
    watchdog.reason = kept.reason;
    watchdog.scratchData.set(kept.scratch);
  }
  // rp2040js leaves the reset to its user. Its watchdog alarm re-arms itself
  // for the same instant once the counter is at 0, so stop the counter first.
  watchdog.onWatchdogTrigger = () => {
    watchdogFired = { reason: watchdog.reason, scratch: watchdog.scratchData.slice() };
    watchdog.alarm.enable = false;
    watchdog.timer.enable = false;
    chip.clock.nextAlarm = null; // the chip is about to be reset: nothing more fires
  };
  for (const pin of cfg.pins) {
    chip.gpio[pin].addListener((state) => edge(pin, state === 1));
  }
  outside.watchInputs(chip);
  uartAsOnTheChip(chip.uart[0], () => now());
  if (dmx) dmx.attach(chip.uart[1], () => now());
  xipControlAsOnTheChip(chip);
  roscRandomBit(chip);
  flashUniqueId(chip, cfg.uid);
  sramFirst(chip);
  if ((cfg.usb || cfg.live || stream?.port === 'usb') && boot === 0) usb.attach(chip);
  chip.uart[0].onByte = (byte) => {
    if (uartTx.bytes.length === 0) uartTx.ns = now();
    uartTx.bytes.push(byte);
    lastActivity = now();
  };
  for (const slice of cfg.slices) {
    const channel = chip.pwm.channels[slice];
    const write = channel.writeRegister.bind(channel);
    channel.writeRegister = (offset, value) => {
      const on = channel.csr & 1;
      write(offset, value);
      if (offset === 0x0c) emit({ ev: 'cc', slice, value: value >>> 0, ns: now() });
      if (offset === 0x00 && (channel.csr & 1) !== on) {
        emit({ ev: 'en', slice, on: !on, ns: now() });
        if (!on && boot === 0 && slice === outside.anchorSlice) {
          outside.anchor(now());
          radar?.anchor(now());
        }
        // On the chip a channel's output is high while the counter is below
        // the compare value, also right after the enable; rp2040js only
        // raises it at the first wrap. Set it here as the chip does (the
        // compare alarm lowers it as usual).
        if (!on) channel.setA(channel.timer.counter < channel.alarmA.target);
      }
    };
  }
  chip.core.VTOR = cfg.vtor;
  chip.core.reset(); // SP and PC from the vector table, as boot2 hands over
  return chip;
}

// The outside's inputs due by now: UART0's RX line and its TX side, USB,
// DMX, the input pins.
function feedOutside() {
  while (outside.uartDue() <= now()) outside.feedUart();
  mcu.uart[0].sendDue();
  if (usb.send) usb.feed();
  if (dmx) dmx.feed();
  pio.feed();
  if (outside.pinsQueued()) outside.feedPins();
}

// `ns` of virtual time while the CPU stalls (a flash operation in the
// ROM), in steps of a few µs, the outside fed at each: the peripherals and
// the DMA go on, as on the chip.
const STALL_STEP_NS = 5000;
function stall(ns) {
  const end = now() + ns;
  while (now() < end) {
    mcu.clock.tick(Math.min(STALL_STEP_NS, end - now()));
    feedOutside();
  }
}

// UART0's bytes sent (TX), stamped with the first.
const uartTx = { bytes: [], ns: 0 };
function flushUart() {
  if (uartTx.bytes.length === 0) return;
  emit({ ev: 'uart', ns: uartTx.ns, hex: Buffer.from(uartTx.bytes).toString('hex') });
  uartTx.bytes = [];
}

function edge(pin, high, reset = false) {
  if (level.get(pin) === high) return;
  level.set(pin, high);
  lastActivity = now();
  emit(reset ? { ev: 'edge', pin, high, ns: lastActivity, reset } : { ev: 'edge', pin, high, ns: lastActivity });
}

function drainRtt() {
  const base = cfg.rtt - RAM_START;
  const view = mcu.sramView;
  const flags = view.getUint32(base + RTT_FLAGS, true);
  if ((flags & 3) !== RTT_BLOCK_IF_FULL) {
    view.setUint32(base + RTT_FLAGS, (flags & ~3) | RTT_BLOCK_IF_FULL, true);
  }
  const write = view.getUint32(base + RTT_WRITE, true);
  let read = view.getUint32(base + RTT_READ, true);
  if (write === read) return;
  const buffer = view.getUint32(base + RTT_BUFFER, true) - RAM_START;
  const size = view.getUint32(base + RTT_SIZE, true);
  if (buffer < 0 || buffer + size > mcu.sram.length || write >= size || read >= size) return;
  if (rtt.bytes.length === 0) rtt.ns = now();
  while (read !== write) {
    rtt.bytes.push(mcu.sram[buffer + read]);
    read = (read + 1) % size;
  }
  view.setUint32(base + RTT_READ, read, true);
  lastActivity = now();
}

// Log bytes go out in batches, stamped with the time of the first.
const rtt = { bytes: [], ns: 0 };
function flushRtt() {
  if (rtt.bytes.length === 0) return;
  emit({ ev: 'rtt', ns: rtt.ns, hex: Buffer.from(rtt.bytes).toString('hex') });
  rtt.bytes = [];
}

// The lowest word of the stack region that no longer holds the paint.
function stackLow() {
  const [low, high] = cfg.stack;
  for (let a = low; a < high; a += 4) {
    if (mcu.sramView.getUint32(a - RAM_START, true) !== cfg.paint >>> 0) return a;
  }
  return high;
}

function hex(n) {
  return '0x' + (n >>> 0).toString(16);
}

function startBoot(kept) {
  if (mcu) bootNs += mcu.clock.nanos;
  boot += 1;
  outside.startBoot(boot);
  mcu = powerUp(kept);
  pio.attach(mcu, now);
  watchdogFired = null;
  emit({ ev: 'boot', n: boot, ns: bootNs });
  for (const pin of cfg.pins) edge(pin, false, true); // a reset releases the pins: low
}

function endBoot() {
  if (cfg.stack) emit({ ev: 'stack', n: boot, low: stackLow() });
}

// rp2040js's `nanosToNextAlarm` is 0 both when no alarm is set and when one
// is due now (a DMA transfer, scheduled with no delay when its DREQ rises):
// the loops below take 0 for none. A due one fires here, at once (else a
// sleeping chip's clock would jump past the alarms after it, their
// interrupts taken late); true if one did.
function alarmDue(clock) {
  if (!clock.nextAlarm || clock.nextAlarm.nanos > clock.nanos) return false;
  clock.tick(0);
  return true;
}

// One instruction.
function step() {
  const { core, clock } = mcu;
  const cycles = core.executeInstruction();
  instructions++;
  clock.tick(cycles * NS_PER_CYCLE);
}

// rp2040js leaves the reset to its user: the next boot on the chip as the
// watchdog left it (flash and SRAM, its REASON and SCRATCH registers).
function resetAfterWatchdog() {
  emit({ ev: 'watchdog', ns: now(), reason: watchdogFired.reason });
  endBoot();
  const kept = {
    flash: mcu.flash.slice(),
    sram: mcu.sram.slice(),
    reason: watchdogFired.reason,
    scratch: watchdogFired.scratch,
  };
  startBoot(kept);
}

function run() {
  const feedsUart = Boolean(cfg.uart || cfg.script || stream);
  startBoot({ flash: firstFlash() });
  let call = null; // {ret, cycles} while the probed function runs
  while (!stop) {
    const { core, clock } = mcu;
    for (let i = 0; i < 4096 && !stop && !watchdogFired; i++) {
      if (core.waiting) {
        if (alarmDue(clock)) continue;
        let wait = clock.nanosToNextAlarm;
        const due = outside.uartDue() - now(); // asleep until the next scripted byte at the latest
        if (due <= 0) {
          outside.feedUart();
          continue;
        }
        if (due !== Infinity && (wait <= 0 || due < wait)) wait = due;
        const sending = mcu.uart[0].txDue() - now(); // a byte leaving UART0
        if (sending <= 0) {
          mcu.uart[0].sendDue();
          continue;
        }
        if (sending !== Infinity && (wait <= 0 || sending < wait)) wait = sending;
        const more = Math.min(dmx ? dmx.due() : Infinity, usb.due(), pio.due()) - now(); // DMX, USB, PIO
        if (more <= 0) {
          if (dmx) dmx.feed();
          if (usb.send) usb.feed();
          pio.feed();
          continue;
        }
        if (more !== Infinity && (wait <= 0 || more < wait)) wait = more;
        const cycle = outside.powerCycleDue() - now();
        if (cycle <= 0) break;
        if (cycle !== Infinity && (wait <= 0 || cycle < wait)) wait = cycle;
        const driving = outside.pinDue() - now(); // asleep until the next scripted pin at the latest
        if (driving <= 0) {
          outside.feedPins();
          continue;
        }
        if (driving !== Infinity && (wait <= 0 || driving < wait)) wait = driving;
        if (wait <= 0) {
          stop = 'asleep';
          break;
        }
        clock.tick(wait);
        continue;
      }
      const pc = core.PC;
      if (pc === cfg.probe && call === null) call = { ret: core.LR & ~1, cycles: core.cycles };
      else if (call !== null && pc === call.ret) {
        emit({ ev: 'call', cycles: core.cycles - call.cycles, ns: now() });
        call = null;
      }
      step();
      // What comes from outside, looked at every 32 instructions (a quarter
      // of a µs at 125 MHz: a byte on UART0 takes 87 µs).
      if ((i & 31) !== 0) continue;
      if ((i & 63) === 0 && cfg.rtt) drainRtt();
      if (feedsUart) outside.feedUart();
      if (outside.pinsQueued()) outside.feedPins();
      mcu.uart[0].sendDue();
      if ((i & 255) === 0 && usb.send) usb.feed();
      if (dmx) dmx.feed();
      if ((i & 63) === 0) pio.feed();
      if ((i & 255) === 0 && now() >= outside.powerCycleDue()) break;
    }
    if (cfg.rtt) drainRtt();
    flushRtt();
    flushUart();
    if (watchdogFired) {
      call = null;
      resetAfterWatchdog();
      continue;
    }
    if (now() >= outside.powerCycleDue()) {
      outside.powerCycled();
      emit({ ev: 'power_cycle', ns: now() });
      endBoot();
      call = null;
      startBoot({ flash: mcu.flash.slice() });
      continue;
    }
    if (stop) break;
    if (now() >= cfg.ns) stop = 'time';
    else if (now() - lastActivity > cfg.silence_ns) stop = 'silent';
    else if (Date.now() - started > cfg.wall_ms) stop = 'wall';
  }
  endBoot();
  unmodelled.report(emit);
  if (radar) emit({ ev: 'radar', ns: now(), frames: radar.count(now()) });
  emit({ ev: 'end', why: stop, ns: now(), instructions, wall_ms: Date.now() - started });
  flush();
}

// A live run: the chip at real time, stdin to its USB serial port. The
// chip runs in slices up to a few ms ahead of the wall clock, then the
// harness sleeps until the wall clock catches up, so timers, the frames and
// the replies come at their true times; stdin is read between slices.
const AHEAD_NS = 5e6;
async function runLive() {
  const pending = []; // bytes from stdin, waiting for the device
  const controls = []; // control line states from stdin, waiting for the device
  const drives = []; // input levels from stdin: [pin, high]
  let carry = '';
  process.stdin.on('data', (chunk) => {
    const lines = (carry + chunk.toString('latin1')).split('\n');
    carry = lines.pop();
    for (const line of lines) {
      const dtr = /^dtr ([01])$/.exec(line.trim());
      const pin = /^pin (\d+) ([01])$/.exec(line.trim());
      if (dtr) controls.push(dtr[1] === '1' ? 0x3 : 0x0);
      else if (pin) drives.push([Number(pin[1]), pin[2] === '1']);
      else pending.push(...Buffer.from(line.trim(), 'hex'));
    }
  });
  process.stdin.on('end', () => {
    stop = stop ?? 'closed';
  });
  startBoot({ flash: firstFlash() });
  const t0 = process.hrtime.bigint();
  const wallNs = () => Number(process.hrtime.bigint() - t0);
  while (!stop) {
    if (usb.live && pending.length) usb.live(pending.splice(0));
    if (usb.lines && controls.length) usb.lines(controls.shift());
    for (const [pin, high] of drives.splice(0)) outside.drive(pin, high);
    const until = wallNs() + AHEAD_NS;
    const { core, clock } = mcu;
    while (!stop && !watchdogFired && now() < until) {
      if (core.waiting) {
        if (alarmDue(clock)) continue;
        const wait = clock.nanosToNextAlarm;
        const sending = mcu.uart[0].txDue() - now();
        if (sending <= 0) {
          mcu.uart[0].sendDue();
          continue;
        }
        // Asleep with nothing due before `until`: on to the wall clock.
        let step = until - now();
        if (wait > 0 && wait < step) step = wait;
        if (sending !== Infinity && sending < step) step = sending;
        clock.tick(step);
        continue;
      }
      step();
      if ((instructions & 63) === 0 && cfg.rtt) drainRtt();
      if ((instructions & 15) === 0) mcu.uart[0].sendDue();
      if ((instructions & 63) === 0) pio.feed();
    }
    if (cfg.rtt) drainRtt();
    flushRtt();
    flushUart();
    flush();
    if (watchdogFired) {
      resetAfterWatchdog();
      continue;
    }
    const ahead = (now() - wallNs()) / 1e6;
    await new Promise((resolve) => setTimeout(resolve, Math.max(0, ahead)));
  }
  unmodelled.report(emit);
  emit({ ev: 'end', why: stop, ns: now(), instructions, wall_ms: Date.now() - started });
  flush();
  process.exit(0);
}

try {
  if (cfg.live) await runLive();
  else run();
} catch (error) {
  unmodelled.report(emit);
  emit({ ev: 'end', why: 'error', msg: String(error?.stack ?? error), ns: mcu ? now() : 0, instructions, wall_ms: Date.now() - started });
  flush();
  process.exitCode = 1;
}
