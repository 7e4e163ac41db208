// The planner's browser test (run by planner_browser_test.cpp, which starts the CAD service, the world
// model, the controller, scripted executors with the real skill library and the console): headless
// Debian chromium through playwright-core, as the console's browser test. The tree is built by clicks
// only; the target's four holes are picked by clicking the 3D view where each hole's entry point (from
// the CAD service's features) projects on the screen, through the page's test hook screenOf(). Any
// failed check ends the script with exit code 1.
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const env = (k) => { if (!process.env[k]) throw new Error(`${k} is not set`); return process.env[k]; };
const URL_ = env('CONSOLE_URL');
const ART = env('ARTIFACTS');
const MODULES = env('NODE_PATH');
const TOKEN = env('TOKEN_PROGRAMMER');
const { chromium } = await import(pathToFileURL(path.join(MODULES, 'playwright-core/index.mjs')).href);
const result = {};

function check(cond, what) {
  if (!cond) throw new Error(`check failed: ${what}`);
  console.log(`ok: ${what}`);
}
async function call(pathname, { method = 'GET', body } = {}) {
  const headers = { Authorization: `Bearer ${TOKEN}` };
  if (body !== undefined) headers['Content-Type'] = 'application/json';
  const res = await fetch(URL_ + pathname, { method, headers, body: typeof body === 'string' ? body : JSON.stringify(body) });
  let json = null;
  try { json = await res.json(); } catch { /* not JSON */ }
  return { status: res.status, json };
}

// The executors' announcements reach the console in their own time: wait until it knows the skills used.
const needed = ['Localize', 'YankMonitor', 'Screw'];
for (const deadline = Date.now() + 60000; ;) {
  const r = await call('/api/skills');
  const names = (r.json?.skills || []).map((s) => s.name);
  if (needed.every((n) => names.includes(n))) break;
  check(Date.now() < deadline, `the console knows ${needed} within 60 s (has ${names})`);
  await new Promise((ok) => setTimeout(ok, 200));
}
const features = (await call('/api/cad/features?model=object:target')).json;
check(features?.holes?.length === 4, `the CAD service lists the target's 4 holes (${features?.holes?.length})`);
result.cad_holes = features.holes;
// A bad pick is refused with where and what.
let r = await call('/api/planner/screws', { method: 'POST', body: { model: 'object:target', holes: [7] } });
check(r.status === 400 && /no hole 7/.test(r.json?.error), `a pick of a hole that does not exist -> 400 ${JSON.stringify(r.json)}`);

const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'rigger-chromium-'));
const context = await chromium.launchPersistentContext(profile, {
  executablePath: '/usr/bin/chromium', headless: true, viewport: { width: 1600, height: 1000 }, acceptDownloads: true,
  args: ['--no-sandbox', '--disable-gpu', '--no-first-run', '--disable-background-networking', '--disable-component-update',
    '--disable-sync', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
context.setDefaultTimeout(60000);
try {
  const page = await context.newPage();
  page.on('pageerror', (e) => console.log(`[planner] page error: ${e.message}`));
  page.on('console', (m) => { if (m.type() === 'error') console.log(`[planner] console: ${m.text()}`); });
  await page.goto(`${URL_}/?token=${TOKEN}#/planner`);
  await page.waitForFunction(() => window.rigger?.ready === true && window.rigger.planner?.ready === true, null, { timeout: 90000 });
  check(await page.locator('#planner-add-kind option[value="skill:Screw"]').count() === 1, 'the Screw skill is offered from the live library');

  // --- the tree, by clicks ---
  const addNode = async (value) => { await page.selectOption('#planner-add-kind', value); await page.click('#planner-add'); };
  const select = async (pointer) => page.click(`button.pnode[data-pointer="${pointer}"]`);
  await addNode('control:Sequence');
  await addNode('control:Parallel');              // into the Sequence: /root/children/0
  await addNode('skill:Localize');                // into the Parallel
  await page.fill('#param-object', 'target');
  await select('/root/children/0');
  await addNode('monitor:YankMonitor');
  await page.fill('#param-max_yank_n_per_s', '2000');
  await select('/root');
  await addNode('skill:Screw');                   // /root/children/1
  await page.fill('#planner-assumptions', 'inserted(load,target)');
  await page.fill('#planner-task-id', 'planned-screws');
  await select('/root/children/0');
  await page.fill('[data-field="name"]', 'localize with yank monitor');
  // Move the Screw up and down again (the order matters for the preconditions).
  await select('/root/children/1');
  await page.click('#planner-up');
  check(await page.locator('button.pnode[data-pointer="/root/children/0"]').innerText().then((t) => t.includes('Screw')), 'Up moved the Screw first');
  await page.click('#planner-down');
  check(await page.locator('button.pnode[data-pointer="/root/children/1"]').innerText().then((t) => t.includes('Screw')), 'Down moved it back');

  // --- a bad threshold, shown on its node and field by the controller's validator ---
  await select('/root/children/0');
  await page.fill('[data-field="success_threshold"]', '2');
  await page.waitForFunction(() => document.querySelector('button.pnode[data-pointer="/root/children/0"]')?.classList.contains('invalid')
    && document.querySelector('[data-field="success_threshold"]')?.getAttribute('aria-invalid') === 'true', null, { timeout: 20000 });
  const fieldError = await page.locator('[data-field="success_threshold"]').locator('xpath=ancestor::div[contains(@class,"field")]').locator('.field-error').innerText();
  check(/success_threshold/.test(fieldError), `the field shows the validator's message: ${fieldError}`);
  const invalidNodes = await page.$$eval('button.pnode.invalid', (bs) => bs.map((b) => b.dataset.pointer));
  // The Screw is flagged too (its holes are not bound yet); the root and the Parallel's children are not.
  check(invalidNodes.includes('/root/children/0') && !invalidNodes.some((p) => p === '/root' || p.startsWith('/root/children/0/')),
    `the Parallel is flagged, not the root nor its children (flagged: ${invalidNodes})`);
  result.threshold_error = { node: '/root/children/0', field: await page.locator('[aria-invalid="true"]').first().getAttribute('data-field'), message: fieldError };
  await page.screenshot({ path: path.join(ART, 'planner-threshold-error.png'), fullPage: true });
  await page.fill('[data-field="success_threshold"]', '1');
  await page.waitForFunction(() => !document.querySelector('button.pnode[data-pointer="/root/children/0"]')?.classList.contains('invalid'), null, { timeout: 20000 });
  console.log('ok: the fixed threshold is no longer flagged');

  // --- pick the target's four holes in the 3D view ---
  await page.evaluate(() => window.scrollTo(0, 0));
  const hover = await page.evaluate((h) => window.rigger.planner.screenOf('target', h.entry_m), features.holes[0]);
  await page.mouse.move(hover.x, hover.y);
  await page.waitForFunction(() => window.rigger.planner.view.hovered === 'target:hole:0', null, { timeout: 10000 });
  console.log('ok: hovering hole 0 highlights it');
  for (const h of features.holes) {
    const p = await page.evaluate((hole) => window.rigger.planner.screenOf('target', hole.entry_m), h);
    await page.mouse.click(p.x, p.y);
  }
  const picks = await page.evaluate(() => window.rigger.planner.state.picks.map((p) => ({ kind: p.kind, hole: p.hole, entity: p.entity, sig: p.ref.signature.type })));
  check(picks.length === 4 && picks.every((p, i) => p.kind === 'hole' && p.hole === features.holes[i].index && p.entity === 'target' && p.sig === 'cylinder'),
    `four holes picked in the 3D view, in order ${JSON.stringify(picks)}`);
  check(await page.locator('ol.picks li[data-kind="hole"]').count() === 4, 'the selection list shows the four picks with their references');
  await page.screenshot({ path: path.join(ART, 'planner-picks.png'), fullPage: true });

  // --- the Screw skill's holes from the picks ---
  await select('/root/children/1');
  await page.click('#planner-bind-holes');
  await page.waitForFunction(() => document.querySelectorAll('#planner-screws tr').length === 5, null, { timeout: 20000 });
  const params = await page.evaluate(() => window.rigger.planner.state.doc.root.children[1].params.holes);
  check(params.length === 4 && new Set(params).size === 4 && params.every((f) => /^target\/h[1-4]$/.test(f)),
    `the Screw's holes are the world model's four screw-hole features ${JSON.stringify(params)}`);
  await page.waitForSelector('#planner-valid', { timeout: 20000 });
  console.log('ok: the tree validates');

  // --- export (download), then the same text validated by the console, then reopened ---
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#planner-export')]);
  const exportedPath = path.join(ART, 'planned-screws.json');
  await download.saveAs(exportedPath);
  const exported = fs.readFileSync(exportedPath, 'utf8');
  result.exported = exported;
  r = await call('/api/planner/validate', { method: 'POST', body: exported });
  check(r.status === 200 && r.json.ok === true, `the exported recipe validates ${JSON.stringify(r.json?.errors)}`);
  const doc = JSON.parse(exported);
  const screws = doc.root.children[1].bindings.holes.screws;
  check(screws.every((s, i) => JSON.stringify(s.pose.position_m) === JSON.stringify(features.holes[i].entry_m)),
    'the exported screw positions are the CAD service\'s hole entries');
  await page.setInputFiles('#planner-open', exportedPath);
  await select('/root/children/1');
  await page.waitForFunction(() => document.querySelectorAll('#planner-screws tr').length === 5, null, { timeout: 20000 });
  console.log('ok: the reopened recipe has its screw binding back');
  // A binding whose reference no longer matches the model (as after an edit of the STEP file) is flagged
  // on its node when the recipe is opened, and the recipe is not valid; the good file clears it again.
  const tampered = JSON.parse(exported);
  tampered.root.children[1].bindings.holes.screws[2].ref.signature.radius_m += 0.001;
  const tamperedPath = path.join(ART, 'planned-screws-stale.json');
  fs.writeFileSync(tamperedPath, JSON.stringify(tampered));
  let checked = await page.evaluate(() => window.rigger.planner.state.bindingsChecked || 0);
  await page.setInputFiles('#planner-open', tamperedPath);
  await page.waitForFunction((n) => window.rigger.planner.state.bindingsChecked > n && window.rigger.planner.state.validation, checked, { timeout: 20000 });
  const stale = await page.evaluate(() => window.rigger.planner.state.errors.filter((e) => /stale/.test(e.message)));
  check(stale.length === 1 && stale[0].pointer === '/root/children/1/bindings/holes' && /CAD_STALE_REFERENCE/.test(stale[0].message),
    `the changed reference is flagged as a stale binding on the Screw ${JSON.stringify(stale)}`);
  check(await page.locator('button.pnode.invalid[data-pointer="/root/children/1"]').count() === 1, 'the Screw node is flagged');
  checked = await page.evaluate(() => window.rigger.planner.state.bindingsChecked);
  await page.setInputFiles('#planner-open', exportedPath);
  await page.waitForFunction((n) => window.rigger.planner.state.bindingsChecked > n, checked, { timeout: 20000 });
  await page.waitForSelector('#planner-valid', { timeout: 20000 });
  console.log('ok: the good file opens valid again');

  // --- publish: select, confirm ---
  await page.click('#planner-publish');
  await page.waitForSelector('dialog[open]');
  await page.click('#confirm-yes');
  await page.waitForFunction(() => document.body.innerText.includes('Published planned-screws'), null, { timeout: 60000 });
  console.log('ok: published from the planner');
  await page.screenshot({ path: path.join(ART, 'planner.png'), fullPage: true });
} finally {
  fs.writeFileSync(env('RESULT'), JSON.stringify(result, null, 2));
  await context.close();
  fs.rmSync(profile, { recursive: true, force: true });
}
