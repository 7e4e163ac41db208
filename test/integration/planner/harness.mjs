// What the planner's browser scripts (e2e.mjs, paper_task.mjs) share: their environment (set by
// planner_test_support.hpp), checks that end the script with exit code 1, the console's API with the
// programmer's token, headless Debian chromium through playwright-core, and the wait for the skills.
import fs from 'node:fs';

import { check, consoleRequest, env, launchChromium, logPage } from '../browser.mjs';

export { check, env };

export const URL_ = env('CONSOLE_URL');
export const ART = env('ARTIFACTS');
export const MODULES = env('NODE_PATH');
export const TOKEN = env('TOKEN_PROGRAMMER');

/// The console's API as the programmer: {status, json}.
export function call(pathname, { method = 'GET', body } = {}) {
  return consoleRequest(URL_, pathname, { token: TOKEN, method, body });
}

/// Asks the console `pathname` every 200 ms until `done(json)`; fails with `what(json)` after `timeoutMs`.
export async function until(pathname, done, what, timeoutMs) {
  for (const deadline = Date.now() + timeoutMs; ;) {
    const json = (await call(pathname)).json || {};
    if (done(json)) return;
    check(Date.now() < deadline, what(json));
    await new Promise((ok) => setTimeout(ok, 200));
  }
}

/// The executors' announcements reach the console in their own time: waits until it knows `needed`.
export async function waitForSkills(needed) {
  const names = (json) => (json.skills || []).map((s) => s.name);
  await until('/api/skills', (json) => needed.every((n) => names(json).includes(n)),
    (json) => `the console knows ${needed} within 60 s (has ${names(json)})`, 60000);
}

/// Waits until the console's executors are exactly `ids` (sorted or not): the cell the test brought up,
/// nothing of another left. Up to `timeoutMs`.
export async function waitForExecutors(ids, timeoutMs) {
  const wanted = JSON.stringify([...ids].sort());
  const now = (json) => JSON.stringify(Object.keys(json.executors || {}).sort());
  await until('/api/skills', (json) => now(json) === wanted,
    (json) => `the console's executors are ${wanted} within ${timeoutMs / 1000} s (are ${now(json)})`, timeoutMs);
}

/// Headless chromium with a fresh profile (../browser.mjs); closeBrowser() ends it.
export async function launchBrowser() {
  return launchChromium(MODULES, { acceptDownloads: true });
}
/// Writes `result` to RESULT (also after a failed check: what the script saw so far) and ends the browser.
export async function closeBrowser(browser, result) {
  fs.writeFileSync(env('RESULT'), JSON.stringify(result, null, 2));
  await browser.close();
}

/// A new page on the planner, logged in, once the page and its parts are ready; page errors are logged.
export async function openPlanner(browser) {
  const page = await browser.context.newPage();
  logPage('planner', page);
  await page.goto(`${URL_}/?token=${TOKEN}#/planner`);
  await page.waitForFunction(() => window.rigger?.ready === true && window.rigger.planner?.ready === true, null, { timeout: 90000 });
  return page;
}

/// `page` with its person-like actions counted as the planner's Effort counts them (effort.js): a click
/// (page.click, page.mouse.click), a choice from a list (selectOption), a field typed (fill) with its
/// characters. Returns [the counting page, the counts so far].
export function countActions(page) {
  const acts = { clicks: 0, choices: 0, fields_typed: 0, characters: 0 };
  const mouse = new Proxy(page.mouse, {
    get(target, key) {
      const v = Reflect.get(target, key);
      if (key === 'click') return (...a) => { acts.clicks += 1; return v.apply(target, a); };
      return typeof v === 'function' ? v.bind(target) : v;
    },
  });
  const counting = new Proxy(page, {
    get(target, key) {
      const v = Reflect.get(target, key);
      if (key === 'mouse') return mouse;
      if (key === 'click') return (...a) => { acts.clicks += 1; return v.apply(target, a); };
      if (key === 'selectOption') return (...a) => { acts.choices += 1; return v.apply(target, a); };
      if (key === 'fill') {
        return (selector, value, ...rest) => {
          acts.fields_typed += 1;
          acts.characters += String(value).length;
          return v.call(target, selector, value, ...rest);
        };
      }
      return typeof v === 'function' ? v.bind(target) : v;
    },
  });
  return [counting, acts];
}

/// The 3D view's mouse gestures on `page`: `orbit(dy)` drags from the canvas's centre by `dy` pixels
/// (up: negative, the view goes under); `clickAt(entity, p)` clicks `entity`'s model point `p` where the
/// page draws it and returns the pick the page made.
export async function viewGestures(page) {
  const state = (fn, arg) => page.evaluate(fn, arg);
  const canvas = page.locator('.pview canvas');
  await canvas.scrollIntoViewIfNeeded();
  const box = await canvas.boundingBox();
  /// A drag from the canvas's centre: `dy` down (the view tilts), `dx` right (it turns about the vertical).
  const orbit = async (dy, dx = 0) => {
    // Where the canvas is now: a screenshot or a click may have scrolled the page since.
    await canvas.scrollIntoViewIfNeeded();
    const now = await canvas.boundingBox();
    const x = now.x + now.width / 2, y = now.y + now.height / 2;
    await page.mouse.move(x, y);
    await page.mouse.down();
    for (let i = 1; i <= 10; ++i) await page.mouse.move(x + (dx * i) / 10, y + (dy * i) / 10);
    await page.mouse.up();
  };
  const clickAt = async (entity, p) => {
    const n = await state(() => window.rigger.planner.state.picks.length);
    const q = await state(([e, pt]) => window.rigger.planner.screenOf(e, pt), [entity, p]);
    await page.mouse.click(q.x, q.y);
    await page.waitForFunction((k) => window.rigger.planner.state.picks.length === k + 1, n, { timeout: 10000 });
    return state(() => window.rigger.planner.state.picks.at(-1));
  };
  return { box, orbit, clickAt };
}

/// Waits until the Planner has drawn the parts of cell revision `n` (or a later one): after a confirmed
/// revision the page clears and reloads its parts, and a click before that lands on nothing.
export async function waitForDrawnRevision(page, n) {
  await page.waitForFunction((k) => (window.rigger.planner.drawnRevision || 0) >= k, n, { timeout: 30000 });
}
