// Rehearse, then publish, in a real browser (run by rehearsal_browser_test.cpp, which starts the full
// simulated cell on the rehearsal domain, a controller with scripted executors on the console's own
// domain, a console with rehearsal_domain and one without). Headless Debian chromium through
// playwright-core, launched as the planner's browser test does. The refusals over HTTP first (a viewer;
// a console without a rehearsal domain), then the recipe RECIPE opened on the planner, Rehearse
// clicked, and the run followed in the rehearsal view to its end state; a Publish afterwards still asks
// for confirmation (cancelled here: nothing may reach the cell); last, the console without a rehearsal
// domain says so in its page. Any failed check
// ends the script with exit code 1. Every wait is on a condition.
import fs from 'node:fs';
import path from 'node:path';
import { check as checked, consoleRequest, env, launchChromium, logPage } from '../browser.mjs';

const URL_ = env('CONSOLE_URL');
const PLAIN = env('PLAIN_URL');
const ART = env('ARTIFACTS');
const MODULES = env('NODE_PATH');
const TOKEN = env('TOKEN_PROGRAMMER');
const VIEWER = env('TOKEN_VIEWER');
const RECIPE = env('RECIPE');
const TASK_ID = JSON.parse(fs.readFileSync(RECIPE, 'utf8')).task_id;
const DOMAIN = Number(env('REHEARSAL_DOMAIN'));
const result = {};
const t0 = Date.now();
const since = () => `${((Date.now() - t0) / 1000).toFixed(1)} s`;

const check = (cond, what) => checked(cond, `(${since()}) ${what}`);
const call = (base, pathname, { method = 'GET', body, token = TOKEN } = {}) =>
  consoleRequest(base, pathname, { token, method, body });
const recipeText = fs.readFileSync(RECIPE, 'utf8');

// --- refusals over HTTP: a viewer may not rehearse; a console without a rehearsal domain says so ---
let r = await call(URL_, '/api/planner/rehearse', { method: 'POST', body: recipeText, token: VIEWER });
check(r.status === 403, `a viewer's rehearsal -> 403 ${JSON.stringify(r.json)}`);
r = await call(PLAIN, '/api/planner/rehearse', { method: 'POST', body: recipeText });
check(r.status === 409 && /rehearsal_domain/.test(r.json?.error), `no rehearsal domain configured -> 409 saying so ${JSON.stringify(r.json)}`);
result.no_domain_answer = r.json;

// The rehearsal cell's executors and controller reach the console in their own time (the test started
// the browser once they were READY on their domain): wait until the console has heard them.
const cellExecutors = ['robot-skills', 'perception-skills', 'operator-skills', 'monitors'];
for (const deadline = Date.now() + 60000; ;) {
  r = await call(URL_, '/api/rehearsal/state');
  const ids = (r.json?.executors || []).map((e) => e.executor_id);
  if (r.status === 200 && cellExecutors.every((e) => ids.includes(e))) break;
  check(Date.now() < deadline, `the console hears the rehearsal cell's executors within 60 s (has ${ids})`);
  await new Promise((ok) => setTimeout(ok, 200));
}
check(r.json.domain === DOMAIN && r.json.tasks.length === 0, `GET /api/rehearsal/state: domain ${r.json.domain}, no task yet`);

const browser = await launchChromium(MODULES);
try {
  const page = await browser.context.newPage();
  logPage('planner', page);
  // Opens the planner of console `base` and the recipe file with the Open button; waits until the
  // opened recipe was validated (its bindings checked).
  const openRecipe = async (base) => {
    await page.goto(`${base}/?token=${TOKEN}#/planner`);
    await page.waitForFunction(() => window.rigger?.ready === true && window.rigger.planner?.ready === true, null, { timeout: 90000 });
    await page.setInputFiles('#planner-open', RECIPE);
    await page.waitForFunction(() => window.rigger.planner.state.bindingsChecked > 0 && window.rigger.planner.state.validation, null, { timeout: 30000 });
    check(await page.evaluate(() => window.rigger.planner.state.doc.task_id) === TASK_ID, `${RECIPE} opened on the planner`);
  };

  // --- Rehearse on the console with a rehearsal domain: the live view of the run, to its end ---
  await openRecipe(URL_);
  // The page's loading (three.js, software WebGL) done before the run starts, as a person's would be.
  await page.evaluate(() => new Promise((ok) => requestIdleCallback(ok, { timeout: 10000 })));
  await page.click('#planner-rehearse');
  // The answer is the rehearsal controller's verdict: the view, or a refusal under the toolbar.
  await page.waitForFunction(() => !document.querySelector('#rehearsal').hidden
    || /Not rehearsed/.test(document.querySelector('#planner-notice')?.textContent || ''), null, { timeout: 30000 });
  check(await page.locator('#rehearsal').isVisible(), `the rehearsal was accepted (${await page.locator('#planner-notice').innerText()})`);
  const title = await page.locator('#rehearsal-title').innerText();
  check(title === `Rehearsal — simulated cell, domain ${DOMAIN}`, `the view is labelled "${title}"`);
  check(await page.locator('#planner-editor').isHidden(), 'the plan makes room for the rehearsal view');
  result.title = title;
  await page.waitForFunction(() => document.querySelectorAll('#rehearsal li[data-node]').length > 0, null, { timeout: 60000, polling: 100 });
  check(true, 'the rehearsal tree fills in live');
  const started = Date.now();
  // Polled twice a second, not on every animation frame: a software-rendered chromium drawing frames
  // for nothing takes CPU the rehearsal cell's real-time loops need.
  await page.waitForFunction(() => window.rigger.planner.rehearsal.ended(), null, { timeout: 5 * 60000, polling: 500 });
  result.run_s = (Date.now() - started) / 1000;
  // The tree redraws on animation frames: wait until every row shows its node's last state.
  await page.waitForFunction(() => {
    const v = window.rigger.planner.rehearsal;
    const nodes = v.store.nodes.get(v.taskId);
    return nodes && [...nodes.values()].every((n) => document.querySelector(`#rehearsal li[data-node="${n.node_id}"] > .row`)?.dataset.state === n.state);
  }, null, { timeout: 10000 });
  result.task_state = await page.evaluate(() => window.rigger.planner.rehearsal.state());
  result.shown = await page.$$eval('#rehearsal li[data-node]', (lis) => Object.fromEntries(lis.map((li) => [li.dataset.node, li.querySelector(':scope > .row').dataset.state])));
  const status = await page.locator('#rehearsal-status').innerText();
  check(result.task_state === 'SUCCEEDED' && /ended SUCCEEDED/.test(status), `the rehearsal ended ${result.task_state}: "${status}" after ${result.run_s} s`);
  check(Object.keys(result.shown).length > 3 && result.shown.root === 'SUCCESS', `every node's final state shown (${Object.keys(result.shown).length} nodes)`);
  await page.screenshot({ path: path.join(ART, 'rehearsal-succeeded.png'), fullPage: true });
  await page.addScriptTag({ path: path.join(MODULES, 'axe-core/axe.min.js') });
  const axe = await page.evaluate(async () => (await window.axe.run(document)).violations.map((x) => `${x.id}: ${x.help} (${x.nodes.length})`));
  check(axe.length === 0, `axe-core: no violations on the rehearsal view ${JSON.stringify(axe)}`);
  r = await call(URL_, `/api/rehearsal/state?task=${TASK_ID}`);
  check(r.json.tasks.some((t) => t.task_id === TASK_ID && t.state === 'SUCCEEDED'), 'GET /api/rehearsal/state has the rehearsal\'s task');
  r = await call(URL_, '/api/state');
  check(r.json.tasks.length === 0, 'the cell\'s own state has no task');

  // --- back to the plan; a Publish is still two steps (cancelled: nothing reaches the cell) ---
  await page.click('#rehearsal-back');
  check(await page.locator('#planner-editor').isVisible() && await page.evaluate(() => window.rigger.planner.state.doc.task_id) === TASK_ID,
    'Back to the plan: the plan as it was');
  await page.click('#planner-publish');
  await page.waitForSelector('dialog[open]');
  check(true, 'Publish after the rehearsal asks for confirmation');
  await page.click('#confirm-no');
  await page.waitForFunction(() => /Publish not confirmed/.test(document.querySelector('#planner-notice')?.textContent || ''), null, { timeout: 30000 });
  check(true, 'cancelled: not published');

  // Last, so that the run above starts after one page load, not two (the cell runs in real time).
  // --- no rehearsal domain: the page says so and stays on the plan ---
  await openRecipe(PLAIN);
  await page.click('#planner-rehearse');
  await page.waitForFunction(() => /rehearsal_domain/.test(document.querySelector('#planner-notice')?.textContent || ''), null, { timeout: 30000 });
  const plainNotice = await page.locator('#planner-notice').innerText();
  check(/Not rehearsed/.test(plainNotice) && await page.locator('#rehearsal').isHidden(), `the page says what is missing: "${plainNotice}"`);
  result.no_domain_notice = plainNotice;
  await page.screenshot({ path: path.join(ART, 'rehearsal-no-domain.png'), fullPage: true });
} finally {
  fs.writeFileSync(env('RESULT'), JSON.stringify(result, null, 2));
  await browser.close();
}
