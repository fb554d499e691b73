// The head's console as the page speaks it: two transports behind one
// interface (Web Serial for a board, `cargo xtask panel`'s bridge), and a
// console client that sends one line at a time and waits for its reply
// (docs/user/protocol.md), telling telemetry lines (`~ …`) apart.

/** CRC-8/SMBUS, as the firmware's machine mode and telemetry use it. */
export function crc8(bytes) {
  let crc = 0;
  for (const byte of bytes) {
    crc ^= byte;
    for (let i = 0; i < 8; i++) crc = crc & 0x80 ? ((crc << 1) ^ 0x07) & 0xff : (crc << 1) & 0xff;
  }
  return crc;
}

/**
 * A telemetry line (`~ t=… p=… r=… y=… us=a,b,c lost=n *hh`) as numbers,
 * or null if it is damaged. With the radar on it goes on with `targets=n
 * at=<yaw mdeg>|- xy=x,y;x,y|- who=<index>|-`: then `radar` is
 * {targets, at (degrees or null), people [{x, y} mm], who (index or null)}.
 */
export function parseTelemetry(line) {
  const star = line.lastIndexOf(' *');
  if (star < 0) return null;
  const body = line.slice(0, star);
  const crc = parseInt(line.slice(star + 2), 16);
  if (crc !== crc8(new TextEncoder().encode(body))) return null;
  const fields = {};
  for (const word of body.slice(2).split(' ')) {
    const [key, value] = word.split('=');
    fields[key] = value;
  }
  const us = (fields.us ?? '').split(',').map(Number);
  const t = {
    t: Number(fields.t),
    pitch: Number(fields.p) / 1000,
    roll: Number(fields.r) / 1000,
    yaw: Number(fields.y) / 1000,
    us,
    lost: Number(fields.lost),
  };
  if (!([t.t, t.pitch, t.roll, t.yaw, ...us].every(Number.isFinite))) return null;
  if (fields.targets !== undefined) {
    const people = !fields.xy || fields.xy === '-' ? [] : fields.xy.split(';').map((pair) => {
      const [x, y] = pair.split(',').map(Number);
      return { x, y };
    });
    const radar = {
      targets: Number(fields.targets),
      at: fields.at === undefined || fields.at === '-' ? null : Number(fields.at) / 1000,
      people,
      who: fields.who === undefined || fields.who === '-' ? null : Number(fields.who),
    };
    const numbers = [radar.targets, ...people.flatMap((p) => [p.x, p.y])];
    if (radar.at !== null) numbers.push(radar.at);
    if (radar.who !== null) numbers.push(radar.who);
    if (!numbers.every(Number.isFinite)) return null;
    t.radar = radar;
  }
  return t;
}

/** Web Serial: the board's USB serial port, chosen by the user. */
export class SerialTransport {
  constructor(port) {
    this.port = port;
    this.name = 'USB serial port (Web Serial)';
    this.onBytes = () => {};
    this.onClose = () => {};
    this.closed = false;
  }

  static available() {
    return 'serial' in navigator;
  }

  /** Asks the user for the head's port (its USB VID:PID first). */
  static async choose() {
    const port = await navigator.serial.requestPort({
      filters: [{ usbVendorId: 0x16c0, usbProductId: 0x27dd }],
    });
    return new SerialTransport(port);
  }

  async open() {
    await this.port.open({ baudRate: 115200 });
    this.writer = this.port.writable.getWriter();
    this.reader = this.port.readable.getReader();
    this.disconnected = (event) => {
      if (event.target === this.port) this.finish('the board was unplugged');
    };
    navigator.serial.addEventListener('disconnect', this.disconnected);
    this.reading = (async () => {
      try {
        for (;;) {
          const { value, done } = await this.reader.read();
          if (done) break;
          if (value) this.onBytes(value);
        }
        this.finish('the port closed');
      } catch (error) {
        this.finish(`the port failed: ${error.message ?? error}`);
      }
    })();
  }

  async write(bytes) {
    await this.writer.write(bytes);
  }

  finish(why) {
    if (this.closed) return;
    this.closed = true;
    navigator.serial.removeEventListener('disconnect', this.disconnected);
    this.onClose(why);
  }

  async close() {
    this.finish('disconnected');
    try {
      await this.reader?.cancel();
      this.reader?.releaseLock();
      this.writer?.releaseLock();
      await this.port.close();
    } catch {
      // Already gone.
    }
  }
}

/**
 * `cargo xtask panel`'s bridge: the head's bytes as server-sent events
 * (hex digits; an event `gone` when the head goes away), ours by POST.
 */
export class BridgeTransport {
  constructor(name) {
    this.name = name;
    this.onBytes = () => {};
    this.onClose = () => {};
    this.closed = false;
  }

  open() {
    return new Promise((resolve, reject) => {
      const events = new EventSource('events');
      this.events = events;
      let opened = false;
      events.onopen = () => {
        opened = true;
        resolve();
      };
      events.onmessage = (event) => {
        const hex = event.data;
        const bytes = new Uint8Array(hex.length / 2);
        for (let i = 0; i < bytes.length; i++) bytes[i] = parseInt(hex.slice(2 * i, 2 * i + 2), 16);
        this.onBytes(bytes);
      };
      events.addEventListener('gone', (event) => this.finish(`the head went away: ${event.data}`));
      events.onerror = () => {
        if (!opened) reject(new Error('no bridge at this address'));
        this.finish('the bridge closed the connection');
      };
    });
  }

  async write(bytes) {
    if (this.closed) throw new Error('the connection is closed');
    const sent = await fetch('send', { method: 'POST', body: bytes });
    if (!sent.ok) throw new Error(await sent.text());
  }

  finish(why) {
    if (this.closed) return;
    this.closed = true;
    this.events?.close();
    this.onClose(why);
  }

  async close() {
    this.finish('disconnected');
  }
}

/** A reply that did not come in time. */
export class NoReply extends Error {}

/**
 * The console over a transport: `send(line)` resolves to its reply line
 * (`ok …` or `err …`); telemetry lines go to `onTelemetry`, every line to
 * `onLine(direction, text)`.
 */
export class Console {
  constructor(transport, { onTelemetry, onLine, timeout = 3000 }) {
    this.transport = transport;
    this.onTelemetry = onTelemetry;
    this.onLine = onLine;
    this.timeout = timeout;
    this.partial = '';
    this.waiting = null; // {resolve, reject, timer} of the line sent
    this.queue = Promise.resolve();
    this.decoder = new TextDecoder();
    transport.onBytes = (bytes) => this.take(bytes);
  }

  take(bytes) {
    this.partial += this.decoder.decode(bytes, { stream: true });
    let end;
    while ((end = this.partial.indexOf('\n')) >= 0) {
      const line = this.partial.slice(0, end).replace(/\r$/, '');
      this.partial = this.partial.slice(end + 1);
      if (line.startsWith('~')) {
        const telemetry = parseTelemetry(line);
        this.onLine('telemetry', line);
        if (telemetry) this.onTelemetry(telemetry);
      } else if (line.length) {
        this.onLine('in', line);
        const waiting = this.waiting;
        this.waiting = null;
        if (waiting) {
          clearTimeout(waiting.timer);
          waiting.resolve(line);
        }
      }
    }
  }

  /** Sends `line`, after the lines before it have their replies. */
  send(line) {
    const turn = this.queue.then(() => this.exchange(line));
    this.queue = turn.catch(() => {});
    return turn;
  }

  exchange(line) {
    return new Promise((resolve, reject) => {
      if (this.transport.closed) {
        reject(new Error('not connected'));
        return;
      }
      const timer = setTimeout(() => {
        this.waiting = null;
        reject(new NoReply(`no reply to \`${line}\` within ${this.timeout / 1000} s`));
      }, this.timeout);
      this.waiting = { resolve, reject, timer };
      this.onLine('out', line);
      this.transport.write(new TextEncoder().encode(`${line}\n`)).catch((error) => {
        clearTimeout(timer);
        this.waiting = null;
        reject(error);
      });
    });
  }

  /** Fails the line waiting for its reply (the transport closed). */
  abandon(why) {
    const waiting = this.waiting;
    this.waiting = null;
    if (waiting) {
      clearTimeout(waiting.timer);
      waiting.reject(new Error(why));
    }
  }
}

/** `key=value` words of a reply, as an object. */
export function fields(reply) {
  const out = {};
  for (const word of reply.split(' ')) {
    const eq = word.indexOf('=');
    if (eq > 0) out[word.slice(0, eq)] = word.slice(eq + 1);
  }
  return out;
}

/** The command words of `help`'s reply. */
export function commandWords(help) {
  return help.replace(/^ok commands:\s*/, '').split(/\s+/);
}

/** The gesture words of `help`'s reply: between `stop` and `look`. */
export function gestureWords(help) {
  const words = commandWords(help);
  const from = words.indexOf('stop');
  const to = words.indexOf('look');
  return from >= 0 && to > from ? words.slice(from + 1, to) : [];
}

/** An `err <code> <reason>` reply as the page shows it: `refused: <reason>`. */
export function refusal(reply) {
  return reply.replace(/^err \w+ /, 'refused: ');
}
