// The dashboard in a real browser (issue 17): `tomorig run` on the default simulated rig with
// --http, a camera made to vanish part-way, and headless Chromium (Debian's) driven by
// Playwright. Checks that live numbers, a thumbnail and a projection appear, that the numbers
// keep changing, that Pause freezes the view while the run goes on and Resume brings it back,
// that the snapshot button writes a PNG, that the lost camera's tile turns red and its alarm
// can be acknowledged, and that the page logs no console error. Waits on conditions, never on
// fixed sleeps. TOMORIG_BINARY names the program (ctest sets it); TOMORIG_SCREENSHOT, if set,
// is where a screenshot of the running dashboard is saved.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { existsSync, mkdtempSync, rmSync, statSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

import { binary, launchChromium, requireTools, stopChild } from './harness.mjs';



// Starts the run and resolves with the dashboard's address from its stderr.
function startRun(dir) {
  const args = ['run', '--sets', '3000', '--out', join(dir, 's.h5'), '--status', `ipc://${dir}/status`,
    '--preview', `ipc://${dir}/quicklook`, '--http', '127.0.0.1:0', '--snapshots', join(dir, 'snaps'),
    '--on-camera-loss', 'continue', '--inject-fault', 'cam2:vanish-after=30'];
  const child = spawn(binary, args, { stdio: ['ignore', 'ignore', 'pipe'] });
  let err = '';
  const url = new Promise((resolve, reject) => {
    child.stderr.on('data', (chunk) => {
      err += chunk;
      const m = err.match(/run: dashboard on (http:\/\/\S+)/);
      if (m) resolve(m[1]);
    });
    child.on('exit', (code) => reject(new Error(`tomorig run ended (${code}) before serving:\n${err}`)));
  });
  return { child, url, stderr: () => err };
}

async function stateSet(url) {
  const r = await fetch(new URL('api/state', url));
  const body = await r.json();
  return body.quicklook ? body.quicklook.set : -1;
}

test('the dashboard follows a simulated run in Chromium', { timeout: 240_000 }, async (t) => {
  requireTools();
  const dir = mkdtempSync(join(tmpdir(), 'tomorig-browser-'));
  const run = startRun(dir);
  const browser = await launchChromium();
  t.after(async () => {
    await browser.close();
    await stopChild(run.child);
    rmSync(dir, { recursive: true, force: true });
  });

  const url = await run.url;
  const page = await browser.newPage({ viewport: { width: 1400, height: 1600 } });
  const consoleErrors = [];
  page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
  page.on('pageerror', (e) => consoleErrors.push(String(e)));
  await page.goto(url);

  // Live numbers: a set, cam0's ppp near the rig's 0.05, its thumbnail decoded, a projection.
  await page.waitForFunction(() => /^\d+$/.test(document.getElementById('set').textContent), null, { timeout: 30_000 });
  const ppp = page.locator('[data-camera="cam0"] [data-figure="ppp"] .value');
  await page.waitForFunction(
    () => /\d/.test(document.querySelector('[data-camera="cam0"] [data-figure="ppp"] .value')?.textContent || ''),
    null, { timeout: 30_000 });
  const pppValue = Number(await ppp.textContent());
  assert.ok(Math.abs(pppValue - 0.05) < 0.01, `cam0 ppp ${pppValue}, the simulated rig has 0.05`);
  await page.waitForFunction(() => {
    const img = document.querySelector('[data-camera="cam0"] img.thumb');
    return img && img.complete && img.naturalWidth > 0;
  }, null, { timeout: 30_000 });
  await page.waitForFunction(() => {
    const img = document.getElementById('mip_z');
    return img.complete && img.naturalWidth > 0;
  }, null, { timeout: 45_000 });
  await page.waitForFunction(() => document.getElementById('rig-state') === null &&
    /running/.test(document.getElementById('status').textContent), null, { timeout: 30_000 });

  // The numbers keep changing: five new sets shown. The wait for each is generous because ctest
  // runs this beside the heavy tests on 2 cores, where the quick-look skips sets and Chromium is
  // starved for seconds at a time; how often the page updates on a machine that is not
  // overloaded is what six_cameras.test.mjs measures. Here the gaps are only reported.
  let shown = Number(await page.locator('#set').textContent());
  const gaps = [];
  for (let i = 0; i < 5; ++i) {
    const since = Date.now();
    await page.waitForFunction((before) => Number(document.getElementById('set').textContent) > before, shown,
      { timeout: 20_000 });
    gaps.push(Date.now() - since);
    const now = Number(await page.locator('#set').textContent());
    assert.ok(now > shown, `the set shown went from ${shown} to ${now}`);
    shown = now;
  }
  t.diagnostic(`seconds between updates of the set shown: ${gaps.map((g) => (g / 1000).toFixed(2)).join(' ')}`);

  // Pause freezes the view while the run goes on; Resume shows the newest set again.
  await page.click('#pause');
  const frozen = await page.locator('#set').textContent();
  let serverSet = await stateSet(url);
  const pausedAt = Date.now();
  while (serverSet < Number(frozen) + 3) {
    assert.ok(Date.now() - pausedAt < 60_000, `the run went on while paused (server at set ${serverSet}, shown ${frozen})`);
    await page.waitForTimeout(100);  // polling the server, not standing in for a condition
    serverSet = await stateSet(url);
  }
  assert.equal(await page.locator('#set').textContent(), frozen, 'paused: the set shown stays');
  assert.match(await page.locator('#pause').textContent(), /Resume/);
  await page.click('#pause');
  await page.waitForFunction((s) => Number(document.getElementById('set').textContent) >= s, serverSet,
    { timeout: 20_000 });

  // Snapshot: the server writes the newest set as PNG into --snapshots.
  await page.click('#snapshot');
  await page.waitForFunction(() => /snapshot: /.test(document.getElementById('action-result').textContent), null,
    { timeout: 10_000 });
  const file = (await page.locator('#action-result').textContent()).replace('snapshot: ', '');
  assert.ok(existsSync(file) && statSync(file).size > 1000, `snapshot ${file}`);

  // The camera that vanishes: its tile turns red, the others stay as they were, its alarm is acknowledged.
  await page.waitForSelector('[data-camera="cam2"].tile.red', { timeout: 45_000 });
  assert.match(await page.locator('[data-camera="cam2"] .health').textContent(), /disconnected/);
  assert.doesNotMatch(await page.locator('[data-camera="cam0"]').getAttribute('class'), /red/);
  const alarm = page.locator('[data-alarm="camera:cam2"]');
  await alarm.waitFor({ timeout: 10_000 });
  if (process.env.TOMORIG_SCREENSHOT) await page.screenshot({ path: process.env.TOMORIG_SCREENSHOT, fullPage: true });
  await alarm.locator('button').click();
  await page.waitForSelector('[data-alarm="camera:cam2"].acknowledged', { timeout: 10_000 });

  assert.deepEqual(consoleErrors, [], 'no console error');

  // The run ends; its session, opened with `tomorig preview --session`, shows its quick-look
  // history as time series.
  const ended = new Promise((resolve) => run.child.on('exit', resolve));
  run.child.kill('SIGINT');
  await page.waitForFunction(() => document.getElementById('connection').textContent === 'ended', null,
    { timeout: 30_000 });
  await ended;
  await page.close();
  const session = join(dir, 's.h5');
  assert.ok(existsSync(session), 'the stopped run closed its session');
  const viewer = spawn(binary, ['preview', '--session', session, '--http', '127.0.0.1:0'], { stdio: ['ignore', 'ignore', 'pipe'] });
  t.after(() => { if (viewer.exitCode === null) viewer.kill('SIGINT'); });
  let viewerErr = '';
  const historyUrl = await new Promise((resolve, reject) => {
    viewer.stderr.on('data', (chunk) => {
      viewerErr += chunk;
      const m = viewerErr.match(/dashboard on (http:\/\/\S+)/);
      if (m) resolve(m[1]);
    });
    viewer.on('exit', (code) => reject(new Error(`tomorig preview --session ended (${code}):\n${viewerErr}`)));
  });
  const history = await browser.newPage({ viewport: { width: 1400, height: 1600 } });
  history.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(m.text()); });
  history.on('pageerror', (e) => consoleErrors.push(String(e)));
  await history.goto(historyUrl);
  await history.waitForSelector('#history-panel:not(.hidden) .chart canvas', { timeout: 10_000 });
  assert.match(await history.locator('#history-range').textContent(), /\d+ sets measured/);
  assert.equal(await history.locator('#history .chart').count(), 9);
  // The ppp chart has its lines drawn: pixels in the series colours, not only the frame.
  const drawn = await history.evaluate(() => {
    const canvas = document.querySelector('#history .chart canvas');
    const data = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
    let coloured = 0;
    for (let i = 0; i < data.length; i += 4) if (data[i + 2] > 200 && data[i] < 150) ++coloured;  // cam0's blue
    return coloured;
  });
  assert.ok(drawn > 20, `ppp time series drawn (${drawn} blue pixels)`);
  if (process.env.TOMORIG_SCREENSHOT_HISTORY)
    await history.screenshot({ path: process.env.TOMORIG_SCREENSHOT_HISTORY, fullPage: true });
  assert.deepEqual(consoleErrors, [], 'no console error on the history page');
});
