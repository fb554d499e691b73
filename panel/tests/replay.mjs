// The radar's map on replayed telemetry (panel/tests/browser.mjs): the
// lines `cargo xtask test` got from a host trace of
// panel/tests/radar-replay.txt (the core's own), replayed by a fake serial
// port.

import { join } from 'node:path';
import { browser, cfg, check, fakeSerial, say, sayLog, shot, sleep, until, watchErrors } from './common.mjs';

/** A telemetry line's `key=value` words. */
function telemetryFields(line) {
  const out = {};
  for (const word of line.slice(2, line.lastIndexOf(' *')).split(' ')) {
    const [key, value] = word.split('=');
    out[key] = value;
  }
  return out;
}

/**
 * The page on a fake serial port that answers each line the page sends
 * with the console's reply (from the host trace's console at the end of
 * the run) and, once asked to `watch`, replays the trace's telemetry lines
 * at 20 a second: the map must draw each person where the last line says,
 * the attended one marked, the gaze at the head's yaw.
 */
export async function replaySession() {
  const { lines, answers } = cfg.replay;
  check(lines.length > 20 && lines.at(-1).includes(' xy='), `${lines.length} telemetry lines to replay, the last: ${lines.at(-1)}`);
  const chrome = await browser();
  const errors = [];
  let page = null;
  let port = -1;
  let replayed = 0;
  let replaying = null;
  const toPage = (text) =>
    page?.evaluate(([id, b]) => window.__serialData(id, b), [port, Array.from(Buffer.from(text, 'latin1'))]).catch(() => {});
  const replay = async () => {
    for (const line of lines) {
      await toPage(`${line}\r\n`);
      replayed += 1;
      await sleep(50);
    }
  };
  try {
    const context = await chrome.newContext({ viewport: { width: 1280, height: 800 } });
    await context.addInitScript(fakeSerial);
    let partial = '';
    await context.exposeBinding('__serialWrite', (_source, id, bytes) => {
      port = id;
      partial += Buffer.from(bytes).toString('latin1');
      let end;
      while ((end = partial.indexOf('\n')) >= 0) {
        const line = partial.slice(0, end).trim();
        partial = partial.slice(end + 1);
        const reply = answers[line] ?? `err syntax unknown command \`${line.split(' ')[0]}\` (try \`help\`)`;
        toPage(`${reply}\r\n`);
        if (line.startsWith('watch ') && !replaying) replaying = replay();
      }
    });
    page = await context.newPage();
    watchErrors(page, errors);
    await page.goto(cfg.url);
    await page.getByRole('button', { name: 'Connect' }).click();
    await until(async () => (await page.locator('#state').textContent()).startsWith('connected'), 10000, 'connected');
    check(await page.locator('#radar-section').isVisible(), 'the radar section is shown (help lists radar and track)');
    await until(async () => (await page.locator('#track-height').inputValue()) !== '', 5000, 'the tracking read back');
    const radarOn = await page.getByLabel('radar on: the head uses it').isChecked();
    const trackOn = await page.getByLabel('track on: the head looks at people').isChecked();
    const mount = Number(await page.getByLabel('track mount: the radar\'s bearing, degrees').inputValue());
    const height = await page.getByLabel("track height: visitors' eyes above the head's pivot, mm").inputValue();
    check(radarOn && trackOn && mount === 10 && height === '250', `radar and tracking read back: radar on, track on, mount ${mount}°, eyes ${height} mm`);

    // While the lines come: the people drawn follow them.
    const counts = new Set();
    while (replayed < lines.length) {
      counts.add(await page.locator('#map-people g.person').count());
      await sleep(40);
    }
    await replaying;
    await sleep(300);
    check(counts.has(1) && counts.has(2), `during the replay the map drew ${[...counts].sort().join(' and ')} people`);

    // The last line, drawn.
    const last = telemetryFields(lines.at(-1));
    const people = last.xy.split(';').map((pair) => pair.split(',').map(Number));
    const who = Number(last.who);
    const drawn = await page.locator('#map-people g.person').evaluateAll((groups) =>
      groups.map((g) => {
        const dot = g.querySelector('circle.dot');
        return {
          x: Number(g.dataset.x),
          y: Number(g.dataset.y),
          attended: g.classList.contains('attended'),
          cx: Number(dot.getAttribute('cx')),
          cy: Number(dot.getAttribute('cy')),
        };
      }),
    );
    check(drawn.length === people.length, `the last line's ${people.length} people drawn: ${drawn.length}`);
    people.forEach(([x, y], i) => {
      // docs/user/radar.md: the head turns to yaw = mount − atan2(x, y)
      // (positive: its own left), at the person's distance; the map has the
      // head looking up the page, its left to the left.
      const yaw = (mount * Math.PI) / 180 - Math.atan2(x, y);
      const d = Math.hypot(x, y);
      const want = { cx: -d * Math.sin(yaw), cy: -d * Math.cos(yaw) };
      const got = drawn[i];
      const off = Math.hypot(got.cx - want.cx, got.cy - want.cy);
      check(got.x === x && got.y === y && off <= 1, `person ${i + 1} at x=${x}, y=${y} mm drawn at (${got.cx}, ${got.cy}), ${off.toFixed(2)} mm from the bearing ${((yaw * 180) / Math.PI).toFixed(1)}° at ${(d / 1000).toFixed(2)} m`);
      check(got.attended === (i === who), `person ${i + 1} ${i === who ? 'marked as the one the head attends to' : 'not marked'} (who=${last.who})`);
    });
    // Straight ahead of the radar (x = 0), mounted 10° to the head's left:
    // 10° left of the head's axis on the map.
    const ahead = drawn.find((p) => p.x === 0);
    const side = ahead ? (Math.atan2(-ahead.cx, -ahead.cy) * 180) / Math.PI : NaN;
    check(Math.abs(side - 10) < 0.1, `the person straight ahead of the radar is drawn ${side.toFixed(2)}° to the head's left (the mount, 10°)`);
    // The gaze: the head's yaw in the line; the aim: `at=`.
    const ray = async (id) =>
      page.locator(id).evaluate((line) => [Number(line.getAttribute('x2')), Number(line.getAttribute('y2'))]);
    const [gx, gy] = await ray('#map-gaze');
    const gaze = (Math.atan2(-gx, -gy) * 180) / Math.PI;
    check(Math.abs(gaze - Number(last.y) / 1000) < 0.1, `the gaze drawn at ${gaze.toFixed(2)}°, the head's yaw in the line (y=${last.y} m°)`);
    const [ax, ay] = await ray('#map-aim');
    const aim = (Math.atan2(-ax, -ay) * 180) / Math.PI;
    check(last.at !== '-' && Math.abs(aim - Number(last.at) / 1000) < 0.1, `the aim drawn at ${aim.toFixed(2)}° (at=${last.at} m°)`);
    const summary = await page.getByLabel('people the radar sees', { exact: true }).textContent();
    check(summary.includes('(attended)'), `the map's words: "${summary}"`);
    await shot(page, 'radar');
    // The map alone, for the user guide (docs/panel-radar.png).
    const map = join(cfg.shots, 'panel-radar-map.png');
    await page.locator('#radar-section').screenshot({ path: map });
    say(`screenshot ${map}`);
    check(errors.length === 0, `no page errors${errors.length ? `: ${errors.join('; ')}` : ''}`);
  } catch (error) {
    await sayLog(page);
    throw error;
  } finally {
    await chrome.close();
  }
}
