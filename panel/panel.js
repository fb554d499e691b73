// The panel: connects to a head (the bridge of `cargo xtask panel` when
// the page is served with one, else Web Serial), shows what the head is
// told (drawing, readouts, plot, status), and offers its actions,
// calibration and settings (servo rate, rest, idle, inputs, DMX and the
// radar in modules of their own), every one read back from the head.
// Every line sent and received goes to the log.

import { BridgeTransport, Console, NoReply, SerialTransport, commandWords, fields, gestureWords, refusal } from './link.js';
import { makePlot, showTelemetry } from './view.js';
import * as rest from './rest.js';
import * as inputs from './inputs.js';
import * as dmx from './dmx.js';
import * as rate from './rate.js';
import * as idle from './idle.js';
import * as radar from './radar.js';

const $ = (id) => document.getElementById(id);
const AXES = ['pitch', 'roll', 'yaw'];
/** Telemetry lines a second while connected. */
const WATCH_HZ = 20;

let link = null; // {transport, console}
let bridge = null; // what bridge.json says, when served with one
let servos = {}; // axis -> calibration as `servo <axis>` says
let statusTimer = null;
let pollTimer = null; // status polled for the readouts (no telemetry)
let limitRun = null; // a "go to limit" in progress
let hasInputs = false; // the firmware has trigger inputs
let hasDmx = false; // the firmware answers `dmx`
let hasRest = false; // the firmware has rest settings
let hasRadar = false; // the firmware has a radar

// ---- log ----------------------------------------------------------------

function log(kind, text) {
  if (kind === 'telemetry' && !$('log-telemetry').checked) return;
  const item = document.createElement('li');
  item.className = kind + (kind === 'in' && text.startsWith('err') ? ' err' : '');
  item.textContent = text;
  const list = $('log');
  list.append(item);
  while (list.childElementCount > 400) list.firstElementChild.remove();
  list.scrollTop = list.scrollHeight;
}

// ---- connection ---------------------------------------------------------

function setState(text, kind) {
  const state = $('state');
  state.textContent = text;
  state.className = `pill ${kind}`;
}

function banner(text, { reconnect = false, info = false } = {}) {
  $('banner').hidden = !text;
  $('banner').className = info ? 'info' : '';
  $('banner-text').textContent = text ?? '';
  $('reconnect').hidden = !reconnect;
}

function setControls(enabled) {
  for (const el of document.querySelectorAll('#actions :is(button, input), #calibration :is(button, input), #setup :is(input, select)')) {
    // Stop is for a "go to limit" in progress only.
    el.disabled = !enabled || (el.id === 'limit-stop' && !limitRun);
  }
  $('lookpad').setAttribute('aria-disabled', String(!enabled));
}

async function connect(makeTransport) {
  banner(null);
  setState('connecting…', 'off');
  let transport;
  try {
    transport = await makeTransport();
    await transport.open();
  } catch (error) {
    setState('not connected', 'off');
    banner(`Could not connect: ${error.message ?? error}`, { reconnect: true });
    return;
  }
  const console = new Console(transport, {
    onTelemetry: telemetry,
    onLine: (direction, text) => log(direction, text),
  });
  link = { transport, console };
  transport.onClose = (why) => lost(why);
  $('transport').textContent = transport.name;
  $('connect').hidden = true;
  $('disconnect').hidden = false;
  try {
    await start();
  } catch (error) {
    fault(error);
  }
}

/** A telemetry line: the drawing, readouts and plot, and the radar's map. */
function telemetry(t) {
  showTelemetry(t);
  if (hasRadar) radar.showTelemetry(t);
}

/** Every setting, as the head answers it: on connect, after Load and Defaults. */
async function readSettings() {
  for (const axis of AXES) await readServo(axis);
  showServo();
  await rate.read();
  if (hasRest) await rest.read();
  await idle.read();
  if (hasInputs) await inputs.read();
  if (hasDmx) hasDmx = await dmx.read();
  if (hasRadar) await radar.read();
}

/** What the page asks first: the commands, the status, every setting, telemetry. */
async function start() {
  const help = await ask('help');
  makeGestureButtons(gestureWords(help));
  const words = commandWords(help);
  hasRest = rest.offered(words);
  hasInputs = inputs.offered(words);
  hasDmx = dmx.offered(words);
  hasRadar = radar.offered(words);
  await refreshStatus();
  await readSettings();
  const watch = await ask(`watch ${WATCH_HZ}`);
  if (watch.startsWith('err')) {
    banner(
      `This firmware answers \`watch\` with \`${watch}\`: it streams no telemetry (an older firmware). ` +
        'The readouts follow `status`, asked twice a second; update the firmware for the live plot at full rate.',
      { info: true },
    );
    pollTimer = setInterval(() => refreshStatus(true).catch(fault), 500);
  }
  setState('connected', 'on');
  setControls(true);
  statusTimer = setInterval(() => {
    if (!limitRun) {
      refreshStatus()
        .then(() => hasDmx && dmx.refresh())
        .then(() => hasRadar && radar.refresh())
        .then(() => idle.readIdle())
        .catch(fault);
    }
  }, 2000);
}

function stopTimers() {
  clearInterval(statusTimer);
  clearInterval(pollTimer);
  statusTimer = pollTimer = null;
  if (limitRun) limitRun.stop = true;
}

/** The transport closed: say so, offer to reconnect. */
function lost(why) {
  if (!link) return;
  link.console.abandon(why);
  link = null;
  stopTimers();
  setControls(false);
  setState('disconnected', 'fault');
  $('connect').hidden = true;
  $('disconnect').hidden = true;
  banner(`Disconnected: ${why}.`, { reconnect: true });
  log('note', `disconnected: ${why}`);
}

/** A reply that never came, or a failed write: the link is not to be trusted. */
function fault(error) {
  if (!link) return;
  const why = error instanceof NoReply ? `${error.message} (is the head still there?)` : error.message ?? String(error);
  const transport = link.transport;
  lost(why);
  transport.close();
}

async function disconnect() {
  if (!link) return;
  const transport = link.transport;
  try {
    await link.console.send('watch off');
  } catch {
    // Going anyway.
  }
  link = null;
  stopTimers();
  await transport.close();
  setControls(false);
  setState('not connected', 'off');
  $('connect').hidden = false;
  $('disconnect').hidden = true;
  banner(null);
}

function reconnect() {
  if (bridge) connect(bridgeTransport);
  else connect(serialTransport);
}

function bridgeTransport() {
  return new BridgeTransport(`bridged to ${bridge.name}`);
}

let chosenPort = null;
async function serialTransport() {
  if (!SerialTransport.available()) {
    throw new Error('this browser has no Web Serial: use Chromium, Edge or Opera, or `cargo xtask panel --port <dev>`');
  }
  if (chosenPort) {
    const ports = await navigator.serial.getPorts();
    if (ports.includes(chosenPort)) return new SerialTransport(chosenPort);
  }
  const transport = await SerialTransport.choose();
  chosenPort = transport.port;
  return transport;
}

/** Sends `line`; its reply. A missing reply or a closed link is a fault. */
async function ask(line) {
  if (!link) throw new Error('not connected');
  try {
    return await link.console.send(line);
  } catch (error) {
    fault(error);
    throw error;
  }
}

// ---- what the head is told ----------------------------------------------

async function refreshStatus(pose = false) {
  const reply = await ask('status');
  if (!reply.startsWith('ok')) return;
  const f = fields(reply);
  $('status-line').textContent = reply.replace(/^ok /, 'status: ');
  $('firmware').textContent = f.fw ? `firmware ${f.fw}` : '';
  $('unsaved').hidden = f.settings !== 'changed';
  rest.showStatus(f);
  inputs.showStatus(f);
  dmx.showStatus(f);
  rate.showStatus(f);
  if (f.mode && f.mode !== 'running') setState(`connected · ${f.mode}`, 'on');
  else if (link) setState('connected', 'on');
  if (pose && f.mdeg) {
    const [p, r, y] = f.mdeg.split(',').map((v) => Number(v) / 1000);
    showTelemetry({ t: Number(f.uptime_ms ?? 0), pitch: p, roll: r, yaw: y, us: (f.us ?? '').split(','), lost: 0 });
  }
}

// ---- actions ------------------------------------------------------------

function makeGestureButtons(words) {
  const box = $('gestures');
  box.replaceChildren();
  for (const word of words) {
    const button = document.createElement('button');
    button.type = 'button';
    button.textContent = word[0].toUpperCase() + word.slice(1);
    button.dataset.gesture = word;
    button.addEventListener('click', () => gesture(word));
    box.append(button);
  }
}

async function gesture(word) {
  const amp = $('gesture-amp').value;
  const ms = $('gesture-ms').value;
  let line = word;
  if (amp !== '') {
    line += ` ${Math.round(Number(amp) * 1000)}`;
    if (ms !== '') line += ` ${Math.round(Number(ms))}`;
  } else if (ms !== '') {
    log('note', 'a duration needs an amplitude too: the default duration was used');
  }
  await ask(line);
}

// The look pad, the head as the audience faces it: x is yaw (±45°, right
// is positive: the head turns to its own left), y is pitch (±30°, down is
// positive: nose down).
const PAD = { yaw: 45, pitch: 30 };
let lookAt = { pitch: 0, yaw: 0 };
let lookBusy = false;
let lookNext = null;

function showLookTarget() {
  const target = $('look-target');
  target.setAttribute('cx', String((lookAt.yaw / PAD.yaw) * 50));
  target.setAttribute('cy', String((lookAt.pitch / PAD.pitch) * 35));
  $('lookpad').setAttribute('aria-valuetext', `yaw ${lookAt.yaw}°, pitch ${lookAt.pitch}°`);
}

async function look(at) {
  lookAt = at;
  showLookTarget();
  if (lookBusy) {
    lookNext = at;
    return;
  }
  lookBusy = true;
  try {
    let next = at;
    while (next) {
      lookNext = null;
      await ask(`look ${next.pitch * 1000} ${next.yaw * 1000} 300 hold=stay`);
      next = lookNext;
    }
  } finally {
    lookBusy = false;
  }
}

function padPoint(event) {
  const pad = $('lookpad');
  const box = pad.getBoundingClientRect();
  const x = ((event.clientX - box.left) / box.width) * 2 - 1;
  const y = ((event.clientY - box.top) / box.height) * 2 - 1;
  const clamp = (v) => Math.max(-1, Math.min(1, v));
  return { yaw: Math.round(clamp(x) * PAD.yaw), pitch: Math.round(clamp(y) * PAD.pitch) };
}

function setUpLookPad() {
  const pad = $('lookpad');
  let dragging = false;
  pad.addEventListener('pointerdown', (event) => {
    if (!link) return;
    dragging = true;
    pad.setPointerCapture(event.pointerId);
    look(padPoint(event)).catch(() => {});
  });
  pad.addEventListener('pointermove', (event) => {
    if (dragging && link) look(padPoint(event)).catch(() => {});
  });
  pad.addEventListener('pointerup', () => {
    dragging = false;
  });
  pad.addEventListener('keydown', (event) => {
    if (!link) return;
    const step = event.shiftKey ? 10 : 2;
    const moves = { ArrowLeft: [0, -step], ArrowRight: [0, step], ArrowUp: [-step, 0], ArrowDown: [step, 0] };
    if (moves[event.key]) {
      const [dp, dy] = moves[event.key];
      lookAt = {
        pitch: Math.max(-PAD.pitch, Math.min(PAD.pitch, lookAt.pitch + dp)),
        yaw: Math.max(-PAD.yaw, Math.min(PAD.yaw, lookAt.yaw + dy)),
      };
      showLookTarget();
      event.preventDefault();
    } else if (event.key === 'Enter' || event.key === ' ') {
      look(lookAt).catch(() => {});
      event.preventDefault();
    }
  });
}

// ---- calibration --------------------------------------------------------

/** The calibration fields: their slider range and unit, as the page shows them. */
const FIELDS = [
  { key: 'neutral', label: 'neutral', min: 500, max: 2500, step: 1, unit: 'µs' },
  { key: 'per-degree', label: 'per degree', min: 2000, max: 30000, step: 1, unit: 'ns/°' },
  { key: 'min', label: 'min pulse', min: 500, max: 2500, step: 1, unit: 'µs' },
  { key: 'max', label: 'max pulse', min: 500, max: 2500, step: 1, unit: 'µs' },
  { key: 'limit-min', label: 'lower limit', min: -90, max: 0, step: 1, unit: '°' },
  { key: 'limit-max', label: 'upper limit', min: 0, max: 90, step: 1, unit: '°' },
];

function axisNow() {
  return document.querySelector('input[name=axis]:checked').value;
}

async function readServo(axis) {
  const reply = await ask(`servo ${axis}`);
  if (!reply.startsWith('ok')) return;
  const f = fields(reply);
  const [lo, hi] = (f.limits ?? '0,0').split(',').map(Number);
  servos[axis] = {
    neutral: Number(f.neutral),
    'per-degree': Number(f['per-degree']),
    direction: f.direction,
    min: Number(f.min),
    max: Number(f.max),
    'limit-min': lo / 1000,
    'limit-max': hi / 1000,
  };
}

function makeServoFields() {
  const box = $('servo-fields');
  for (const field of FIELDS) {
    const row = document.createElement('div');
    row.className = 'field';
    row.innerHTML = `
      <label for="f-${field.key}">${field.label}</label>
      <input id="r-${field.key}" type="range" min="${field.min}" max="${field.max}" step="${field.step}" aria-label="${field.label} slider (${field.unit})">
      <span><input id="f-${field.key}" type="number" min="${field.min}" max="${field.max}" step="${field.step}" aria-label="${field.label} (${field.unit})"> ${field.unit}</span>
      <span class="why" id="why-${field.key}" aria-live="polite"></span>`;
    box.append(row);
    const range = row.querySelector('input[type=range]');
    const number = row.querySelector('input[type=number]');
    range.addEventListener('input', () => {
      number.value = range.value;
    });
    range.addEventListener('change', () => setField(field, Number(range.value)));
    number.addEventListener('change', () => setField(field, Number(number.value)));
  }
  const row = document.createElement('div');
  row.className = 'field direction';
  row.innerHTML = `
    <span>direction</span>
    <span role="radiogroup" aria-label="direction">
      <label><input type="radio" name="direction" value="normal"> normal</label>
      <label><input type="radio" name="direction" value="reversed"> reversed</label>
    </span>
    <span class="why" id="why-direction" aria-live="polite"></span>`;
  box.append(row);
  for (const radio of row.querySelectorAll('input')) {
    radio.addEventListener('change', () => setDirection(radio.value));
  }
}

/**
 * Shows the selected servo's calibration. A control the user is in keeps
 * what is being typed (an answer to another field, arriving late, must not
 * undo it), except the field whose answer this is (`answered`): a refused
 * value snaps back there.
 */
function showServo(answered = null) {
  const servo = servos[axisNow()];
  if (!servo) return;
  for (const field of FIELDS) {
    for (const id of [`r-${field.key}`, `f-${field.key}`]) {
      const control = $(id);
      if (control === document.activeElement && field.key !== answered) continue;
      control.value = String(servo[field.key]);
    }
  }
  for (const radio of document.querySelectorAll('input[name=direction]')) {
    radio.checked = radio.value === servo.direction;
  }
}

/** Changes not yet answered, per field: only the newest answer redraws. */
const changing = {};

/** Sends one field's change; a refused value snaps back with the reason. */
async function setField(field, value) {
  const axis = axisNow();
  const servo = servos[axis];
  const why = $(`why-${field.key}`);
  why.textContent = '';
  const mine = (changing[field.key] = (changing[field.key] ?? 0) + 1);
  let line;
  if (field.key === 'limit-min' || field.key === 'limit-max') {
    const lo = field.key === 'limit-min' ? value : servo['limit-min'];
    const hi = field.key === 'limit-max' ? value : servo['limit-max'];
    line = `servo ${axis} limits ${Math.round(lo * 1000)} ${Math.round(hi * 1000)}`;
  } else {
    line = `servo ${axis} ${field.key} ${Math.round(value)}`;
  }
  const reply = await ask(line);
  why.classList.toggle('warn', reply.startsWith('ok'));
  if (reply.startsWith('ok')) {
    servo[field.key] = value;
    if (reply.startsWith('ok warning')) why.textContent = reply.replace(/^ok warning: /, 'warning: ');
  } else {
    why.textContent = refusal(reply);
  }
  // A slider still moving has newer changes on the way: let them land.
  if (changing[field.key] !== mine) return;
  changing[field.key] = 0;
  showServo(field.key);
  await refreshStatus();
}

async function setDirection(direction) {
  const axis = axisNow();
  const why = $('why-direction');
  why.textContent = '';
  const reply = await ask(`servo ${axis} direction ${direction}`);
  if (reply.startsWith('ok')) servos[axis].direction = direction;
  else why.textContent = refusal(reply);
  showServo();
  await refreshStatus();
}

/**
 * "Go to limit": the idle off, then the head stepped slowly to the
 * servo's limit, 1° every 100 ms, by looks held there (pitch, yaw); roll
 * has no look, so it leans there with a slow tilt held 6 s.
 */
async function goToLimit(which) {
  const axis = axisNow();
  const servo = servos[axis];
  const limit = which === 'low' ? servo['limit-min'] : servo['limit-max'];
  $('limit-stop').disabled = false;
  limitRun = { stop: false };
  const run = limitRun;
  try {
    await ask('idle off');
    $('idle-on').checked = false;
    $('limit-note').textContent = `idle off; ${axis} to ${limit}°…`;
    if (axis === 'roll') {
      await ask(`tilt ${Math.round(limit * 1000)} 6000 intensity=0`);
      return;
    }
    let at = axis === 'pitch' ? lookAt.pitch : lookAt.yaw;
    const step = limit > at ? 1 : -1;
    while (!run.stop && at !== limit) {
      at = Math.abs(limit - at) < 1 ? limit : at + step;
      lookAt = axis === 'pitch' ? { ...lookAt, pitch: at } : { ...lookAt, yaw: at };
      showLookTarget();
      await ask(`look ${Math.round(lookAt.pitch * 1000)} ${Math.round(lookAt.yaw * 1000)} 100 hold=stay`);
      await new Promise((resolve) => setTimeout(resolve, 100));
    }
    $('limit-note').textContent = run.stop ? `stopped at ${at}°` : `at the ${which === 'low' ? 'lower' : 'upper'} limit, ${limit}°: Center brings it back`;
  } finally {
    $('limit-stop').disabled = true;
    limitRun = null;
  }
}

// ---- set-up -------------------------------------------------------------

function on(id, event, handler) {
  $(id).addEventListener(event, () => handler().catch(() => {}));
}

async function main() {
  makeServoFields();
  const page = { ask, refreshStatus };
  rest.setUp(page);
  inputs.setUp(page);
  dmx.setUp(page);
  rate.setUp(page);
  idle.setUp(page);
  radar.setUp(page);
  makePlot();
  setUpLookPad();
  setControls(false);
  $('connect').addEventListener('click', () => connect(serialTransport));
  $('disconnect').addEventListener('click', () => disconnect());
  $('reconnect').addEventListener('click', reconnect);
  on('center', 'click', async () => {
    lookAt = { pitch: 0, yaw: 0 };
    showLookTarget();
    await ask('center');
  });
  on('save', 'click', async () => {
    await ask('save');
    await refreshStatus();
  });
  for (const id of ['load', 'defaults']) {
    on(id, 'click', async () => {
      await ask(id);
      await refreshStatus();
      await readSettings();
    });
  }
  for (const radio of document.querySelectorAll('input[name=axis]')) radio.addEventListener('change', () => showServo());
  on('limit-low', 'click', () => goToLimit('low'));
  on('limit-high', 'click', () => goToLimit('high'));
  $('limit-stop').addEventListener('click', () => {
    if (limitRun) limitRun.stop = true;
  });
  $('log-telemetry').addEventListener('change', () => {});

  // Served with a bridge: connect to it at once. Else Web Serial.
  try {
    const response = await fetch('bridge.json', { cache: 'no-store' });
    const served = response.ok ? await response.json() : null;
    bridge = served?.bridge ? served : null;
  } catch {
    bridge = null;
  }
  if (bridge) {
    $('connect').hidden = true;
    await connect(bridgeTransport);
  } else if (!SerialTransport.available()) {
    banner('This browser has no Web Serial. Open the page in Chromium, Edge or Opera, or serve it bridged to the head: `cargo xtask panel --port <dev>`.', { info: true });
  }
}

main();
