// The trigger inputs GP2 to GP5: each one's role (off, a button and the
// motion line it runs, a presence sensor and the direction it looks), read
// with `input <n>` and changed as it is made; and each one's level as
// `status` reports it (`inputs=b0,p1,-,-`). docs/user/protocol.md.

import { refusal } from './link.js';

const $ = (id) => document.getElementById(id);

/** The inputs' numbers: GP2 to GP5. */
const INPUTS = [2, 3, 4, 5];
/** A button's action when none is given yet. */
const FIRST_ACTION = 'nod';

let page = null; // {ask, refreshStatus}
/** Each input's role as the firmware last answered it. */
const roles = {};

/**
 * `input <n>`'s reply as {role, action, toward, level, active}: `ok input 2 off`,
 * `ok input 2 level=high active=0 button nod 6000 cycles=3`,
 * `ok input 3 level=low active=0 presence -20000` (toward in degrees).
 */
function parseInput(reply) {
  const match = /^ok input \d+ (?:off|level=(\w+) active=([01]) (button|presence)\s*(.*))$/.exec(reply);
  if (!match) return null;
  const [, level, active, role, rest] = match;
  if (!role) return { role: 'off', action: '', toward: null, level: null, active: false };
  return {
    role,
    action: role === 'button' ? rest : '',
    toward: role === 'presence' && rest !== '' ? Number(rest) / 1000 : null,
    level,
    active: active === '1',
  };
}

function makeRows() {
  const box = $('inputs');
  for (const n of INPUTS) {
    const row = document.createElement('div');
    row.className = 'input-row';
    row.innerHTML = `
      <label for="in-role-${n}">GP${n}</label>
      <select id="in-role-${n}" aria-label="GP${n} role">
        <option value="off">off</option>
        <option value="button">button</option>
        <option value="presence">presence</option>
      </select>
      <span class="in-what">
        <input id="in-action-${n}" type="text" spellcheck="false" placeholder="${FIRST_ACTION}" aria-label="GP${n} button: the command a press runs" hidden>
        <span id="in-toward-${n}-box" hidden><input id="in-toward-${n}" type="number" min="-90" max="90" step="1" placeholder="none" aria-label="GP${n} presence: the direction it looks, yaw in degrees"> °</span>
      </span>
      <output id="in-level-${n}" aria-label="GP${n} level">–</output>
      <span class="why" id="why-in-${n}" aria-live="polite"></span>`;
    box.append(row);
    const send = () => setInput(n).catch(() => {});
    $(`in-role-${n}`).addEventListener('change', send);
    $(`in-action-${n}`).addEventListener('change', send);
    $(`in-toward-${n}`).addEventListener('change', send);
  }
}

/** Shows input `n` as the firmware last answered it. */
function showRow(n) {
  const role = roles[n];
  if (!role) return;
  $(`in-role-${n}`).value = role.role;
  $(`in-action-${n}`).hidden = role.role !== 'button';
  $(`in-action-${n}`).value = role.action;
  $(`in-toward-${n}-box`).hidden = role.role !== 'presence';
  $(`in-toward-${n}`).value = role.toward === null ? '' : String(role.toward);
}

/** Asks the firmware for input `n`'s role. */
async function readInput(n) {
  const role = parseInput(await page.ask(`input ${n}`));
  if (role) roles[n] = role;
  showRow(n);
  return role;
}

/** The line that gives input `n` the role its controls show. */
function lineFor(n) {
  const role = $(`in-role-${n}`).value;
  if (role === 'off') return `input ${n} off`;
  if (role === 'button') {
    const action = $(`in-action-${n}`).value.trim() || roles[n]?.action || FIRST_ACTION;
    return `input ${n} button ${action}`;
  }
  const toward = $(`in-toward-${n}`).value;
  return toward === '' ? `input ${n} presence` : `input ${n} presence ${Math.round(Number(toward) * 1000)}`;
}

/** Sends input `n`'s new role, then reads it back: a refused one snaps back with the reason. */
async function setInput(n) {
  const why = $(`why-in-${n}`);
  why.textContent = '';
  const reply = await page.ask(lineFor(n));
  why.classList.toggle('warn', reply.startsWith('ok'));
  if (reply.startsWith('ok clamped')) {
    // The direction is kept; the glance stops at the yaw limit.
    const yaw = Number(/yaw=(-?\d+)/.exec(reply)?.[1]) / 1000;
    why.textContent = `the head glances only as far as its yaw limit, ${yaw}°`;
  } else if (!reply.startsWith('ok')) {
    why.textContent = refusal(reply);
  }
  await readInput(n);
  await page.refreshStatus();
}

/** Reads every input's role (on connect, after Load or Defaults). */
export async function read() {
  for (const n of INPUTS) await readInput(n);
}

/** The levels of `status`'s `inputs=` (`b0,p1,-,-`: role letter, then 1 while active). */
export function showStatus(f) {
  const levels = (f.inputs ?? '').split(',');
  INPUTS.forEach((n, i) => {
    const level = levels[i] ?? '';
    const text = { b0: 'released', b1: 'pressed', p0: 'no one', p1: 'someone there', '-': 'off' }[level] ?? '–';
    const out = $(`in-level-${n}`);
    out.textContent = text;
    out.classList.toggle('active', level.endsWith('1'));
  });
}

/** Whether the firmware has trigger inputs (`help` lists `input`). */
export function offered(words) {
  $('inputs-group').hidden = !words.includes('input');
  return words.includes('input');
}

/** The rows and their handlers; `context` gives `ask` and `refreshStatus`. */
export function setUp(context) {
  page = context;
  makeRows();
}
