// Rehearse with no rehearsal cell running (run by rehearsal_on_demand_browser_test.cpp): the console has a
// start command for it and a short idle stop. First the real cell moves on: a revision on the console's
// own domain moves the target 2 cm, so the rehearsal cell, started from the file, must be brought to it.
// The planner opens recipes/crane_insert.json, Rehearse is clicked, the page says it is starting the
// rehearsal cell, then shows the run to its end; back on the plan nobody watches, and the console stops
// the cell. Every wait is on a condition; a failed check ends
// the script with exit code 1.
import fs from 'node:fs';
import { consoleRequest, env, launchChromium, logPage, timedCheck } from '../browser.mjs';

const URL_ = env('CONSOLE_URL');
const TOKEN = env('TOKEN_PROGRAMMER');
const DOMAIN = Number(env('REHEARSAL_DOMAIN'));
const check = timedCheck();
const result = {};
const cell = async () => (await consoleRequest(URL_, '/api/rehearsal/cell', { token: TOKEN })).json;

let c = await cell();
check(c.phase === 'idle' && c.domain === DOMAIN, `before Rehearse the rehearsal cell is idle ${JSON.stringify(c)}`);

/// Moves the target 2 cm along y by a cell revision on the console's own domain, in two steps as a
/// programmer does; the cell's running revision afterwards (without its document).
async function moveTarget() {
  const running = (await consoleRequest(URL_, '/api/cell', { token: TOKEN })).json;
  const doc = JSON.parse(running.cell_json);
  doc.entities.find((e) => e.id === 'target').pose.position_m[1] += 0.02;
  let r = await consoleRequest(URL_, '/api/cell/revisions', { token: TOKEN, method: 'POST', body: { cell: doc, comment: 'the target 2 cm along y' } });
  check(r.status === 202, `the moved target proposed on the cell's domain (${r.status} ${JSON.stringify(r.json)})`);
  r = await consoleRequest(URL_, '/api/confirm', { token: TOKEN, method: 'POST', body: { confirmation_id: r.json.confirmation_id } });
  check(r.status === 200, `and applied (${r.status} ${JSON.stringify(r.json)})`);
  const now = (await consoleRequest(URL_, '/api/cell', { token: TOKEN })).json;
  delete now.cell_json;
  check(now.sha256 !== running.sha256, `the cell runs revision ${now.cell_revision} (${now.sha256})`);
  return now;
}
result.real_revision = await moveTarget();

const browser = await launchChromium(env('NODE_PATH'));
try {
  const page = await browser.context.newPage();
  logPage('planner', page);
  await page.goto(`${URL_}/?token=${TOKEN}#/planner`);
  await page.waitForFunction(() => window.rigger?.ready === true && window.rigger.planner?.ready === true, null, { timeout: 90000 });
  await page.setInputFiles('#planner-open', env('RECIPE'));
  await page.waitForFunction(() => window.rigger.planner.state.validation, null, { timeout: 30000 });
  await page.click('#planner-rehearse');
  const status = '#planner-notice';
  await page.waitForFunction((sel) => /Starting the rehearsal cell/.test(document.querySelector(sel)?.textContent || ''), status,
    { timeout: 30000, polling: 50 });
  result.starting_notice = await page.locator(status).innerText();
  check(true, `the page says "${result.starting_notice}"`);
  result.cell_started = await cell();
  check(['starting', 'ready'].includes(result.cell_started.phase) && result.cell_started.pid > 0,
    `the console runs the start command ${JSON.stringify(result.cell_started)}`);

  await page.waitForFunction((sel) => !document.querySelector('#rehearsal').hidden
    || /Not rehearsed/.test(document.querySelector(sel)?.textContent || ''), status, { timeout: 60000, polling: 200 });
  check(await page.locator('#rehearsal').isVisible(), `the recipe was sent once the controller was there (${await page.locator(status).innerText()})`);
  await page.waitForFunction(() => window.rigger.planner.rehearsal.ended(), null, { timeout: 60000, polling: 200 });
  result.task_state = await page.evaluate(() => window.rigger.planner.rehearsal.state());
  check(result.task_state === 'SUCCEEDED', `the rehearsal ended ${result.task_state}`);
  c = await cell();
  check(c.phase === 'ready', `watched after its run, the cell stays up ${JSON.stringify(c)}`);

  // The cell moves on while the rehearsal cell is up: the next rehearsal runs on that revision too.
  result.second_revision = await moveTarget();
  const again = JSON.parse(fs.readFileSync(env('RECIPE'), 'utf8'));
  again.task_id = 'crane-insert-again';
  const r = await consoleRequest(URL_, '/api/planner/rehearse', { token: TOKEN, method: 'POST', body: again });
  check(r.status === 200, `rehearsed again on the cell's revision ${result.second_revision.cell_revision} (${r.status} ${JSON.stringify(r.json)})`);

  // Back to the plan: the rehearsal's stream closes, nothing runs, so the idle stop comes.
  await page.click('#rehearsal-back');
  const idleFrom = Date.now();
  for (const deadline = Date.now() + 30000; ;) {
    c = await cell();
    if (c.phase === 'idle') break;
    if (Date.now() > deadline) check(false, `the cell stops within 30 s of the last watcher (${JSON.stringify(c)})`);
    await new Promise((ok) => setTimeout(ok, 200));
  }
  result.cell_after = c;
  result.idle_to_stopped_s = (Date.now() - idleFrom) / 1000;
  check(c.error === '', `stopped when idle after ${result.idle_to_stopped_s} s, no error ${JSON.stringify(c)}`);
} finally {
  fs.writeFileSync(env('RESULT'), JSON.stringify(result, null, 2));
  await browser.close();
}
