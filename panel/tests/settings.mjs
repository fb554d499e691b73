// The settings the panel reads back from the head (panel/tests/browser.mjs):
// every one changed from the page and answered back at once, then read
// again by a page that connects anew, and after Load.

import { check, say, until } from './common.mjs';

const DUCK = 'look duck: how much of the idle a held look takes off, percent';
const MOUNT = "track mount: the radar's bearing, degrees";
const HEIGHT = "track height: visitors' eyes above the head's pivot, mm";

/** Waits until the head's reply `reply` is in the log. */
async function answered(page, reply) {
  await until(async () => (await page.locator('#log li.in').allTextContents()).includes(reply), 5000, `the reply \`${reply}\``);
}

/** Types `value` into the field labelled `label` and presses Enter. */
async function enter(page, label, value) {
  const field = page.getByLabel(label, { exact: true });
  await field.fill(String(value));
  await field.press('Enter');
}

/**
 * Every other setting changed from the page, each read back from the
 * head at once (a refused duck or tracking height snaps back with the
 * reason): rest after 300 s and relax on (the pose was set before), the
 * look's duck 35 %, the idle amplitude 40 %, seed 42, the radar on,
 * tracking mounted at 15°, eyes at -250 mm, the newest first, then off.
 */
export async function changeSettings(page) {
  await enter(page, 'rest after, seconds with no one there', 300);
  await answered(page, 'ok rest after=300 pose=-5000,0,6000 relax=off');
  await page.getByLabel('relax at rest: no pulses').check();
  await answered(page, 'ok rest after=300 pose=-5000,0,6000 relax=on');
  await enter(page, DUCK, 35);
  await answered(page, 'ok look duck=35');
  await enter(page, DUCK, 150);
  const duckWhy = await until(async () => (await page.locator('#why-duck').textContent()) || null, 5000, 'the reason duck 150 is refused');
  await until(async () => (await page.getByLabel(DUCK).inputValue()) === '35', 5000, 'the duck snaps back');
  check(duckWhy.includes('0..=100'), `look duck 150 refused, snapped back to 35: "${duckWhy}"`);
  await page.getByLabel('idle amplitude in percent').evaluate((slider) => {
    slider.value = '40';
    slider.dispatchEvent(new Event('change'));
  });
  await answered(page, 'ok idle=off amp=40');
  await page.getByLabel('seed', { exact: true }).fill('42');
  await page.getByRole('button', { name: 'Set seed' }).click();
  await until(async () => (await page.getByLabel('seed in use').textContent()) === '42', 5000, 'the seed in use: 42');
  await page.getByLabel('radar on: the head uses it').check();
  await until(async () => (await page.locator('#log li.in').allTextContents()).some((l) => l.startsWith('ok radar=on ')), 5000, 'radar on read back');
  await enter(page, MOUNT, 15);
  await answered(page, 'ok track=on height=300 mount=15000 prefer=nearest');
  await enter(page, HEIGHT, -250);
  await answered(page, 'ok track=on height=-250 mount=15000 prefer=nearest');
  await page.getByLabel('whom the head attends to').selectOption('newest');
  await answered(page, 'ok track=on height=-250 mount=15000 prefer=newest');
  await page.getByLabel('track on: the head looks at people').uncheck();
  await answered(page, 'ok track=off height=-250 mount=15000 prefer=newest');
  await enter(page, HEIGHT, 4000);
  const why = await until(async () => (await page.locator('#why-radar').textContent()) || null, 5000, 'the reason 4000 mm is refused');
  await until(async () => (await page.getByLabel(HEIGHT).inputValue()) === '-250', 5000, 'the height snaps back');
  check(why.includes('-3000..=3000'), `track height 4000 refused, snapped back to -250: "${why}"`);
  check(true, 'rest after 300 s, relax on, look duck 35 %, idle amplitude 40 %, seed 42, radar on, mount 15°, eyes -250 mm, newest first, tracking off: each read back as set');
}

/** What the page shows of every setting, as it read them. */
async function shown(page) {
  const value = (label) => page.getByLabel(label, { exact: true }).inputValue();
  const ticked = (label) => page.getByLabel(label, { exact: true }).isChecked();
  return {
    after: await value('rest after, seconds with no one there'),
    pose: (await Promise.all(['pitch', 'roll', 'yaw'].map((a) => value(`rest pose ${a} in degrees`)))).join(' '),
    relax: await ticked('relax at rest: no pulses'),
    duck: await value(DUCK),
    idle: await value('idle amplitude in percent'),
    seed: await page.getByLabel('seed in use').textContent(),
    radar: await ticked('radar on: the head uses it'),
    track: await ticked('track on: the head looks at people'),
    mount: await value(MOUNT),
    height: await value(HEIGHT),
    prefer: await value('whom the head attends to'),
    gp2: await value('GP2 role'),
    dmx: await value('DMX start address'),
    rate: await value('servo rate in Hz'),
  };
}

/** The page shows `want` (each of [`shown`]'s, `seed` a pattern), read from the head; what it shows. */
export async function readsBack(page, want, what) {
  let now = null;
  const same = () =>
    Object.entries(want).every(([key, value]) => (value instanceof RegExp ? value.test(now[key]) : now[key] === value));
  try {
    await until(async () => {
      now = await shown(page);
      return same();
    }, 5000, what);
  } catch (error) {
    say(`shown: ${JSON.stringify(now)}, wanted: ${JSON.stringify(want, (_, v) => (v instanceof RegExp ? String(v) : v))}`);
    throw error;
  }
  check(true, `${what}: ${Object.entries(now).map(([k, v]) => `${k} ${v}`).join(', ')}`);
}

/** Every setting after [`changeSettings`] (and the inputs and DMX before it). */
export const CHANGED = {
  after: '300',
  pose: '-5 0 6',
  relax: true,
  duck: '35',
  idle: '40',
  seed: '42',
  radar: true,
  track: false,
  mount: '15',
  height: '-250',
  prefer: 'newest',
  gp2: 'button',
  dmx: '17',
  rate: '50',
};

/** Load: every setting read again as saved (the built-in ones, but for
 * the calibration, before any was changed here). */
export async function loadReadsBack(page) {
  await page.getByRole('button', { name: 'Load' }).click();
  const saved = {
    after: '120',
    pose: '8 0 0',
    relax: false,
    duck: '80',
    idle: '100',
    seed: /^board/,
    radar: false,
    track: true,
    mount: '0',
    height: '300',
    prefer: 'nearest',
    gp2: 'off',
    dmx: '1',
    rate: '50',
  };
  await readsBack(page, saved, 'Load: every setting read again as saved');
  check(await page.locator('#unsaved').isHidden(), 'Load: the unsaved mark is gone');
}
