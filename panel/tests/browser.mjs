// The panel in a real browser: Debian's Chromium, headless, driven by
// playwright-core (never Playwright's own browser download). Run by
// `cargo xtask test` (xtask/src/panel/browser.rs), which starts what each
// session talks to and passes it here as JSON:
//
//   node tests/browser.mjs '{"session": "serial", "url": …, "harness": {"cwd": …, "arg": …}, "shots": …}'
//   node tests/browser.mjs '{"session": "bridge", "url": …, "label": …, "shots": …}'
//
// - serial: the page served without a bridge uses Web Serial; a fake
//   `navigator.serial` (addInitScript) is bridged (exposeBinding) to the
//   shipped Pico image in the RP2040 emulator, live, over its USB serial
//   port. The fake can also unplug the board, answer `watch` as an older
//   firmware does, and swallow a line (a reply that never comes); the
//   emulator's GP2 can be pressed (`pin 2 0` to the harness).
// - bridge: the page served by `cargo xtask panel` with a bridge (QEMU, a
//   serial port) connects over its bridge on load.
// - replay: the page on a fake serial port that replays the telemetry of
//   a host trace with the radar's people (replay.mjs).
//
// Each prints what it checked; any failed check, page error or timeout
// fails the run (exit 1). Screenshots at 1280×800 go to `shots`. What the
// sessions share is in common.mjs; the settings' read-back in settings.mjs.

import { spawn } from 'node:child_process';
import { browser, cfg, check, fakeSerial, readout, say, sayLog, shot, sleep, until, watchErrors } from './common.mjs';
import { replaySession } from './replay.mjs';
import { CHANGED, changeSettings, loadReadsBack, readsBack } from './settings.mjs';

/** The pitch readout swings by more than 2° within 2 s of a click on Nod. */
async function nodSwings(page) {
  await until(async () => !(await page.getByRole('button', { name: 'Nod' }).isDisabled()), 10000, 'the Nod button');
  // Idle off and centred first: the swing is the nod's alone.
  const before = await readout(page, 'pitch');
  const clicked = Date.now();
  await page.getByRole('button', { name: 'Nod' }).click();
  let swing = 0;
  while (Date.now() - clicked < 2000) {
    swing = Math.max(swing, Math.abs((await readout(page, 'pitch')) - before));
    if (swing > 2) break;
    await sleep(20);
  }
  check(swing > 2, `Nod: the pitch readout swung by ${swing.toFixed(1)}° within ${Date.now() - clicked} ms (more than 2° within 2 s)`);
  return swing;
}

/** The README's picture of the panel (panel-front.png, which is
 * docs/images/panel.png), taken on the shipped image in the emulator once
 * connected, the idle moving the readouts and a nod under way: a head at
 * work, not a refusal. */
async function frontPage(page) {
  await until(async () => (await page.locator('#state').textContent()).startsWith('connected'), 20000, 'connected');
  const pose = async () => Promise.all(['pitch', 'roll', 'yaw'].map((a) => readout(page, a)));
  const start = await until(async () => {
    const now = await pose();
    return now.every(Number.isFinite) ? now : null;
  }, 10000, 'the readouts show the pose');
  await until(async () => {
    const now = await pose();
    return now.some((v, i) => Math.abs(v - start[i]) > 0.5) || null;
  }, 6000, 'the idle moves the readouts');
  await sleep(2000);
  await until(async () => !(await page.getByRole('button', { name: 'Nod' }).isDisabled()), 10000, 'the Nod button');
  await page.getByRole('button', { name: 'Nod' }).click();
  await until(async () => (await page.locator('#log li').allTextContents()).some((l) => l.startsWith('ok nod')), 4000, 'the nod answered');
  await sleep(300);
  const moved = (await pose()).map((v, i) => Math.abs(v - start[i]));
  check(Math.max(...moved) > 0.5, `the front page's picture: connected, the readouts moved by ${moved.map((v) => v.toFixed(1)).join('°, ')}°, a nod under way`);
  await shot(page, 'front');
}

/** What every session checks once connected: status, a calibration
 * slider moved from the keyboard and a refused value, a nod, save. */
async function session(page, { yawPulse }) {
  await until(async () => (await page.locator('#state').textContent()).startsWith('connected'), 20000, 'connected');
  const firmware = await page.locator('#firmware').textContent();
  check(/^firmware \d+\.\d+\.\d+/.test(firmware), `connected; the page shows the ${firmware}`);
  const status = await until(async () => {
    const text = await page.locator('#status-line').textContent();
    return text.includes('mode=') ? text : null;
  }, 5000, 'the status line');
  check(/mode=(running|starting)/.test(status), `status read: ${status}`);
  const rate = await until(async () => page.getByLabel('servo rate in Hz').inputValue(), 5000, 'the servo rate read');
  const period = await page.getByLabel('servo period').textContent();
  check(rate === '50' && period === 'period 20000 µs', `servo rate read on connect: ${rate} Hz, ${period}`);
  const gestures = await page.locator('#gestures button').allTextContents();
  check(gestures.includes('Nod') && gestures.includes('Shake') && gestures.includes('Tilt'), `gesture buttons from help: ${gestures.join(', ')}`);

  // A still head: idle off, centred.
  await page.getByLabel('idle motion').uncheck();
  await page.getByRole('button', { name: 'Center' }).click();
  await sleep(2500);
  const yaw0 = await yawPulse();
  check(Math.abs(yaw0 - 1500) <= 2, `yaw pulse at rest ${yaw0.toFixed(1)} µs (its neutral, 1500)`);

  // The yaw neutral slider, moved from the keyboard: 20 steps of 1 µs.
  await page.getByRole('radio', { name: 'yaw' }).check();
  const slider = page.getByLabel('neutral slider (µs)');
  await slider.focus();
  for (let i = 0; i < 20; i++) await page.keyboard.press('ArrowRight');
  await until(async () => (await page.getByLabel('neutral (µs)').inputValue()) === '1520', 5000, 'the number field follows the slider');
  const yaw1 = await until(async () => {
    const us = await yawPulse();
    return Math.abs(us - 1520) <= 2 ? us : null;
  }, 6000, 'the yaw pulse moves to the new neutral');
  check(true, `yaw neutral slider 1500 → 1520 µs: the yaw pulse went ${yaw0.toFixed(1)} → ${yaw1.toFixed(1)} µs`);

  // A value being typed survives an answer to another field arriving
  // meanwhile (here a neutral sent again while the max field has focus).
  const max = page.getByLabel('max pulse (µs)');
  await max.fill('3000');
  const sent = (await page.locator('#log li').allTextContents()).length;
  await page.evaluate(() => {
    const neutral = document.getElementById('f-neutral');
    neutral.dispatchEvent(new Event('change'));
  });
  await until(async () => {
    const lines = (await page.locator('#log li').allTextContents()).slice(sent);
    const at = lines.findIndex((l) => l.startsWith('servo yaw neutral'));
    return at >= 0 && lines.slice(at + 1).some((l) => l === 'ok' || l.startsWith('ok warning')) ? true : null;
  }, 5000, 'the neutral answered');
  await until(async () => (await max.inputValue()) === '3000' || null, 1000, 'the typed max kept');
  check((await max.inputValue()) === '3000', 'a max being typed is kept while another field is answered');

  // A refused value snaps back, with the firmware's reason.
  await max.press('Enter');
  const why = await until(async () => (await page.locator('#why-max').textContent()) || null, 5000, 'the reason');
  check((await max.inputValue()) === '2000' && why.includes('2500'), `max pulse 3000 refused, snapped back to 2000: "${why}"`);

  await shot(page, cfg.label ?? cfg.session);
  await nodSwings(page);

  // Save: the unsaved-changes mark goes.
  check(!(await page.locator('#unsaved').isHidden()), 'unsaved changes marked after the neutral change');
  await page.getByRole('button', { name: 'Save' }).click();
  await until(async () => page.locator('#unsaved').isHidden(), 8000, 'the unsaved mark goes after Save');
  check(true, 'Save: the settings are stored, the unsaved mark is gone');
}

/** Rest to a pose set in the Rest group, then Wake. `pitchPulse()` is
 * the pitch servo's pulse in µs as the session sees it. */
async function restAndWake(page, { pitchPulse }) {
  // The head runs on its built-in rest settings, read back on connect.
  const pose0 = await Promise.all(['pitch', 'roll', 'yaw'].map((a) => page.getByLabel(`rest pose ${a} in degrees`).inputValue()));
  const after0 = await page.getByLabel('rest after, seconds with no one there').inputValue();
  check(pose0.join(' ') === '8 0 0' && after0 === '120' && (await page.locator('#rest-note').isHidden()),
    `rest settings read back on connect: the built-in pose ${pose0.join('°, ')}°, rest after ${after0} s`);
  const after = page.getByLabel('rest after, seconds with no one there');
  await after.fill('0');
  await after.press('Enter');
  const why = await until(async () => (await page.locator('#why-rest').textContent()) || null, 5000, 'the reason rest after 0 is refused');
  await until(async () => (await after.inputValue()) === '120', 5000, 'rest after snaps back');
  check(why.includes('1..=86400'), `rest after 0 refused, snapped back to 120: "${why}"`);
  for (const [axis, value] of [['pitch', '-5'], ['yaw', '6']]) {
    const field = page.getByLabel(`rest pose ${axis} in degrees`);
    await field.fill(value);
    await field.press('Enter');
  }
  await until(async () => (await page.locator('#log').textContent()).includes('rest pose -5000 0 6000'), 5000, 'the rest pose sent');
  await page.getByRole('button', { name: 'Rest', exact: true }).click();
  const mode = await until(async () => {
    const text = await page.getByLabel('mode', { exact: true }).textContent();
    return text === 'resting' ? text : null;
  }, 3000, 'the mode readout says resting');
  check(true, `Rest: the mode readout says ${mode}`);
  const clicked = Date.now();
  const pose = await until(async () => {
    const [p, r, y] = await Promise.all(['pitch', 'roll', 'yaw'].map((a) => readout(page, a)));
    return Math.abs(p + 5) <= 0.15 && Math.abs(r) <= 0.15 && Math.abs(y - 6) <= 0.15 ? [p, r, y] : null;
  }, 6000, 'the head glides to the rest pose (-5°, 0°, 6°)');
  const pulse = await pitchPulse();
  check(Math.abs(Math.abs(pulse - 1500) - 5 * 11.111) <= 3, `at rest in ${((Date.now() - clicked) / 1000).toFixed(1)} s: readouts ${pose.join('°, ')}°, the pitch pulse ${pulse.toFixed(1)} µs (5° from 1500 µs at 11.1 µs/°)`);
  await page.getByRole('button', { name: 'Wake', exact: true }).click();
  const woke = await until(async () => {
    const text = await page.getByLabel('mode', { exact: true }).textContent();
    return /^(waking|running)$/.test(text) ? text : null;
  }, 3000, 'the mode readout says waking or running');
  await until(async () => Math.abs(await readout(page, 'pitch')) < 1, 4000, 'the head leaves the rest pose for its neutral pose (idle off)');
  check(true, `Wake: the mode readout says ${woke}, the head is back at its neutral pose`);
}

/** GP2 as a button running a nod (read back; a refused action snaps back),
 * then the DMX address (a refused one snaps back) and DMX off and on.
 * `press(down)`, when the session can, drives GP2's pin. */
async function inputsAndDmx(page, { press = null } = {}) {
  await page.getByLabel('GP2 role').selectOption('button');
  const action = page.getByLabel('GP2 button: the command a press runs');
  await until(async () => (await action.isVisible()) && (await action.inputValue()) === 'nod', 5000, 'GP2 reads back as a button running `nod`');
  await action.fill('nod 5000 cycles=3');
  await action.press('Enter');
  const readback = await until(async () => {
    const lines = await page.locator('#log li.in').allTextContents();
    return lines.find((l) => /^ok input 2 level=\w+ active=0 button nod 5000 cycles=3$/.test(l));
  }, 5000, 'the read-back of input 2');
  check((await action.inputValue()) === 'nod 5000 cycles=3', `GP2 a button running \`nod 5000 cycles=3\`: read back "${readback}"`);
  await action.fill('nod 90000');
  await action.press('Enter');
  const refused = await until(async () => (await page.locator('#why-in-2').textContent()) || null, 5000, 'the reason GP2 is refused');
  await until(async () => (await action.inputValue()) === 'nod 5000 cycles=3', 5000, 'the action snaps back');
  check(refused.startsWith('refused:') && refused.includes('20°'), `GP2 \`nod 90000\` refused, snapped back to \`nod 5000 cycles=3\`: "${refused}"`);
  const level = await until(async () => {
    const text = await page.getByLabel('GP2 level').textContent();
    return text === 'released' ? text : null;
  }, 3000, 'the GP2 level from status');
  check(true, `GP2's level as status reports it: ${level}`);
  if (press) {
    const p0 = await readout(page, 'pitch');
    await press(true);
    let swing = 0;
    await until(async () => {
      swing = Math.max(swing, Math.abs((await readout(page, 'pitch')) - p0));
      return swing > 2 && (await page.getByLabel('GP2 level').textContent()) === 'pressed';
    }, 3000, 'GP2 pressed: the level readout says so and the head nods');
    await press(false);
    check(true, `GP2 pressed in the emulator: the level readout says pressed, the pitch readout swung by ${swing.toFixed(1)}°`);
  }

  const address = page.getByLabel('DMX start address');
  await address.fill('17');
  await address.press('Enter');
  await until(async () => (await page.locator('#log li.in').allTextContents()).some((l) => / address=17 /.test(l)), 5000, 'the DMX address read back');
  const signal = await page.getByLabel('DMX signal').textContent();
  const counters = await page.getByLabel('DMX frames received').textContent();
  check((await address.inputValue()) === '17' && signal.startsWith('lost'), `DMX address 17 read back; signal "${signal}", "${counters}"`);
  await address.fill('600');
  await address.press('Enter');
  const why = await until(async () => (await page.locator('#why-dmx').textContent()) || null, 5000, 'the reason 600 is refused');
  await until(async () => (await address.inputValue()) === '17', 5000, 'the address snaps back');
  check(why.includes('1..=503'), `DMX address 600 refused, snapped back to 17: "${why}"`);
  await page.getByLabel('DMX drives the head').uncheck();
  await until(async () => (await page.getByLabel('DMX signal').textContent()).startsWith('off'), 5000, 'DMX off');
  await page.getByLabel('DMX drives the head').check();
  await until(async () => (await page.getByLabel('DMX signal').textContent()).startsWith('lost'), 5000, 'DMX on again');
  check(!(await page.locator('#unsaved').isHidden()), 'DMX off and on again: the signal readout followed; the unsaved mark is back');
}

/** The servo rate set to 333 Hz: read back with its period (whole µs),
 * in status; the still head's pulses do not move; 400 Hz refused, snapped
 * back. `pulses()` is the three pulses in µs as the session sees them. */
async function servoRate(page, { pulses }) {
  const before = await pulses();
  const field = page.getByLabel('servo rate in Hz');
  await field.fill('333');
  await field.press('Enter');
  await until(async () => (await page.locator('#log li.in').allTextContents()).includes('ok servo rate=333 period_us=3003'), 5000, 'the rate read back');
  await until(async () => (await page.locator('#status-line').textContent()).endsWith(' rate=333'), 5000, 'status says rate=333');
  const period = await page.getByLabel('servo period').textContent();
  check((await field.inputValue()) === '333' && period === 'period 3003 µs', `servo rate 333 Hz read back, ${period}; status ends rate=333`);
  await sleep(1000);
  const after = await pulses();
  const moved = Math.max(...after.map((us, i) => Math.abs(us - before[i])));
  check(moved <= 1, `the still head's pulses across the change: ${before.join(', ')} → ${after.join(', ')} µs`);
  await field.fill('400');
  await field.press('Enter');
  const why = await until(async () => (await page.locator('#why-rate').textContent()) || null, 5000, 'the reason 400 Hz is refused');
  check((await field.inputValue()) === '333' && why.includes('50..=333'), `servo rate 400 refused, snapped back to 333: "${why}"`);
}

// ---- the Web Serial session ------------------------------------------

async function serialSession() {
  const harness = spawn('node', ['harness.mjs', cfg.harness.arg], { cwd: cfg.harness.cwd, stdio: ['pipe', 'pipe', 'inherit'] });
  const duty = [0, 0, 0]; // the servos' last compare values (counts of 20 ms / 64000)
  const pitchDuties = [];
  let page = null;
  let port = -1; // the fake port the emulator's USB port is plugged into
  let telemetry = 0; // telemetry lines the emulated head sent
  let mode = 'normal'; // or 'old' (answers `watch` with err), 'swallow' (drops `seed` lines)
  let line = '';
  const toPage = (bytes) => page?.evaluate(([id, b]) => window.__serialData(id, b), [port, bytes]).catch(() => {});
  let buffered = '';
  harness.stdout.on('data', (chunk) => {
    buffered += chunk.toString();
    let end;
    while ((end = buffered.indexOf('\n')) >= 0) {
      const event = JSON.parse(buffered.slice(0, end));
      buffered = buffered.slice(end + 1);
      if (event.ev === 'usb') {
        const bytes = Buffer.from(event.hex, 'hex');
        telemetry += (bytes.toString('latin1').match(/~ t=/g) ?? []).length;
        toPage(Array.from(bytes));
      }
      if (event.ev === 'cc' && event.slice <= 2) {
        duty[event.slice] = event.value & 0xffff;
        if (event.slice === 0) pitchDuties.push({ at: Date.now(), us: ((event.value & 0xffff) * 20000) / 64000 });
      }
      if (event.ev === 'end') say(`emulator ended: ${event.why}`);
    }
  });
  const yawPulse = async () => (duty[2] * 20000) / 64000;
  const chrome = await browser();
  const errors = [];
  try {
    const context = await chrome.newContext({ viewport: { width: 1280, height: 800 } });
    await context.addInitScript(fakeSerial);
    await context.exposeBinding('__serialWrite', (_source, id, bytes) => {
      port = id;
      for (const b of bytes) {
        line += String.fromCharCode(b);
        if (b !== 10) continue;
        const sent = line.trim();
        line = '';
        if (mode === 'old' && sent.startsWith('watch')) {
          toPage(Array.from(Buffer.from('err syntax unknown command `watch` (try `help`)\r\n')));
          continue;
        }
        if (mode === 'swallow' && sent.startsWith('seed')) continue;
        harness.stdin.write(Buffer.from(sent + '\n').toString('hex') + '\n');
      }
    });
    page = await context.newPage();
    watchErrors(page, errors);
    await page.goto(cfg.url);
    check((await page.locator('#state').textContent()) === 'not connected', 'served without a bridge: the page waits for Connect');
    await page.getByRole('button', { name: 'Connect' }).click();
    await frontPage(page);
    await session(page, { yawPulse });
    const pitch = pitchDuties.filter((d) => d.at > Date.now() - 4000).map((d) => d.us);
    const span = Math.max(...pitch) - Math.min(...pitch);
    check(span > 2 * 11.1, `the nod in the emulator's pitch pulses on GP16: ${span.toFixed(0)} µs of swing (more than 2° at 11.1 µs/°)`);
    await restAndWake(page, { pitchPulse: async () => (duty[0] * 20000) / 64000 });
    // GP2 is pulled up (a button to ground): pressed is low.
    await inputsAndDmx(page, { press: async (down) => harness.stdin.write(`pin 2 ${down ? 0 : 1}\n`) });
    await shot(page, 'inputs');
    await changeSettings(page);
    const nobody = await until(async () => {
      const text = await page.getByLabel('people the radar sees', { exact: true }).textContent();
      return text === 'Nobody in view.' ? text : null;
    }, 3000, "the map: the emulated Pico's radar sees nobody");
    check(true, `radar on, the emulated Pico's telemetry carries its people: "${nobody}"`);

    // Unplugged mid-session.
    await page.evaluate((id) => window.__unplug(id), port);
    await until(async () => (await page.locator('#banner-text').textContent()).includes('unplugged'), 5000, 'the page says the board was unplugged');
    check(await page.getByRole('button', { name: 'Reconnect' }).isVisible(), `unplugged: "${await page.locator('#banner-text').textContent()}", with Reconnect`);
    await shot(page, 'unplugged');

    // Plugged in again, an older firmware: `watch` is an error.
    mode = 'old';
    await page.getByRole('button', { name: 'Reconnect' }).click();
    await until(async () => (await page.locator('#banner-text').textContent()).includes('watch'), 10000, 'the page says the firmware has no telemetry');
    // Read on connect: every setting as set before (changed, not saved).
    await readsBack(page, CHANGED, 'reconnected: every setting read back from the emulated Pico');
    const p0 = await readout(page, 'pitch');
    await page.getByLabel('idle motion').check();
    await page.getByRole('button', { name: 'Nod' }).click();
    await until(async () => Math.abs((await readout(page, 'pitch')) - p0) > 1, 4000, 'the readouts follow status without telemetry');
    check(true, `older firmware: "${(await page.locator('#banner-text').textContent()).slice(0, 70)}…", the readouts still move`);

    // A reply that never comes.
    mode = 'swallow';
    await page.getByLabel('seed', { exact: true }).fill('7');
    await page.getByRole('button', { name: 'Set seed' }).click();
    await until(async () => (await page.locator('#banner-text').textContent()).includes('no reply'), 6000, 'the page says a reply never came');
    check(await page.getByRole('button', { name: 'Reconnect' }).isVisible(), `no reply: "${await page.locator('#banner-text').textContent()}", with Reconnect`);
    check(errors.length === 0, `no page errors${errors.length ? `: ${errors.join('; ')}` : ''}`);

    // The host closes the port (DTR drops): the telemetry stops, and does
    // not come back when it opens the port again until asked.
    const send = (text) => harness.stdin.write(Buffer.from(text).toString('hex') + '\n');
    send('watch 50\n');
    await sleep(500);
    const streaming = telemetry;
    await sleep(300);
    check(telemetry - streaming >= 10, `watch 50 from the host: ${telemetry - streaming} lines in 300 ms`);
    harness.stdin.write('dtr 0\n');
    await sleep(200);
    const closed = telemetry;
    harness.stdin.write('dtr 1\n');
    await sleep(500);
    check(telemetry === closed, `DTR dropped: the telemetry stopped (${telemetry - closed} lines after it)`);
  } catch (error) {
    await sayLog(page);
    throw error;
  } finally {
    await chrome.close();
    harness.stdin.end();
    harness.kill();
  }
}

// ---- a session over the bridge -------------------------------------------

async function bridgeSession() {
  const chrome = await browser();
  const errors = [];
  let page = null;
  try {
    page = await chrome.newPage({ viewport: { width: 1280, height: 800 } });
    watchErrors(page, errors);
    // The yaw pulse as the telemetry reports it.
    const yawPulse = async () => {
      const text = await page.locator('#pulses').textContent();
      const match = /pulses (\d+), (\d+), (\d+)/.exec(text);
      return match ? Number(match[3]) : NaN;
    };
    await page.goto(cfg.url);
    await until(async () => (await page.locator('#state').textContent()).startsWith('connected'), 20000, 'connected on load');
    check((await page.locator('#transport').textContent()).startsWith('bridged to'), `connected on load, no chooser: ${await page.locator('#transport').textContent()}`);
    await session(page, { yawPulse });
    if (cfg.label === 'qemu') {
      await gazeControls(page);
      const pitchPulse = async () => Number(/pulses (\d+)/.exec(await page.locator('#pulses').textContent())?.[1]);
      await restAndWake(page, { pitchPulse });
      await inputsAndDmx(page);
      const pulses = async () => (/pulses (\d+), (\d+), (\d+)/.exec(await page.locator('#pulses').textContent()) ?? []).slice(1).map(Number);
      await servoRate(page, { pulses });
      await changeSettings(page);
      const nobody = await until(async () => {
        const text = await page.getByLabel('people the radar sees', { exact: true }).textContent();
        return text === 'Nobody in view.' ? text : null;
      }, 3000, "the map: QEMU's radar, with nothing wired, sees nobody");
      check(true, `radar on, QEMU's telemetry carries its people: "${nobody}"`);
      // Reconnected (the page loaded again): every setting read back.
      await page.reload();
      await until(async () => (await page.locator('#state').textContent()).startsWith('connected'), 20000, 'connected again on load');
      await readsBack(page, { ...CHANGED, rate: '333' }, 'reloaded: every setting read back from QEMU');
      await loadReadsBack(page);
    }
    check(errors.length === 0, `no page errors${errors.length ? `: ${errors.join('; ')}` : ''}`);
  } catch (error) {
    await sayLog(page);
    throw error;
  } finally {
    await chrome.close();
  }
}

/** The look pad from the keyboard, and "go to limit" (yaw). */
async function gazeControls(page) {
  const pad = page.getByRole('slider', { name: /Look pad/ });
  await pad.focus();
  for (let i = 0; i < 5; i++) await page.keyboard.press('ArrowRight');
  await page.keyboard.press('Enter');
  const yaw = await until(async () => {
    const value = await readout(page, 'yaw');
    return value > 8 ? value : null;
  }, 4000, 'the head looks 10° to its left (the audience\'s right, right on the pad)');
  check(true, `look pad from the keyboard (5 × ArrowRight, Enter): yaw readout ${yaw}°`);
  // Down on the pad is nose down, +pitch, drawn turning clockwise from the
  // head's right side (docs/user/conventions.md).
  for (let i = 0; i < 5; i++) await page.keyboard.press('ArrowDown');
  await page.keyboard.press('Enter');
  const pitch = await until(async () => {
    const value = await readout(page, 'pitch');
    return value > 8 ? value : null;
  }, 4000, 'the head looks 10° down (down on the pad)');
  const turn = Number(/rotate\((-?[\d.]+)\)/.exec(await page.locator('#side-head').getAttribute('transform'))?.[1]);
  check(turn > 8, `look pad (5 × ArrowDown, Enter): pitch readout ${pitch}°, the side view turned clockwise by ${turn}° (nose down)`);
  await page.getByRole('radio', { name: 'yaw' }).check();
  const limit = Number(await page.getByLabel('upper limit (°)').inputValue());
  await page.getByRole('button', { name: 'Go to upper limit' }).click();
  const reached = await until(async () => {
    const value = await readout(page, 'yaw');
    return Math.abs(value - limit) < 0.5 ? value : null;
  }, 10000, `yaw steps to its upper limit, ${limit}°`);
  check(true, `go to upper limit: yaw readout ${reached}° (limit ${limit}°), stepped 1° every 100 ms`);
  await page.getByRole('button', { name: 'Center' }).click();
}

try {
  if (cfg.session === 'serial') await serialSession();
  else if (cfg.session === 'replay') await replaySession();
  else await bridgeSession();
  say(`passed: ${cfg.label ?? cfg.session}`);
} catch (error) {
  console.log(`FAILED: ${error.message}`);
  process.exitCode = 1;
}
