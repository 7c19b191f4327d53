// What both browser tests share: where tomorig and Chromium are, how Chromium is launched
// headless in a container, and how a tomorig child is stopped (SIGINT, as a user's Ctrl-C,
// then waiting for it to finish its file).
import assert from 'node:assert/strict';
import { existsSync } from 'node:fs';

export const binary = process.env.TOMORIG_BINARY || new URL('../../build/apps/tomorig', import.meta.url).pathname;
export const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';

let playwright;
try {
  playwright = await import('playwright-core');
} catch {
  throw new Error('playwright-core is not installed: run `npm ci` in tests/browser (bash scripts/setup.sh test does)');
}

export function requireTools() {
  assert.ok(existsSync(binary), `tomorig not built at ${binary}`);
  assert.ok(existsSync(chromiumPath), `Chromium not found at ${chromiumPath} (apt-get install chromium)`);
}

// No sandbox (the tests run as root in CI), no GPU, nothing that reaches the network.
export function launchChromium() {
  return playwright.chromium.launch({
    executablePath: chromiumPath,
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
      '--disable-component-update', '--disable-sync', '--disable-dev-shm-usage'],
  });
}

export async function stopChild(child) {
  if (child.exitCode !== null || child.signalCode !== null) return;
  const ended = new Promise((resolve) => child.on('exit', resolve));
  child.kill('SIGINT');
  await ended;
}
