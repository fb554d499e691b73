// The idle motion, the look's duck and the seeds, read back from the head:
// `idle` (`ok idle=on amp=100`: on or off, and the amplitude), `look duck`
// (`ok look duck=80`) and `seed` (`ok seed=board:1234`). A change is sent
// as it is made and read back; a refused one snaps back with its reason.
// docs/user/protocol.md.

import { fields, refusal } from './link.js';

const $ = (id) => document.getElementById(id);

let page = null; // {ask, refreshStatus}

/** `idle`: the checkbox and the slider as the head plays the idle. */
export async function readIdle() {
  const reply = await page.ask('idle');
  if (!reply.startsWith('ok idle=')) return false;
  const f = fields(reply);
  $('idle-on').checked = f.idle === 'on';
  if (document.activeElement !== $('idle-amp')) {
    $('idle-amp').value = f.amp;
    $('idle-amp-value').textContent = f.amp;
  }
  return true;
}

/** `look duck`: the duck field (hidden if the firmware cannot say). */
export async function readDuck() {
  const reply = await page.ask('look duck');
  const has = reply.startsWith('ok look duck=');
  $('duck-box').hidden = !has;
  if (has) $('look-duck').value = fields(reply).duck;
  return has;
}

/** `seed`: the seed in use (`board:<n>`, `paper` or `<n>`). */
export async function readSeed() {
  const reply = await page.ask('seed');
  if (!reply.startsWith('ok seed=')) return false;
  const seed = fields(reply).seed;
  $('seed-now').textContent = seed;
  if (/^\d+$/.test(seed)) $('seed').value = seed;
  return true;
}

/** Reads all three (on connect, after Load or Defaults). */
export async function read() {
  await readIdle();
  await readDuck();
  await readSeed();
}

/** Sends `line`; a refusal's reason goes to `why`; then `readBack`. */
async function set(line, why, readBack) {
  $(why).textContent = '';
  const reply = await page.ask(line);
  if (!reply.startsWith('ok')) $(why).textContent = refusal(reply);
  await readBack();
  await page.refreshStatus();
  return reply;
}

/** The handlers; `context` gives `ask` and `refreshStatus`. */
export function setUp(context) {
  page = context;
  const on = (id, event, handler) => $(id).addEventListener(event, () => handler().catch(() => {}));
  on('idle-on', 'change', () => set($('idle-on').checked ? 'idle on' : 'idle off', 'why-idle', readIdle));
  $('idle-amp').addEventListener('input', () => {
    $('idle-amp-value').textContent = $('idle-amp').value;
  });
  on('idle-amp', 'change', () => set(`idle amp ${$('idle-amp').value}`, 'why-idle', readIdle));
  on('look-duck', 'change', async () => {
    const value = $('look-duck').value;
    if (value === '') return readDuck();
    return set(`look duck ${Math.round(Number(value))}`, 'why-duck', readDuck);
  });
  on('seed-set', 'click', () => set(`seed ${Math.round(Number($('seed').value))}`, 'why-seed', readSeed));
  on('seed-random', 'click', () => set('seed random', 'why-seed', readSeed));
}
