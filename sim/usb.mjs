// The USB serial port: rp2040js's CDC-ACM host on the chip's USB
// controller, bridged where it differs from the chip and a real host, and
// the bytes it sends (the config's `usb` chunks at their times, or a live
// run's stdin).
//
// Two gaps of rp2040js's USB device controller and its CDC-ACM host, bridged
// as the chip and a real host behave:
// - The controller clears an OUT buffer's AVAILABLE bit as soon as the
//   firmware sets it, before any packet has arrived. On the chip it stays
//   set until a packet is in the buffer. embassy-rp waits for the bit to
//   clear and then reads the buffer with the length it wrote itself (64), so
//   it reads stale bytes as a packet. Here the bit stays set until the host's
//   packet is written into the buffer.
// - The host answers every OUT transfer at once, with a zero-length packet
//   when it has nothing to send. A real host sends nothing (the device NAKs)
//   until it has data. Here a transfer waits until there are bytes.

import { USBCDC } from 'rp2040js';

const EP0_IN_BUFFER_CONTROL = 0x80;
const EP15_OUT_BUFFER_CONTROL = 0xfc;
const USB_BUF_CTRL_FULL = 1 << 15;
const USB_BUF_CTRL_AVAILABLE = 1 << 10;

// The host side of the port for the harness's `cfg`: `emit` reports, `now`
// is the virtual time, `active` notes activity (the run is not silent).
export function usbLink(cfg, { emit, now, active }, stream) {
  const chunks = cfg.usb ? [].concat(cfg.usb).sort((a, b) => a.at_ns - b.at_ns) : [];
  // A line stream for the port (stream.mjs): its next line joins the chunks
  // when they run out, unannounced (it is one of thousands).
  const lines = stream?.port === 'usb' ? stream : null;
  const refill = () => {
    if (chunks.length || !lines) return;
    const line = lines.next();
    if (line) chunks.push({ bytes: line.bytes, at_ns: line.at_ns, streamed: true });
  };
  refill();
  const link = {
    send: null, // sends a chunk of the USB script, once the device is configured
    live: null, // sends bytes from stdin (a live run), once the device is configured
    lines: null, // sets the host's control lines (DTR, RTS), once the device is configured
    // The host on `chip`'s USB controller.
    attach(chip) {
      const usb = chip.usbCtrl;
      const view = chip.usbDPRAMView;
      const cdc = new USBCDC(usb);
      const updated = usb.DPRAMUpdated.bind(usb);
      usb.DPRAMUpdated = (offset, value) => {
        updated(offset, value);
        const out = (offset & 4) !== 0;
        const endpoint = (offset - EP0_IN_BUFFER_CONTROL) >> 3;
        if (out && endpoint !== 0 && value & USB_BUF_CTRL_AVAILABLE) {
          if (offset >= EP0_IN_BUFFER_CONTROL && offset <= EP15_OUT_BUFFER_CONTROL) {
            const now = view.getUint32(offset, true);
            if (!(now & USB_BUF_CTRL_FULL)) view.setUint32(offset, now | USB_BUF_CTRL_AVAILABLE, true);
          }
        }
      };
      const finish = usb.finishRead.bind(usb);
      usb.finishRead = (endpoint, buffer) => {
        finish(endpoint, buffer);
        const offset = EP0_IN_BUFFER_CONTROL + endpoint * 8 + 4;
        view.setUint32(offset, view.getUint32(offset, true) & ~USB_BUF_CTRL_AVAILABLE, true);
      };
      const read = usb.onEndpointRead;
      let waiting = null; // an OUT transfer the host has not answered yet
      usb.onEndpointRead = (endpoint, size) => {
        if (endpoint === cdc.outEndpoint && cdc.txFIFO.empty) waiting = { endpoint, size };
        else read(endpoint, size);
      };
      // Its SET_CONTROL_LINE_STATE (DTR and RTS on) goes to the device, where
      // a real host (and the CDC-ACM class) addresses the communication
      // interface (bmRequestType 0x21): the device never sees DTR, which says
      // that a terminal has the port open. Sent as a host sends it.
      cdc.cdcSetControlLineState = function (value = 0x3, interfaceNumber = 0) {
        const setup = new Uint8Array([0x21, 0x22, value & 0xff, value >> 8, interfaceNumber, 0, 0, 0]);
        this.usb.sendSetupPacket(setup);
        this.initialized = true;
      };
      const sendBytes = (bytes) => {
        for (const byte of bytes) cdc.sendSerialByte(byte);
        if (waiting && !cdc.txFIFO.empty) {
          const { endpoint, size } = waiting;
          waiting = null;
          read(endpoint, size);
        }
      };
      cdc.onDeviceConnected = () => {
        emit({ ev: 'usb_connected', ns: now() });
        link.lines = (value) => cdc.cdcSetControlLineState(value);
        if (cfg.live) link.live = sendBytes;
        else
          link.send = (chunk) => {
            const bytes = chunk.bytes ?? Buffer.from(chunk.hex, 'hex');
            sendBytes(bytes);
            if (!chunk.streamed && (chunks.length > 1 || Array.isArray(cfg.usb))) {
              emit({ ev: 'usb_in', ns: now(), n: bytes.length });
            }
          };
      };
      cdc.onSerialData = (bytes) => {
        emit({ ev: 'usb', ns: now(), hex: Buffer.from(bytes).toString('hex') });
        active();
      };
    },
    // When the next chunk is due (once the device is configured).
    due: () => (link.send && chunks.length ? chunks[0].at_ns : Infinity),
    // Sends the chunks due.
    feed() {
      while (link.send && chunks.length && now() >= chunks[0].at_ns) {
        link.send(chunks.shift());
        refill();
      }
      if (!chunks.length) link.send = null;
    },
  };
  return link;
}
