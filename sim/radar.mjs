// An HLK-LD2450 radar on GP13 (RADAR_PIN): its report frames as the waveform on its TX
// line, which the firmware's PIO UART receives (pio.mjs runs the state
// machine in step with the CPU; rp2040js has no line to drive but a pin's
// level).
//
// A frame is 30 bytes at 256000 baud 8N1, back to back (3.9 µs a bit, 1.17
// ms a frame): the header AA FF 03 00, three targets of eight bytes (x, y,
// speed, distance resolution, 16-bit little-endian; x, y and speed in the
// module's sign encoding: the top bit set for a positive value, clear for
// a negative one, the magnitude in the other 15 bits; an empty slot is
// eight zero bytes) and the footer 55 CC. Encoded here on its own, from
// the module's description, not with the firmware's encoder: the decoder
// is checked against it.
//
// The schedule follows the host trace's (`cargo xtask trace`), so that the
// board takes each frame's sighting at the frame the trace hands it over:
// the radar sends from its first line on, frame k due at k · period_ns from
// the first frame (when `anchor` is called: the script's time 0), carrying
// the people of the last line at or before then; the frame ends `early_ns`
// before the first servo frame at or after that (servo frames every
// `frame_ns`), so that the receiver has it in time. Between frames the
// line idles high, as the module drives it.
//
//   cfg: { baud, period_ns, frame_ns, early_ns, end_ns,
//          lines: [{at_ns, people: [[x_mm, y_mm] | null, ...]}] }
//
// Events: {"ev":"radar","ns":..,"frames":n}  the frames sent in the run, at
// its end (`report`).

/// The pin the radar's TX drives.
export const RADAR_PIN = 13;

const BITS = 10; // a start bit, eight data bits, a stop bit
const FRAME_BYTES = 30;
const RESOLUTION_MM = 360; // what the module reports as its distance gate

// `value` in the module's sign encoding.
function signed(value) {
  const magnitude = Math.min(Math.abs(Math.round(value)), 0x7fff);
  return value >= 0 ? magnitude | 0x8000 : magnitude;
}

// The 30 bytes of a frame seeing `people` (up to three [x, y], or null).
export function ld2450Frame(people) {
  const bytes = [0xaa, 0xff, 0x03, 0x00];
  const word = (w) => bytes.push(w & 0xff, (w >> 8) & 0xff);
  for (let i = 0; i < 3; i++) {
    const person = people[i];
    if (!person) {
      bytes.push(0, 0, 0, 0, 0, 0, 0, 0);
      continue;
    }
    word(signed(person[0]));
    word(signed(person[1]));
    word(signed(0)); // speed: not used by the head
    word(RESOLUTION_MM);
  }
  bytes.push(0x55, 0xcc);
  return bytes;
}

export function radarLine(cfg) {
  const bitNs = 1e9 / cfg.baud;
  const byteNs = BITS * bitNs;
  const lines = [...cfg.lines].sort((a, b) => a.at_ns - b.at_ns);
  let frames = []; // [{start, end, bytes}], in time order (absolute ns)
  let sent = 0;

  // The frames from the first line on, once the first frame's time is known.
  function anchor(at) {
    if (frames.length || !lines.length) return;
    const first = Math.ceil(lines[0].at_ns / cfg.period_ns);
    for (let k = first; k * cfg.period_ns <= cfg.end_ns; k++) {
      const due = k * cfg.period_ns;
      let seen = null;
      for (const line of lines) if (line.at_ns <= due) seen = line.people;
      const frame = Math.ceil(due / cfg.frame_ns) * cfg.frame_ns;
      const end = at + frame - cfg.early_ns;
      frames.push({ start: end - FRAME_BYTES * byteNs, end, bytes: ld2450Frame(seen ?? []) });
    }
  }

  // The frame sending at `t`, or the next one (undefined if none is left).
  let at = 0;
  function frameAt(t) {
    while (at < frames.length && frames[at].end <= t) at++;
    // (Times go back a little when the line is looked at from a state
    // machine's next cycle: look back from where it was.)
    while (at > 0 && frames[at - 1].end > t) at--;
    return frames[at];
  }

  function level(t) {
    const frame = frameAt(t);
    if (!frame || t < frame.start) return true;
    const byte = Math.floor((t - frame.start) / byteNs);
    const bit = Math.floor((t - frame.start - byte * byteNs) / bitNs);
    if (bit === 0) return false;
    if (bit === BITS - 1) return true;
    return ((frame.bytes[byte] >> (bit - 1)) & 1) === 1;
  }

  // The first time from `t` on when the line is at `high`.
  function next(t, high) {
    if (level(t) === high) return t;
    const frame = frameAt(t);
    if (!frame) return Infinity;
    if (t < frame.start) return frame.start; // idle (high) until the start bit
    // Inside the frame: bit by bit to the level (a stop bit is high).
    let edge = frame.start + Math.floor((t - frame.start) / bitNs + 1) * bitNs;
    while (edge < frame.end && level(edge) !== high) edge += bitNs;
    return edge < frame.end ? edge : high ? frame.end : next(frame.end, high);
  }

  return {
    anchor,
    line: { level, next },
    // The frames whose last bit had gone out by `t`.
    count(t) {
      while (sent < frames.length && frames[sent].end <= t) sent++;
      return sent;
    },
  };
}
