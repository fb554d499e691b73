// Show control: whether DMX drives the head, its start address, and the
// receiver's signal and frame counters (`dmx`), read on connect and with
// each `status`. docs/user/protocol.md, docs/user/show.md.

import { fields, refusal } from './link.js';

const $ = (id) => document.getElementById(id);

let page = null; // {ask, refreshStatus}
let known = null; // the last `dmx` reply's fields

/**
 * Shows a `dmx` reply: `ok dmx=lost address=17 good=0 short=0 long=0
 * start_code=0 garbled=0`; the settings too unless only the counters are
 * refreshed (a field being typed in stays as it is).
 */
function show(f, settings = true) {
  known = f;
  if (settings) {
    $('dmx-on').checked = f.dmx !== 'off';
    $('dmx-address').value = f.address ?? '';
  }
  showSignal(f.dmx);
  const count = (key) => f[key] ?? '–';
  $('dmx-counters').textContent =
    `frames: ${count('good')} used, ${count('short')} short, ${count('long')} long, ` +
    `${count('start_code')} other start code, ${count('garbled')} garbled`;
}

function showSignal(signal) {
  $('dmx-signal').textContent = { ok: 'ok (receiving)', lost: 'lost (no signal)', off: 'off' }[signal] ?? '–';
  $('dmx-signal').className = `pill ${signal === 'ok' ? 'on' : signal === 'lost' ? 'fault' : 'off'}`;
}

/** Asks for the receiver's state and counters; whether the firmware has them. */
export async function read(settings = true) {
  const reply = await page.ask('dmx');
  if (!reply.startsWith('ok')) return false;
  show(fields(reply), settings);
  return true;
}

/** The signal and the counters, refreshed with `status`. */
export function refresh() {
  return read(false);
}

/** Sends a DMX setting; a refused one snaps back with the reason. */
async function set(line) {
  const why = $('why-dmx');
  why.textContent = '';
  const reply = await page.ask(line);
  if (!reply.startsWith('ok')) why.textContent = refusal(reply);
  // Snaps back (refused) or shows the new state (taken).
  if (!(await read()) && known) show(known);
  await page.refreshStatus();
}

/** `status`'s `dmx=`: the signal, between two `dmx` readings. */
export function showStatus(f) {
  if (f.dmx) showSignal(f.dmx);
}

/** Whether the firmware has a DMX receiver (`help` lists `dmx`). */
export function offered(words) {
  $('dmx-group').hidden = !words.includes('dmx');
  return words.includes('dmx');
}

/** The handlers; `context` gives `ask` and `refreshStatus`. */
export function setUp(context) {
  page = context;
  $('dmx-on').addEventListener('change', () => set(`dmx ${$('dmx-on').checked ? 'on' : 'off'}`).catch(() => {}));
  $('dmx-address').addEventListener('change', () => {
    const value = $('dmx-address').value;
    if (value === '') {
      if (known) show(known);
      return;
    }
    set(`dmx address ${Math.round(Number(value))}`).catch(() => {});
  });
}
