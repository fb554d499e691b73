// The servo rate: the PWM period of all three servos, which the frames
// follow (`servo rate [<hz>]`, 50..333 Hz, the period whole µs).
// docs/user/protocol.md, docs/user/calibration.md.

import { fields, refusal } from './link.js';

const $ = (id) => document.getElementById(id);

let page = null; // {ask, refreshStatus}
let known = null; // {hz, period} as the head last answered

/** Shows the rate; a field being typed in keeps what is typed. */
function show(force = false) {
  if (!known) return;
  if (force || document.activeElement !== $('servo-rate')) $('servo-rate').value = String(known.hz);
  $('servo-period').textContent = known.period ? `period ${known.period} µs` : '';
}

/** `ok servo rate=333 period_us=3003`: what the head runs at. */
function take(reply) {
  const f = fields(reply);
  known = { hz: Number(f.rate), period: Number(f.period_us) };
}

/** Asks for the rate; whether the firmware has one to set (an older one refuses). */
export async function read() {
  const reply = await page.ask('servo rate');
  const offered = reply.startsWith('ok');
  $('rate-group').hidden = !offered;
  if (offered) {
    take(reply);
    show(true);
  }
  return offered;
}

/** `status`'s `rate=`, between two readings (the period stays as read). */
export function showStatus(f) {
  if (!f.rate || !known || Number(f.rate) === known.hz) return;
  known = { hz: Number(f.rate), period: null };
  show();
}

/** Sends a new rate; a refused one snaps back with the reason. */
async function set(value) {
  const why = $('why-rate');
  why.textContent = '';
  const reply = await page.ask(`servo rate ${value}`);
  if (reply.startsWith('ok')) take(reply);
  else why.textContent = refusal(reply);
  show(true);
  await page.refreshStatus();
}

/** The handler; `context` gives `ask` and `refreshStatus`. */
export function setUp(context) {
  page = context;
  $('servo-rate').addEventListener('change', () => {
    const value = $('servo-rate').value;
    if (value === '') {
      show(true);
      return;
    }
    set(Math.round(Number(value))).catch(() => {});
  });
}
