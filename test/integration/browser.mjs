// What the console's browser tests share: headless Debian chromium (/usr/bin/chromium, never a downloaded
// browser) driven by npm playwright-core, with a throw-away profile and software WebGL (swiftshader), and
// check(), which ends the script with an error (exit code 1) when a check fails.
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

/// A persistent chromium context (60 s default timeout); close() also removes its profile.
export async function launchChromium(modules, { viewport = { width: 1600, height: 1000 }, ...options } = {}) {
  const { chromium } = await import(pathToFileURL(path.join(modules, 'playwright-core/index.mjs')).href);
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'rigger-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: '/usr/bin/chromium', headless: true, viewport, ...options,
    args: ['--no-sandbox', '--disable-gpu', '--no-first-run', '--disable-background-networking', '--disable-component-update',
      '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
  context.setDefaultTimeout(60000);
  return {
    context,
    close: async () => { await context.close(); fs.rmSync(profile, { recursive: true, force: true }); },
  };
}

/// Logs a page's errors and console errors, prefixed with `name`.
export function logPage(name, page) {
  page.on('pageerror', (e) => console.log(`[${name}] page error: ${e.message}`));
  page.on('console', (m) => { if (m.type() === 'error') console.log(`[${name}] console: ${m.text()}`); });
}

export function check(cond, what) {
  if (!cond) throw new Error(`check failed: ${what}`);
  console.log(`ok: ${what}`);
}

/// check() with the seconds since `t0` in each line.
export const timedCheck = (t0 = Date.now()) => (cond, what) => check(cond, `(${((Date.now() - t0) / 1000).toFixed(1)} s) ${what}`);

/// An environment variable the test must set; a missing one ends the script naming it.
export const env = (k) => { if (!process.env[k]) throw new Error(`${k} is not set`); return process.env[k]; };

/// One request to the console at `base`: the bearer `token` (none when empty), `body` sent as JSON (a
/// string as it is). Returns {status, json} (json null when the answer is not JSON).
export async function consoleRequest(base, pathname, { token, method = 'GET', body } = {}) {
  const headers = {};
  if (token) headers.Authorization = `Bearer ${token}`;
  if (body !== undefined) headers['Content-Type'] = 'application/json';
  const res = await fetch(base + pathname, { method, headers, body: typeof body === 'string' ? body : JSON.stringify(body) });
  let json = null;
  try { json = await res.json(); } catch { /* not JSON */ }
  return { status: res.status, json };
}
