// What the outside does to the chip, as the harness's config scripts it:
// the input pins (GP2 to GP5) at their pads' pulls until driven, boot 0's
// script of pin levels and console lines from the first frame on, the
// bytes for UART0's RX line per boot, and the power cycles.
//
// `h` is what the harness shares: `emit` reports, `now` is the virtual time
// since power-on, `chip`, `boot` and `bootNs` the current boot's chip,
// number and start, `active` notes activity (the run is not silent).

import { GPIOPinState } from 'rp2040js';

export function scripted(cfg, h, stream) {
  const { emit, now, active } = h;
  // A line stream for UART0 (stream.mjs), in boot 0.
  const lines = stream?.port === 'uart' ? stream : null;
  const fromStream = (boot) => {
    const line = boot === 0 ? lines?.next() : null;
    return line ? { boot, bytes: line.bytes, at_ns: line.at_ns, byte_ns: lines.byteNs, streamed: true } : null;
  };

  // The inputs the outside drives (GPIO2..5): at their pads' pull until the
  // script drives them. rp2040js has no model of the pulls for an input:
  // here a pin nobody drives reads high with the pull-up on and low
  // otherwise, as on the chip (no floating inputs), and follows its pad
  // register as the firmware changes it. A level is only set when it
  // changes: rp2040js latches an edge interrupt at every set.
  const inputs = new Map(); // pin -> {driven: null|bool, level: bool}
  function inputLevel(pin, state) {
    const input = inputs.get(pin);
    return input.driven ?? state === GPIOPinState.InputPullUp;
  }
  function setInput(chip, pin, level) {
    const input = inputs.get(pin);
    if (input.level === level) return;
    input.level = level;
    chip.gpio[pin].setInputValue(level);
  }
  function watchInputs(chip) {
    for (const pin of cfg.inputs ?? []) {
      // A new chip reads low; what the outside drives it keeps driving.
      const driven = inputs.get(pin)?.driven ?? null;
      inputs.set(pin, { driven, level: false });
      if (driven) setInput(chip, pin, true);
      chip.gpio[pin].addListener((state) => setInput(chip, pin, inputLevel(pin, state)));
    }
  }
  /** The outside drives input `pin` (one of `inputs`) high or low. */
  function drive(pin, high) {
    const input = inputs.get(pin);
    if (!input) return;
    input.driven = high;
    emit({ ev: 'drive', pin, high, ns: now() });
    setInput(h.chip(), pin, high);
    active();
  }

  // UART0's scripted RX line (per boot).
  const scripts = (cfg.uart ?? [])
    .map((s) => ({ ...s, bytes: Buffer.from(s.hex, 'hex') }))
    .sort((a, b) => a.at_ns - b.at_ns);
  let bootScripts = []; // this boot's, in order
  let script = null; // the one going out
  let scriptAt = 0;
  function startBoot(boot) {
    bootScripts = scripts.filter((s) => s.boot === boot);
    script = bootScripts.shift() ?? fromStream(boot);
    scriptAt = 0;
  }
  function uartDue() {
    if (!script || scriptAt >= script.bytes.length) return Infinity;
    return h.bootNs() + script.at_ns + scriptAt * script.byte_ns;
  }
  function feedUart() {
    if (now() < uartDue()) return;
    const damaged = script.errors?.includes(scriptAt) ?? false;
    if (!h.chip().uart[0].receive(script.bytes[scriptAt], damaged)) {
      emit({ ev: 'uart_overrun', ns: now() });
    }
    scriptAt += 1;
    active();
    if (scriptAt === script.bytes.length) {
      // (A streamed line is one of thousands: no event of its own.)
      if (!script.streamed) emit({ ev: 'uart_rx', ns: now(), n: scriptAt });
      script = bootScripts.shift() ?? fromStream(h.boot());
      scriptAt = 0;
    }
  }

  // Boot 0's script: pin levels and console lines from the first frame on.
  const scriptCfg = cfg.script ?? null;
  let anchorNs = null; // when the first frame went out
  let pinQueue = []; // [{ns, pin, high}], absolute, in order
  function anchor(at) {
    if (anchorNs !== null || !scriptCfg) return;
    anchorNs = at;
    pinQueue = scriptCfg.pins.map((p) => ({ ...p, ns: at + p.at_ns })).sort((a, b) => a.ns - b.ns);
    // Lines go out at the line rate, one after the other, each in by its
    // time less `early_ns`: scheduled from the last one back, so that lines
    // due together go out back to back ahead of their time.
    const lines = scriptCfg.lines
      .map((l) => ({ bytes: Buffer.from(l.hex, 'hex'), end: at - h.bootNs() + l.at_ns - scriptCfg.early_ns }))
      .sort((a, b) => a.end - b.end);
    let next = Infinity;
    for (let k = lines.length - 1; k >= 0; k--) {
      const line = lines[k];
      line.end = Math.min(line.end, next);
      line.at_ns = Math.max(0, line.end - line.bytes.length * scriptCfg.byte_ns);
      next = line.at_ns;
    }
    for (const line of lines) Object.assign(line, { boot: h.boot(), byte_ns: scriptCfg.byte_ns });
    bootScripts.push(...lines);
    bootScripts.sort((a, b) => a.at_ns - b.at_ns);
    if (!script || scriptAt === 0) {
      if (script) bootScripts.unshift(script);
      bootScripts.sort((a, b) => a.at_ns - b.at_ns);
      script = bootScripts.shift() ?? null;
      scriptAt = 0;
    }
  }
  const pinDue = () => (pinQueue.length ? pinQueue[0].ns : Infinity);
  function feedPins() {
    while (pinQueue.length && pinQueue[0].ns <= now()) {
      const { pin, high } = pinQueue.shift();
      drive(pin, high);
    }
  }

  // The power cycles still to come.
  const powerCycles = [...(cfg.power_cycles_ns ?? [])].sort((a, b) => a - b);

  return {
    watchInputs,
    drive,
    startBoot,
    uartDue,
    feedUart,
    // The PWM slice whose enable in boot 0 is the first frame: the script's
    // time 0 (`anchor`).
    anchorSlice: scriptCfg?.anchor_slice,
    anchor,
    pinDue,
    feedPins,
    pinsQueued: () => pinQueue.length > 0,
    powerCycleDue: () => powerCycles[0] ?? Infinity,
    // The power cycle due has happened.
    powerCycled: () => powerCycles.shift(),
  };
}
