// Rest and wake: the head's mode as `status` reports it, Rest and Wake by
// hand, and the rest settings (`rest after`, `rest pose`, `rest relax`;
// docs/user/protocol.md), read back from the head: `rest after` alone
// answers all three (`ok rest after=120 pose=8000,0,0 relax=off`, then
// ` clamped=…` where the head rests if the pose lies past the limits).
//
// A firmware that cannot be asked (an older one answers `err`) leaves
// what the page does not know blank (a checkbox half-ticked), each value
// shown once set here.

import { fields, refusal } from './link.js';

const $ = (id) => document.getElementById(id);

const POSE = ['pitch', 'roll', 'yaw'];

let page = null; // {ask, refreshStatus}
/** What the page knows of the rest settings: null where it does not. */
const UNKNOWN = { seconds: null, never: null, pose: null, relax: null };
let known = { ...UNKNOWN };
/** Whether the head answers `rest after` alone. */
let answers = true;
/** The control whose change is being answered (it snaps back if refused). */
let answering = null;

/**
 * Shows `write(control)` in the control `id`, unless it is being typed in
 * (it has the focus and the answer is to another one's change).
 */
function put(id, write) {
  const control = $(id);
  if (control === document.activeElement && id !== answering) return;
  write(control);
}

/** Degrees as the console's whole millidegrees. */
const mdeg = (degrees) => Math.round(degrees * 1000);
const degrees = (text) => text.split(',').map((v) => Number(v) / 1000);

function showAfter() {
  put('rest-after', (c) => {
    c.value = known.seconds === null ? '' : String(known.seconds);
  });
  put('rest-never', (c) => {
    c.checked = known.never === true;
    c.indeterminate = known.never === null;
  });
}

function showPose() {
  POSE.forEach((axis, i) => {
    put(`rest-${axis}`, (c) => {
      c.value = known.pose ? String(known.pose[i]) : '';
    });
  });
}

function showRelax() {
  put('rest-relax', (c) => {
    c.checked = known.relax === true;
    c.indeterminate = known.relax === null;
  });
}

function showAll() {
  showAfter();
  showPose();
  showRelax();
  $('rest-note').hidden = answers || !Object.values(known).includes(null);
}

function say(text, warn = false) {
  $('why-rest').textContent = text;
  $('why-rest').classList.toggle('warn', warn);
}

/** The pose clamped to the limits, as a note (or none). */
function sayClamped(clamped) {
  if (clamped) say(`past the servos' limits: the head rests at pitch ${clamped[0]}°, roll ${clamped[1]}°, yaw ${clamped[2]}°`, true);
}

/**
 * Reads the rest settings from the head (on connect, after a change, Load
 * or Defaults); whether it answered. `quiet` keeps the note under the
 * group (a refusal's reason).
 */
export async function read(quiet = false) {
  const reply = await page.ask('rest after');
  answers = reply.startsWith('ok rest ');
  if (!answers) {
    known = { ...UNKNOWN };
    showAll();
    return false;
  }
  const f = fields(reply);
  const never = f.after === 'never';
  known = {
    seconds: never ? null : Number(f.after),
    never,
    pose: degrees(f.pose ?? '0,0,0'),
    relax: f.relax === 'on',
  };
  showAll();
  if (!quiet) say('');
  sayClamped(f.clamped ? degrees(f.clamped) : null);
  return true;
}

/**
 * Sends one rest setting, then reads them back; a refused one snaps back
 * with the reason. A head that cannot be asked: `taken(reply)` on `ok`,
 * `redraw` on a refusal.
 */
async function set(line, taken, redraw) {
  say('');
  const source = document.activeElement?.id ?? null;
  const reply = await page.ask(line);
  const refused = !reply.startsWith('ok');
  if (refused) say(refusal(reply));
  answering = source;
  try {
    if (answers) {
      await read(refused);
    } else if (refused) {
      redraw();
    } else {
      taken(reply);
      showAll();
    }
  } finally {
    answering = null;
  }
  await page.refreshStatus();
}

/** `rest after <seconds>`: no longer never. */
function setSeconds(seconds) {
  return set(
    `rest after ${seconds}`,
    () => {
      known.seconds = seconds;
      known.never = false;
    },
    showAfter,
  );
}

function setAfter() {
  const value = $('rest-after').value;
  if (value === '') {
    showAfter();
    return Promise.resolve();
  }
  return setSeconds(Math.round(Number(value)));
}

function setNever() {
  if (!$('rest-never').checked) {
    // Back to a time: the one in the field, else the built-in one (120 s).
    const value = $('rest-after').value;
    return setSeconds(value === '' ? 120 : Math.round(Number(value)));
  }
  return set(
    'rest after never',
    () => {
      known.never = true;
    },
    showAfter,
  );
}

/** The pose from its three fields (a blank one as 0°). */
function setPose() {
  const pose = POSE.map((axis) => Number($(`rest-${axis}`).value || 0));
  return set(
    `rest pose ${pose.map(mdeg).join(' ')}`,
    (reply) => {
      known.pose = pose;
      // `ok clamped pitch=… roll=… yaw=…`: the pose past the limits.
      if (reply.startsWith('ok clamped')) {
        const f = fields(reply);
        sayClamped(POSE.map((axis) => Number(f[axis]) / 1000));
      }
    },
    showPose,
  );
}

function setRelax() {
  const on = $('rest-relax').checked;
  return set(
    `rest relax ${on ? 'on' : 'off'}`,
    () => {
      known.relax = on;
    },
    showRelax,
  );
}

/** Rest or Wake by hand: the mode follows at once. */
async function act(word) {
  say('');
  const reply = await page.ask(word);
  if (!reply.startsWith('ok')) say(refusal(reply));
  await page.refreshStatus();
}

/** A `status` reply's fields: the mode. */
export function showStatus(f) {
  $('mode').textContent = f.mode ?? '–';
}

/** Whether the firmware has rest and wake (`help` lists them). */
export function offered(words) {
  const has = words.includes('rest') && words.includes('wake');
  for (const id of ['rest-group', 'rest', 'wake']) $(id).hidden = !has;
  return has;
}

/** The controls' handlers; `context` gives `ask` and `refreshStatus`. */
export function setUp(context) {
  page = context;
  const on = (id, event, handler) => $(id).addEventListener(event, () => handler().catch(() => {}));
  on('rest', 'click', () => act('rest'));
  on('wake', 'click', () => act('wake'));
  on('rest-after', 'change', setAfter);
  on('rest-never', 'change', setNever);
  for (const axis of POSE) on(`rest-${axis}`, 'change', setPose);
  on('rest-relax', 'change', setRelax);
  showAll();
}
