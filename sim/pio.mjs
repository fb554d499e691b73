// rp2040js's PIO, run in step with the emulated CPU.
//
// The chip: a state machine runs at clk_sys divided by its CLKDIV (an
// integer and 1/256ths), one instruction a cycle, each followed by its
// delay cycles; a stalled instruction (a `wait`, a `push` into a full FIFO)
// looks at its condition again every cycle; IN and JMP PIN sample the pins
// at the cycle the instruction runs. With SHIFTCTRL's FJOIN_RX its RX FIFO
// is 8 deep.
//
// rp2040js 1.4.1: `RPPIO.run` steps every state machine from a
// `setTimeout(0)` loop, 1000 instructions at a time, on the wall clock and
// not in step with the emulated CPU; each step is one instruction whatever
// the clock divider and the delay cycles; the FIFOs are 4 deep whatever
// FJOIN says. Under the harness, whose run loop never yields to Node's event
// loop, the state machines would not run at all until the run ended (and a
// UART program's bit timing would be meaningless).
//
// The bridge: rp2040js's loop is switched off, and each enabled state
// machine is stepped here, up to the virtual time the harness has reached,
// at its own clock: its next cycle is one cycle on after a stalled cycle,
// 1 + delay cycles after an instruction (or a stall that ends). Before each
// cycle, the input lines the harness drives (`drive(pin, line)`: the
// radar's on GP13) are set to their level at that moment, as the pin's
// synchroniser would see it. A state machine stalled on a `wait` for a
// driven pin skips straight to the cycle where the line next has the level
// it waits for: the cycles in between would only look again at a level
// that has not changed, so the outcome is the chip's. One stalled on
// anything else (another pin, an IRQ flag, a full FIFO) is stepped again at
// the harness's next look; rp2040js itself ends those stalls when the CPU,
// the DMA or the harness changes what they wait for. A joined RX FIFO is
// made 8 deep when the machine starts.

import { FIFO } from 'rp2040js';

const NS_PER_CYCLE = 8; // clk_sys at 125 MHz, as the harness runs the core
const WAIT_PIN = 1; // rp2040js's WaitType.Pin
const FJOIN_RX = 1 << 31;

export function pioInStep() {
  let chip = null;
  let machines = []; // [{m, t}]: t is the virtual time of m's next cycle (null: stopped)
  const lines = new Map(); // pin -> {level(t), next(t, level)}
  let now = () => 0;

  const cycleNs = (m) => NS_PER_CYCLE * ((m.clockDivInt || 65536) + m.clockDivFrac / 256);

  // A line's level at `t`, set on the pin if it changed (rp2040js ends a
  // `wait` on that pin at once if the new level is the one it waits for).
  function setLines(t) {
    for (const [pin, line] of lines) {
      const level = line.level(t);
      const gpio = chip.gpio[pin];
      if (gpio.rawInputValue !== level) gpio.setInputValue(level);
    }
  }

  // One cycle of `m` (its pins already set): how many cycles it took.
  function cycle(m) {
    if (m.waiting) {
      const delay = Math.max(0, m.waitDelay);
      m.checkWait();
      return m.waiting ? 1 : 1 + delay;
    }
    const before = m.cycles;
    m.updatePC = true;
    m.executeInstruction(m.pio.instructions[m.pc]);
    if (m.updatePC) m.nextPC();
    return m.waiting ? 1 : Math.max(1, m.cycles - before);
  }

  // Runs `s.m` from `s.t` up to `until`.
  function run(s, until) {
    const { m } = s;
    const step = cycleNs(m);
    while (s.t <= until) {
      const waiting = m.waiting;
      const delay = Math.max(0, m.waitDelay);
      setLines(s.t);
      if (waiting && !m.waiting) {
        // The new level ended the wait in this cycle.
        s.t += (1 + delay) * step;
        continue;
      }
      if (m.waiting) {
        const line = m.waitType === WAIT_PIN ? lines.get(m.waitIndex) : null;
        const at = line ? line.next(s.t, m.waitPolarity) : Infinity;
        if (at > s.t) {
          // Nothing changes before `at`: on to the cycle at or after it (or
          // past `until`, to look again then).
          const to = Math.min(at, until + step);
          s.t += Math.max(1, Math.ceil((to - s.t) / step)) * step;
          continue;
        }
      }
      s.t += cycle(m) * step;
    }
  }

  return {
    // A new boot's chip: its PIOs run here from now on.
    attach(newChip, clock) {
      chip = newChip;
      now = clock;
      for (const pio of chip.pio) pio.run = () => {};
      machines = chip.pio.flatMap((pio) => pio.machines.map((m) => ({ m, t: null })));
      setLines(now());
    },
    // `pin` follows `line` from now on: `line.level(t)` is its level at
    // virtual time t, `line.next(t, level)` the first time from t on when
    // it has `level` (Infinity if never).
    drive(pin, line) {
      lines.set(pin, line);
    },
    // When a state machine has its next cycle to run (Infinity if none
    // does, or all wait for what only the CPU or the harness can change).
    due() {
      let due = Infinity;
      for (const s of machines) {
        if (!s.m.enabled || s.t === null) continue;
        let at = s.t;
        if (s.m.waiting) {
          const line = s.m.waitType === WAIT_PIN ? lines.get(s.m.waitIndex) : null;
          at = line ? Math.max(s.t, line.next(s.t, s.m.waitPolarity)) : Infinity;
        }
        due = Math.min(due, at);
      }
      return due;
    },
    // Runs every enabled state machine up to now.
    feed() {
      const t = now();
      for (const s of machines) {
        if (!s.m.enabled) {
          s.t = null;
          continue;
        }
        if (s.t === null) {
          // Started: from now, with its joined FIFO as deep as the chip's.
          s.t = t;
          if (s.m.shiftCtrl & FJOIN_RX && s.m.rxFIFO.size !== 8) s.m.rxFIFO = new FIFO(8);
        }
        run(s, t);
      }
    },
  };
}
