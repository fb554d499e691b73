// A stream of console lines for UART0 or the USB serial port: `count`
// lines, one every `every_ns` from `start_ns` on (boot 0), cycling through
// `lines`: `{text}` as it is, `{machine}` in machine mode, with the line's
// index (mod 100000) as its sequence number and its CRC-8 checksum. Made one
// at a time as they go out, so that a run of minutes needs no script of
// hundreds of thousands of lines.
//
//   stream: {port: 'uart'|'usb', start_ns, every_ns, count, byte_ns, lines: [{text}|{machine}]}

export function lineStream(cfg) {
  const s = cfg.stream;
  if (!s) return null;
  let k = 0;
  return {
    port: s.port,
    byteNs: s.byte_ns,
    // The next line, {at_ns, bytes}, or null after the last.
    next() {
      if (k >= s.count) return null;
      const template = s.lines[k % s.lines.length];
      const text = template.machine !== undefined ? machineLine(k % 100000, template.machine) : template.text;
      const line = { at_ns: s.start_ns + k * s.every_ns, bytes: Buffer.from(`${text}\r\n`) };
      k += 1;
      return line;
    },
  };
}

// `#<seq> <command> *<crc>`: the CRC-8 (SMBus: polynomial 0x07, initial
// value 0) of everything before ` *`, as the console checks it.
function machineLine(seq, command) {
  const body = `#${seq} ${command}`;
  let crc = 0;
  for (const byte of Buffer.from(body)) {
    crc ^= byte;
    for (let bit = 0; bit < 8; bit++) crc = crc & 0x80 ? ((crc << 1) ^ 0x07) & 0xff : (crc << 1) & 0xff;
  }
  return `${body} *${crc.toString(16).padStart(2, '0')}`;
}
