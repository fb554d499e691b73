// Rest and wake: the head's mode as `status` reports it, Rest and Wake by
// hand, and the rest settings (`rest after`, `rest pose`, `rest relax`;
// docs/user/protocol.md).
//
// The firmware answers no query for the rest settings, so the page shows
// what it knows: the built-in values while `status` says the head runs on
// them (`settings=defaults`), and each value set here since; a value it
// does not know is blank (a checkbox half-ticked).

import { fields, refusal } from './link.js';

const $ = (id) => document.getElementById(id);

/** The built-in rest settings (`rest after 120`, `rest pose 8000 0 0`, `rest relax off`). */
const BUILT_IN = { seconds: 120, never: false, pose: [8, 0, 0], relax: false };
const POSE = ['pitch', 'roll', 'yaw'];

let page = null; // {ask, refreshStatus}
/** What the page knows of the rest settings: null where it does not. */
const UNKNOWN = { seconds: null, never: null, pose: null, relax: null };
let known = { ...UNKNOWN };

/** Degrees as the console's whole millidegrees. */
const mdeg = (degrees) => Math.round(degrees * 1000);

// Each part is drawn from `known` when it is learnt or a change is
// refused (it snaps back); a change taken is already on show, and a field
// is never redrawn under the user's fingers by an answer to another one.
function showAfter() {
  $('rest-after').value = known.seconds === null ? '' : String(known.seconds);
  $('rest-never').checked = known.never === true;
  $('rest-never').indeterminate = known.never === null;
}

function showPose() {
  POSE.forEach((axis, i) => {
    $(`rest-${axis}`).value = known.pose ? String(known.pose[i]) : '';
  });
}

function showRelax() {
  $('rest-relax').checked = known.relax === true;
  $('rest-relax').indeterminate = known.relax === null;
}

function showAll() {
  showAfter();
  showPose();
  showRelax();
  $('rest-note').hidden = !Object.values(known).includes(null);
}

function say(text, warn = false) {
  $('why-rest').textContent = text;
  $('why-rest').classList.toggle('warn', warn);
}

/** Sends one rest setting: `taken(reply)` on `ok`; a refused one snaps back (`redraw`) with the reason. */
async function set(line, taken, redraw) {
  say('');
  const reply = await page.ask(line);
  if (reply.startsWith('ok')) {
    taken(reply);
  } else {
    say(refusal(reply));
    redraw();
  }
  $('rest-note').hidden = !Object.values(known).includes(null);
  await page.refreshStatus();
}

/** `rest after <seconds>`: no longer never. */
function setSeconds(seconds) {
  return set(
    `rest after ${seconds}`,
    () => {
      known.seconds = seconds;
      known.never = false;
      if ($('rest-after').value === '') $('rest-after').value = String(seconds);
      $('rest-never').checked = false;
      $('rest-never').indeterminate = false;
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
    // Back to a time: the one in the field, else the built-in one.
    const value = $('rest-after').value;
    return setSeconds(value === '' ? BUILT_IN.seconds : Math.round(Number(value)));
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
      // `ok clamped pitch=… roll=… yaw=…`: the pose past the limits, clamped to them.
      if (reply.startsWith('ok clamped')) {
        const f = fields(reply);
        known.pose = POSE.map((axis) => Number(f[axis]) / 1000);
        showPose();
        say(`clamped to the servos' limits: pitch ${known.pose[0]}°, roll ${known.pose[1]}°, yaw ${known.pose[2]}°`, true);
      } else if (pose.some((v, i) => $(`rest-${POSE[i]}`).value === '')) {
        showPose(); // the blanks, sent as 0°
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

/** Connected (or after Load): nothing known until `status` says more. */
export function forget() {
  known = { ...UNKNOWN };
  say('');
  showAll();
}

/** A `status` reply's fields: the mode, and the built-in settings if it runs on them. */
export function showStatus(f) {
  $('mode').textContent = f.mode ?? '–';
  if (f.settings === 'defaults' && JSON.stringify(known) !== JSON.stringify(BUILT_IN)) {
    known = { ...BUILT_IN, pose: [...BUILT_IN.pose] };
    showAll();
  }
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
