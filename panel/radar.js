// The radar: a map of the room from above, as the head's telemetry tells
// it (the people the radar sees, whom the head attends to, where it looks
// and where it aims), and the radar's and the tracking's settings (`radar
// on|off`, `track on|off|height|mount|prefer`), read back from the head.
// docs/user/radar.md, docs/user/protocol.md.
//
// The map is in the head's frame, in mm: the head at the origin looking
// up the page, its left to the left. A person the radar sees at (x, y)
// (x across, to the radar's right as seen from behind it; y away from it)
// is at the bearing `mount − atan2(x, y)` (a yaw: positive to the head's
// left), as the head turns for them.

import { fields, refusal } from './link.js';

const $ = (id) => document.getElementById(id);
const SVG = 'http://www.w3.org/2000/svg';
/** How far the map reaches, mm (the LD2450 sees about 6 m). */
const REACH = 6000;
/** The radar's field of view, ± degrees around its axis. */
const FIELD = 60;

let page = null; // {ask, refreshStatus}
let known = null; // {radar, track, height, mount, prefer} as the head answered
let lastTelemetry = null; // the last telemetry line, as parsed
let mountDeg = 0;

const rad = (degrees) => (degrees * Math.PI) / 180;

/**
 * Where a person the radar sees at (x, y) mm is on the map (the head's
 * frame: X to the head's right, Y down the page, mm), with the radar
 * mounted at `mount` degrees of yaw; and their bearing and distance.
 */
function place(x, y, mount) {
  const bearing = mount - (Math.atan2(x, y) * 180) / Math.PI;
  const distance = Math.hypot(x, y);
  return { X: -distance * Math.sin(rad(bearing)), Y: -distance * Math.cos(rad(bearing)), bearing, distance };
}

/** The end of a ray from the head at `yaw` degrees, `length` mm long. */
function ray(yaw, length) {
  return { X: -length * Math.sin(rad(yaw)), Y: -length * Math.cos(rad(yaw)) };
}

function element(name, attributes) {
  const el = document.createElementNS(SVG, name);
  for (const [key, value] of Object.entries(attributes)) el.setAttribute(key, String(value));
  return el;
}

/** The map's fixed parts: the range rings and their labels. */
function makeMap() {
  const rings = $('map-rings');
  for (let m = 1; m <= REACH / 1000; m++) {
    rings.append(element('circle', { cx: 0, cy: 0, r: m * 1000, class: 'ring' }));
    const label = element('text', { x: 80, y: -m * 1000 + 300, class: 'ring-label' });
    label.textContent = `${m} m`;
    rings.append(label);
  }
}

/** The radar's field of view: a wedge ±60° about its axis, to its reach. */
function drawField() {
  const from = ray(mountDeg + FIELD, REACH);
  const to = ray(mountDeg - FIELD, REACH);
  $('map-field').setAttribute('d', `M 0 0 L ${from.X.toFixed(0)} ${from.Y.toFixed(0)} A ${REACH} ${REACH} 0 0 1 ${to.X.toFixed(0)} ${to.Y.toFixed(0)} Z`);
}

function setLine(id, end) {
  const line = $(id);
  line.setAttribute('x2', end.X.toFixed(0));
  line.setAttribute('y2', end.Y.toFixed(0));
}

/** Which side a bearing is on, for people reading the list. */
function side(bearing) {
  const deg = Math.round(Math.abs(bearing));
  if (deg === 0) return 'straight ahead';
  return `${deg}° to the head's ${bearing > 0 ? 'left' : 'right'}`;
}

/**
 * The map from a telemetry line: the head's yaw (the gaze), and with the
 * radar on its people, whom the head attends to and its aim.
 */
export function showTelemetry(t) {
  lastTelemetry = t;
  setLine('map-gaze', ray(t.yaw, REACH));
  $('map-head').setAttribute('transform', `rotate(${(-t.yaw).toFixed(2)})`);
  $('map').dataset.yaw = String(t.yaw);
  const r = t.radar ?? null;
  const aiming = r !== null && r.at !== null;
  $('map-aim').style.display = aiming ? '' : 'none';
  if (aiming) setLine('map-aim', ray(r.at, REACH));
  const box = $('map-people');
  box.replaceChildren();
  const words = [];
  (r?.people ?? []).forEach((p, i) => {
    const at = place(p.x, p.y, mountDeg);
    const attended = r.who === i;
    const g = element('g', {
      class: attended ? 'person attended' : 'person',
      'data-index': i,
      'data-x': p.x,
      'data-y': p.y,
    });
    if (attended) g.append(element('circle', { cx: at.X.toFixed(0), cy: at.Y.toFixed(0), r: 380, class: 'halo' }));
    g.append(element('circle', { cx: at.X.toFixed(0), cy: at.Y.toFixed(0), r: 220, class: 'dot' }));
    const label = element('text', { x: (at.X + 420).toFixed(0), y: (at.Y + 140).toFixed(0), class: 'person-label' });
    label.textContent = String(i + 1);
    g.append(label);
    box.append(g);
    words.push(`${i + 1}: ${(at.distance / 1000).toFixed(1)} m, ${side(at.bearing)}${attended ? ' (attended)' : ''}`);
  });
  let summary;
  if (!r) summary = known?.radar ? 'The head sends no radar positions (an older firmware).' : 'Radar off.';
  else if (!r.people.length) summary = r.targets ? `${r.targets} seen (this firmware sends no positions)` : 'Nobody in view.';
  else summary = words.join(' · ');
  if (r && r.at !== null) summary += ` · aiming at ${side(r.at)}`;
  $('map-summary').textContent = summary;
}

/**
 * Shows the settings as the head answered them; a control being typed in
 * keeps what is typed unless the answer is to its own change (`source`).
 */
function show(source = null) {
  if (!known) return;
  const put = (id, write) => {
    if ($(id) !== document.activeElement || id === source) write($(id));
  };
  put('radar-on', (c) => {
    c.checked = known.radar;
  });
  put('track-on', (c) => {
    c.checked = known.track;
  });
  put('track-height', (c) => {
    c.value = String(known.height);
  });
  put('track-mount', (c) => {
    c.value = String(known.mount / 1000);
  });
  put('track-prefer', (c) => {
    c.value = known.prefer;
  });
  mountDeg = known.mount / 1000;
  drawField();
  if (lastTelemetry) showTelemetry(lastTelemetry);
}

function showCounters(f) {
  $('radar-counters').textContent = `frames: ${f.frames ?? '–'} received, ${f.bad ?? '–'} damaged; ${f.targets ?? '–'} in the latest`;
}

/** Asks for the radar's state and the tracking's settings; whether the firmware has them. */
export async function read(source = null) {
  const radar = await page.ask('radar');
  if (!radar.startsWith('ok')) return false;
  const track = await page.ask('track');
  const r = fields(radar);
  const t = fields(track);
  known = {
    radar: r.radar === 'on',
    track: t.track === 'on',
    height: Number(t.height),
    mount: Number(t.mount),
    prefer: t.prefer,
  };
  showCounters(r);
  show(source);
  return true;
}

/** The counters, refreshed with `status` (the settings stay as read). */
export async function refresh() {
  const reply = await page.ask('radar');
  if (reply.startsWith('ok')) showCounters(fields(reply));
}

/** Sends a radar or tracking setting, then reads both back: a refused one snaps back with the reason. */
async function set(line) {
  const why = $('why-radar');
  why.textContent = '';
  const source = document.activeElement?.id ?? null;
  const reply = await page.ask(line);
  if (!reply.startsWith('ok')) why.textContent = refusal(reply);
  await read(source);
  await page.refreshStatus();
}

/** Whether the firmware has a radar (`help` lists `radar` and `track`). */
export function offered(words) {
  const has = words.includes('radar') && words.includes('track');
  $('radar-section').hidden = !has;
  return has;
}

/** The map and the handlers; `context` gives `ask` and `refreshStatus`. */
export function setUp(context) {
  page = context;
  makeMap();
  drawField();
  const number = (id, line) =>
    $(id).addEventListener('change', () => {
      const value = $(id).value;
      if (value === '') {
        show();
        return;
      }
      set(line(Number(value))).catch(() => {});
    });
  $('radar-on').addEventListener('change', () => set(`radar ${$('radar-on').checked ? 'on' : 'off'}`).catch(() => {}));
  $('track-on').addEventListener('change', () => set(`track ${$('track-on').checked ? 'on' : 'off'}`).catch(() => {}));
  number('track-height', (mm) => `track height ${Math.round(mm)}`);
  number('track-mount', (deg) => `track mount ${Math.round(deg * 1000)}`);
  $('track-prefer').addEventListener('change', () => set(`track prefer ${$('track-prefer').value}`).catch(() => {}));
}
