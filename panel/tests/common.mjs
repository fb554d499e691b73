// What the panel's browser sessions share (panel/tests/browser.mjs): the
// configuration, the checks and waits, screenshots, the browser, the fake
// `navigator.serial` the page gets instead of Web Serial.

import { mkdirSync } from 'node:fs';
import { join } from 'node:path';
import { chromium } from 'playwright-core';

export const cfg = JSON.parse(process.argv[2] ?? '{}');
const CHROMIUM = cfg.chromium ?? '/usr/bin/chromium';
const ARGS = [
  '--headless',
  '--no-sandbox',
  '--disable-gpu',
  '--disable-quic',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
];
const started = Date.now();
export const say = (text) => console.log(`[${((Date.now() - started) / 1000).toFixed(1)} s] ${text}`);
export const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

export function check(ok, what) {
  if (!ok) throw new Error(`check failed: ${what}`);
  say(`ok: ${what}`);
}

/**
 * Waits for `probe` to give a value. The limits are for a head that is
 * there; on a loaded machine the emulators fall behind real time, so each
 * limit stretches by SLACK (a head that never answers still fails, only
 * later). The Nod check's 2 s is the requirement itself and does not.
 */
const SLACK = Number(process.env.PANEL_TEST_SLACK ?? 3);

export async function until(probe, ms, what) {
  const end = Date.now() + ms * SLACK;
  for (;;) {
    const value = await probe();
    if (value) return value;
    if (Date.now() > end) throw new Error(`timed out after ${ms * SLACK} ms: ${what}`);
    await sleep(50);
  }
}

export async function readout(page, axis) {
  return Number(await page.locator(`#${axis}`).textContent());
}

export async function shot(page, name) {
  mkdirSync(cfg.shots, { recursive: true });
  const path = join(cfg.shots, `panel-${name}.png`);
  await page.screenshot({ path });
  say(`screenshot ${path}`);
}

/** The panel's log, its last lines, when a check failed: what was sent and answered. */
export async function sayLog(page) {
  const lines = await page?.locator('#log li').allTextContents().catch(() => []);
  if (lines?.length) say(`the panel's log, last lines:\n  ${lines.slice(-12).join('\n  ')}`);
}

export async function browser() {
  return chromium.launch({ executablePath: CHROMIUM, args: ARGS, headless: true });
}

/** Collects the page's errors in `errors`, and says each as it comes (a
 * check that times out after one has its cause in the output). */
export function watchErrors(page, errors) {
  const note = (text) => {
    errors.push(text);
    say(text);
  };
  page.on('pageerror', (error) => note(`page error: ${error.message}`));
  page.on('console', (message) => {
    if (message.type() === 'error') note(`console error: ${message.text()}`);
  });
}

/** The page's fake `navigator.serial`: ports whose bytes go to and come
 * from Node (`__serialWrite`, `__serialData`), which can be unplugged. */
export function fakeSerial() {
  class FakePort extends EventTarget {
    constructor(id) {
      super();
      this.id = id;
      this.readable = null;
      this.writable = null;
    }
    getInfo() {
      return { usbVendorId: 0x16c0, usbProductId: 0x27dd };
    }
    async open() {
      if (window.__fake.unplugged.has(this.id)) throw new Error('the device has been lost');
      this.readable = new ReadableStream({
        start: (controller) => {
          this.controller = controller;
        },
      });
      this.writable = new WritableStream({
        write: (chunk) => window.__serialWrite(this.id, Array.from(chunk)),
      });
    }
    async close() {
      this.readable = this.writable = null;
    }
  }
  const listeners = new EventTarget();
  window.__fake = { ports: [], unplugged: new Set() };
  window.__serialData = (id, bytes) => {
    const port = window.__fake.ports.find((p) => p.id === id);
    try {
      port?.controller?.enqueue(new Uint8Array(bytes));
    } catch {
      // closed
    }
  };
  window.__unplug = (id) => {
    const port = window.__fake.ports.find((p) => p.id === id);
    window.__fake.unplugged.add(id);
    try {
      port.controller.error(new DOMException('The device has been lost.', 'NetworkError'));
    } catch {
      // closed
    }
    const event = new Event('disconnect');
    Object.defineProperty(event, 'target', { value: port });
    listeners.dispatchEvent(event);
  };
  let next = 0;
  Object.defineProperty(navigator, 'serial', {
    value: {
      async requestPort() {
        const port = new FakePort(next++);
        window.__fake.ports.push(port);
        return port;
      },
      async getPorts() {
        return window.__fake.ports.filter((p) => !window.__fake.unplugged.has(p.id));
      },
      addEventListener: (type, fn) => listeners.addEventListener(type, fn),
      removeEventListener: (type, fn) => listeners.removeEventListener(type, fn),
    },
  });
}
